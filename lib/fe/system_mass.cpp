// Consistent mass matrices of the leaves and the rigid body's mass (system.hpp).
#include <cmath>
#include <functional>

#include "fe/leaf_sections.hpp"
#include "stackbeam/fe/system.hpp"

namespace stackbeam {
namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

/// The leaves' consistent mass on the full DOFs (u, v, theta per node) [kg, kg m^2].
Eigen::SparseMatrix<double> leaf_mass_full(const Model& model, int num_full,
                                           const std::function<int(int, int)>& node_dof) {
    const auto& spec = model.spec();
    const auto& xs = model.nodes_x();
    Triplets mt;
    for (int l = 0; l < static_cast<int>(spec.leaves.size()); ++l) {
        const auto& leaf = spec.leaves[l];
        // a profile: rho b(x) t(x) integrated exactly; uniform: rho A L (leaf_sections.hpp)
        if (leaf.density_kg_per_m3 == 0.0) continue;
        for (int j = model.first_node(l); j < model.last_node(l); ++j)
            detail::add_matrix(mt, node_dof(l, j), node_dof(l, j + 1), detail::element_mass(leaf, xs[j], xs[j + 1]));
    }
    Eigen::SparseMatrix<double> M(num_full, num_full);
    M.setFromTriplets(mt.begin(), mt.end());
    return M;
}
}  // namespace

Eigen::SparseMatrix<double> System::mass_reduced(bool with_body) const {
    const Eigen::SparseMatrix<double> M = leaf_mass_full(model_, num_full_, [this](int l, int j) { return node_dof(l, j); });
    Eigen::SparseMatrix<double> Mr = (P_.transpose() * M * P_).pruned();
    if (!with_body) return Mr;
    Mr.coeffRef(Mr.rows() - 1, Mr.cols() - 1) += mass_;  // the rigid body on w (meshed part's share)
    // the axle's pitch inertia on theta_R and its mass on u_R (full model only: no share to take)
    const auto& body = model_.spec().rigid_body;
    if (seat_rotation_dof_ >= 0 && body.pitch_inertia_kg_m2 > 0.0)
        Mr.coeffRef(seat_rotation_dof_, seat_rotation_dof_) += body.pitch_inertia_kg_m2;
    // (rigid_body.axial = 'auto' keeps the model before windup: the body's axial inertia left out)
    if (seat_axial_dof_ >= 0 && body.axial == SeatAxial::free) Mr.coeffRef(seat_axial_dof_, seat_axial_dof_) += mass_;
    return Mr;
}

Eigen::VectorXd System::vertical_inertia_kg() const {
    const Eigen::SparseMatrix<double> M = leaf_mass_full(model_, num_full_, [this](int l, int j) { return node_dof(l, j); });
    // e_y: every node translated by 1 in +y (v = 1, u = theta = 0). M e_y is the consistent load of a
    // uniform body force rho A per unit acceleration (the Hermite shapes of v sum to 1), and P^T
    // gives its work-equivalent load on the reduced DOFs.
    Eigen::VectorXd ey = Eigen::VectorXd::Zero(num_full_);
    for (int i = 1; i < num_full_; i += 3) ey[i] = 1.0;
    Eigen::VectorXd l = P_.transpose() * (M * ey);
    l[l.size() - 1] += mass_;  // the rigid body on w (meshed part's share)
    return l;
}

}  // namespace stackbeam
