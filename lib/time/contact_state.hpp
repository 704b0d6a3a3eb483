#pragma once
// Internal: the contact bookkeeping the modes share: relative positions and the layer's
// energy from a state, the anchors after a step, the previous step's friction limits, and the
// rows closed at the start.
#include <Eigen/Dense>
#include <vector>

#include "stackbeam/contact/contact.hpp"
#include "stackbeam/fe/system.hpp"

namespace stackbeam::detail {

/// The layer compliance for a stiffness form (SparseStepForm::layer_compliance):
/// the system's c_L [m/N] when it has an elastic layer, else empty (rigid contact).
inline Eigen::VectorXd sparse_layer(const System& system) {
    return system.has_layer() ? system.layer_compliance_m_per_n() : Eigen::VectorXd();
}

/// The relative positions rel = s + d = G z + c_L p [m] from displacements z and forces p
/// (c_L the elastic layer's compliance, 0 on rigid interfaces: system.hpp).
inline Eigen::VectorXd relative_positions(const System& system, const Eigen::VectorXd& z, const Eigen::VectorXd& p) {
    Eigen::VectorXd rel = system.contact_rows() * z;
    if (system.has_layer()) rel += system.layer_compliance_m_per_n().cwiseProduct(p);
    return rel;
}

/// The layer's elastic energy p^T C_L p / 2 on the meshed part [J] (0 on rigid interfaces).
inline double layer_energy_j(const System& system, const Eigen::VectorXd& p) {
    if (!system.has_layer()) return 0.0;
    return 0.5 * p.dot(system.layer_compliance_m_per_n().cwiseProduct(p));
}

/// Anchors (paper, section 5): a pair that sticks keeps its d_t; every other tangential
/// row of `laws` (not bonded) is re-anchored where it is, d_t = rel_t. `p`: the forces
/// that give the states, `rel`: the relative positions s + d [m].
void reanchor(const ContactLaws& laws, const Eigen::VectorXd& p, const Eigen::VectorXd& rel, Eigen::VectorXd& d);

/// The contact rows tied in the initial velocity shape of the steppers with leaf mass (the stack
/// moving with R, nothing impacting at t = 0): every bilateral normal row, a unilateral one whose
/// gap is closed (rel - d > -1e-12 m; rel = s + d the relative positions [m]), and the tangential
/// row of a closed pair that is bonded or carries friction.
std::vector<int> closed_rows(const std::vector<ContactPair>& pairs, const Eigen::VectorXd& rel, const Eigen::VectorXd& d);

/// TauRule::previous_step: sets problem.tau_previous_n [N] per pair from the forces p of
/// the step before (|p_n| for a unilateral pair, max(0, F_c - p_n) at a clamp).
void set_previous_step_limits(ContactLaws& problem, const Eigen::VectorXd& p);

}  // namespace stackbeam::detail
