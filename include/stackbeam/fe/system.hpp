#pragma once
/// @file system.hpp
/// Derived data of a Model (Pinocchio's "data"): the finite-element stiffness of
/// the leaves, the constraints (supports, the rigid body's seat, symmetry), and
/// the condensation to the contact surface points of the paper (eqs. 1-6, A3).
///
/// Reduced coordinates z = [z_r; w]: z_r the free beam DOFs, w the rigid body's
/// displacement (+y). With massless leaves, for contact forces p and w given,
///     s = C' p + c w - d                  (eq. 6 with eq. 12 eliminated: u = C'p + (A/a) w)
///     f = k w - c^T p                     (force of R on the stack, +y; eq. 12: w = A^T p + a f)
/// C' = G_r K_rr^-1 G_r^T + C_L is the compliance with R held (eq. A3, SPD), C_L = diag(c_L)
/// the elastic interface layer's compliance per contact row (0 on rigid interfaces), k = 1/a the
/// stiffness at R with no contact force, c = A/a the relative surface motion
/// per unit w. All of it on the meshed part (half the spring on the half model).
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <memory>
#include <vector>

#include "stackbeam/contact/contact.hpp"
#include "stackbeam/model/model.hpp"

namespace stackbeam {

class System;

/// The deflected axis of one leaf at one time: its nodes, whole leaf (System::leaf_nodes).
/// SI units, signs of conventions.hpp.
struct LeafNodes {
    int leaf = 0;                   ///< index in ModelSpec::leaves (0: the top leaf)
    std::vector<double> x_m;        ///< x of each node [m], increasing, the leaf's whole length
    std::vector<double> w_m;        ///< transverse displacement v of the axis at each node [m], +y
    std::vector<double> theta_rad;  ///< rotation of the cross-section, dv/dx [rad], counter-clockwise
};

class System {
public:
    /// Assembles and condenses. Throws InputError when the stack is not
    /// restrained with R held (a leaf or the seat free to move as a rigid body).
    explicit System(const Model& model);

    const Model& model() const noexcept { return model_; }

    /// The contact pairs kept (components a support or the seat already fixes are
    /// dropped), with their rows in C', c and the gaps.
    const std::vector<ContactPair>& pairs() const noexcept { return pairs_; }
    /// For each kept pair, its index in model().candidate_pairs().
    const std::vector<int>& pair_candidates() const noexcept { return pair_candidate_; }
    /// The candidate-pair record of kept pair k (interface, node, x).
    const PairSpec& pair_spec(int k) const { return model_.candidate_pairs()[pair_candidate_[k]]; }
    int num_components() const noexcept { return static_cast<int>(gaps_.size()); }
    /// d_n per row for normal rows (the initial gap) and 0 for tangential rows [m].
    const Eigen::VectorXd& initial_offsets_m() const noexcept { return gaps_; }
    /// Compliance of the contact points with R held, C' [m/N] (eq. A3), the elastic
    /// interface layer's diagonal C_L included (layer_compliance_m_per_n()). Dense,
    /// num_components()^2 doubles: built on the first call (one sparse solve per
    /// contact row), not by the constructor, so that a large model run on the sparse
    /// contact path (simulation.hpp, ContactPath) never pays for it. Thread-safe.
    const Eigen::MatrixXd& compliance_held() const;
    /// The elastic interface layer's compliance per contact row, c_L [m/N]: 1/(k_n A) on a
    /// normal row, 1/(k_t A) on a tangential row of an elastic interface (PairSpec), 0 on a
    /// rigid one. With contact forces p the relative position is s = G z + c_L p - d: the
    /// layer deflects by c_L p (a compressed pair, p_n < 0, lets the leaves approach by
    /// -c_L p_n), so a closed pair (s_n = 0) carries p_n = -(G z - d)_n / c_L and a sticking
    /// one p_t = -(G z - d)_t / c_L, and the layer stores p^T C_L p / 2.
    const Eigen::VectorXd& layer_compliance_m_per_n() const noexcept { return layer_; }
    /// Whether any contact row has an elastic layer.
    bool has_layer() const noexcept { return layer_.size() > 0 && layer_.maxCoeff() > 0.0; }
    /// Contact rows on the reduced DOFs, G [-] (num_components() x num_reduced_dofs(),
    /// w last): s = G z - d for reduced displacements z (paper eq. 1 and 7; plus c_L p with
    /// an elastic layer).
    const Eigen::SparseMatrix<double>& contact_rows() const noexcept { return G_; }
    /// c = A/a: relative surface displacement per unit w with p = 0 [-].
    const Eigen::VectorXd& coupling() const noexcept { return c_; }
    /// k = 1/a: stiffness at R of the meshed part with p = 0 [N/m].
    double stiffness_n_per_m() const noexcept { return k_; }
    /// Mass carried by the meshed part [kg] (half of R on the half model).
    double mass_kg() const noexcept { return mass_; }
    /// Whole-spring stiffness at R with every kept contact component tied [N/m]
    /// (the bonded stiffness on a bonded model): factor * (k + c^T C'^-1 c).
    double tied_stiffness_n_per_m() const;
    /// Whole-spring stiffness at R with every contact force zero [N/m].
    double free_stiffness_n_per_m() const noexcept { return model_.whole_spring_factor() * k_; }
    /// Index in pairs() of the probe pair, or -1.
    int probe_pair() const noexcept { return probe_; }

