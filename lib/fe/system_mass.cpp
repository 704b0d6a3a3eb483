// Consistent mass matrices of the leaves and the rigid body's mass (system.hpp).
#include <cmath>
#include <functional>

#include "fe/leaf_sections.hpp"
#include "stackbeam/fe/system.hpp"

namespace stackbeam {
namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

/// Consistent mass of a Bernoulli-Euler 2-node element of mass m = rho A L [kg],
/// DOFs (u1, v1, th1, u2, v2, th2): axial m/6 [2 1; 1 2]; bending (cubic Hermite
/// shapes, rotary inertia neglected as in the stiffness) m/420 [156 22L 54 -13L; ...].
void add_element_mass(Triplets& t, int a, int b, double m, double L) {
    const int d[6] = {3 * a, 3 * a + 1, 3 * a + 2, 3 * b, 3 * b + 1, 3 * b + 2};
    double me[6][6] = {};
    me[0][0] = me[3][3] = m / 3.0;
    me[0][3] = me[3][0] = m / 6.0;
    const double c = m / 420.0;
    const double mb[4][4] = {{156 * c, 22 * L * c, 54 * c, -13 * L * c},
                             {22 * L * c, 4 * L * L * c, 13 * L * c, -3 * L * L * c},
                             {54 * c, 13 * L * c, 156 * c, -22 * L * c},
                             {-13 * L * c, -3 * L * L * c, -22 * L * c, 4 * L * L * c}};
    const int bi[4] = {1, 2, 4, 5};
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) me[bi[i]][bi[j]] = mb[i][j];
    for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j)
            if (me[i][j] != 0.0) t.emplace_back(d[i], d[j], me[i][j]);
}

}  // namespace

namespace {
/// The leaves' consistent mass on the full DOFs (u, v, theta per node) [kg, kg m^2].
Eigen::SparseMatrix<double> leaf_mass_full(const Model& model, int num_full,
                                           const std::function<int(int, int)>& node_dof) {
    const auto& spec = model.spec();
    const auto& xs = model.nodes_x();
    Triplets mt;
    for (int l = 0; l < static_cast<int>(spec.leaves.size()); ++l) {
        const auto& leaf = spec.leaves[l];
        if (!leaf.profile.x_m.empty()) {  // a profile: rho b(x) t(x) integrated exactly (leaf_sections.hpp)
            if (leaf.density_kg_per_m3 == 0.0) continue;
            for (int j = model.first_node(l); j < model.last_node(l); ++j)
                detail::add_matrix(mt, node_dof(l, j), node_dof(l, j + 1), detail::profiled_mass(leaf, xs[j], xs[j + 1]));
            continue;
        }
        const double rho_a = leaf.density_kg_per_m3 * leaf.width_m * leaf.height_m;  // [kg/m]
        if (rho_a == 0.0) continue;
        for (int j = model.first_node(l); j < model.last_node(l); ++j) {
            const double L = xs[j + 1] - xs[j];
            add_element_mass(mt, node_dof(l, j), node_dof(l, j + 1), rho_a * L, L);
        }
    }
    Eigen::SparseMatrix<double> M(num_full, num_full);
    M.setFromTriplets(mt.begin(), mt.end());
    return M;
}
}  // namespace

Eigen::SparseMatrix<double> System::mass_reduced() const {
    const Eigen::SparseMatrix<double> M = leaf_mass_full(model_, num_full_, [this](int l, int j) { return node_dof(l, j); });
    Eigen::SparseMatrix<double> Mr = (P_.transpose() * M * P_).pruned();
    Mr.coeffRef(Mr.rows() - 1, Mr.cols() - 1) += mass_;  // the rigid body on w (meshed part's share)
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