    /// Number of reduced degrees of freedom (including w, the last).
    int num_reduced_dofs() const noexcept { return static_cast<int>(K_red_.rows()); }
    /// The seat's reduced DOFs (conventions.hpp, "Seat"): node-major leaf DOFs, then u_R (if the seat
    /// slides), then theta_R (full model), then w, the last. Index of w [m].
    int seat_w_dof() const noexcept { return num_reduced_dofs() - 1; }
    /// Index of theta_R [rad, counter-clockwise], -1 on the half model (the symmetry plane holds it).
    int seat_rotation_dof() const noexcept { return seat_rotation_dof_; }
    /// Index of u_R [m, +x], -1 where the seat locates the stack axially (RigidBodySpec::axial).
    int seat_axial_dof() const noexcept { return seat_axial_dof_; }
    /// Reduced stiffness P^T K P [N/m, N, N m per unit DOF], w last.
    const Eigen::SparseMatrix<double>& stiffness_reduced() const noexcept { return K_red_; }
    /// Reduced mass P^T M P [kg, kg m^2 per unit DOF], w last: the leaves' consistent
    /// mass matrices (density from the model; 0 = massless, the paper) plus the rigid
    /// body's mass on w (the meshed part's share: half on the half model), its pitch inertia J
    /// on theta_R and, with rigid_body.axial = 'free', its mass on u_R (the axle moves with the seat;
    /// 'auto' leaves it out, as the model before windup did). `with_body` false: the leaves' mass
    /// only (the windup rig leaves R's inertia out of its quasi-static loop, loading.hpp).
    Eigen::SparseMatrix<double> mass_reduced(bool with_body = true) const;
    /// The inertia of everything per unit acceleration in +y, on the reduced DOFs [kg] (w last):
    /// l = P^T M_full e_y + m e_w, the leaves' consistent mass times a unit translation of every
    /// node in y (their weight's consistent nodal loads per unit g) plus the rigid body's mass
    /// on w (meshed part's share). Gravity g loads the stack with -g l; a base acceleration
    /// y_b'' of the supports loads it, in the frame of the supports, with -y_b'' l (loading.hpp).
    /// Massless leaves: l = m e_w.
    Eigen::VectorXd vertical_inertia_kg() const;
    /// Seat loads on the massless stack (loading.hpp), condensed as the paper condenses the leaves:
    /// with seat loads S = [M; H] [N m, N] on theta_R and u_R (a column of zeros where the seat has
    /// no such DOF), R at w and contact forces p, the free DOFs solve K_rr z_r = G_r^T p - K_rw w + E S:
    ///     s        = C' p + c w + B S - d           B = G_r K_rr^-1 E   [m per unit load]
    ///     f        = k w - c^T p + g^T S              g = E^T K_rr^-1 K_rw [N per unit load] (R's force on the stack)
    ///     [theta_R; u_R] = B^T p - g w + F S          F = E^T K_rr^-1 E     [rad/(N m), m/N ...]
    /// (K symmetric: E^T K_rr^-1 G_r^T = B^T). Two solves with K_rr, on each call.
    struct SeatCondensation {
        Eigen::MatrixXd B;  ///< num_components() x 2
        Eigen::Vector2d g = Eigen::Vector2d::Zero();
        Eigen::Matrix2d F = Eigen::Matrix2d::Zero();
    };
    SeatCondensation seat_condensation() const;
    /// Reduced displacements z = [z_r; w] for contact forces p and rigid-body displacement w
    /// (one sparse solve with K_rr): K_rr z_r = G_r^T p - K_rw w.
    Eigen::VectorXd reduced_displacements(const Eigen::VectorXd& p, double w) const;
    /// As above with seat loads S = [M; H] [N m, N] on theta_R and u_R (SeatCondensation).
    Eigen::VectorXd reduced_displacements(const Eigen::VectorXd& p, double w, const Eigen::Vector2d& seat_loads) const;
    /// Displacements (u, v, theta) of every leaf node [m, m, rad] for contact forces p
    /// and rigid-body displacement w: index 3*node_dof(leaf, node) + {0,1,2}.
    Eigen::VectorXd leaf_displacements(const Eigen::VectorXd& p, double w) const;
    /// Displacements (u, v, theta) of every leaf node [m, m, rad] for reduced displacements
    /// z = [z_r; w] (num_reduced_dofs() entries), indexed as leaf_displacements(p, w); from the
    /// leaves' free shapes. InputError naming z when it has the wrong size.
    Eigen::VectorXd leaf_displacements(const Eigen::VectorXd& z) const;
    /// Offset of (leaf, node) in leaf_displacements() / 3, or -1 if the leaf has no such node.
    int node_dof(int leaf, int node) const;
    /// Every leaf's nodes (x, v, theta) for reduced displacements z = [z_r; w] (w last,
    /// num_reduced_dofs() entries), one entry per leaf in ModelSpec::leaves order. The
    /// displacements are from the leaf's free (unstressed) shape, which is flat unless the leaf
    /// has a free camber. On the half model the meshed left half is mirrored about the
    /// attachment x_R to the whole leaf (the motion is symmetric there: v(2 x_R - x) = v(x),
    /// theta(2 x_R - x) = -theta(x)); the node at x_R appears once. InputError naming z when it
    /// has not num_reduced_dofs() entries.
    std::vector<LeafNodes> leaf_nodes(const Eigen::VectorXd& z) const;

private:
    friend struct SystemAccess;  // internal: lib/fe/system_internal.hpp
    Model model_;
    std::vector<ContactPair> pairs_;
    std::vector<int> pair_candidate_;
    Eigen::VectorXd gaps_;
    Eigen::VectorXd layer_;                         // c_L per contact row [m/N]
    struct LazyCompliance;                          // C', built once on demand
    std::shared_ptr<LazyCompliance> C_held_;        // shared by copies (same model, same C')
    Eigen::SparseMatrix<double> G_;                 // contact rows x reduced DOFs (w last)
    Eigen::VectorXd c_;
    double k_ = 0.0;
    double mass_ = 0.0;
    int probe_ = -1;
    int seat_rotation_dof_ = -1, seat_axial_dof_ = -1;
    std::vector<int> node_offset_;         // per leaf: first full node index minus first_node
    int num_full_ = 0;
    Eigen::SparseMatrix<double> P_;        // full DOFs <- reduced DOFs
    Eigen::SparseMatrix<double> K_red_;
    Eigen::SparseMatrix<double> Gr_;       // contact rows x free DOFs (w excluded)
    Eigen::SparseMatrix<double> Krw_col_;  // K_rw as a sparse column
    Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> Krr_llt_;
};

}  // namespace stackbeam
