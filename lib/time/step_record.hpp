#pragma once
// Internal: what the time-stepping modes share: the part of a StepRecord they fill
// alike from the state (w, w', contact forces p) and the energies, and the contact
// bookkeeping of a step (anchors, the previous step's friction limits, the static
// equilibrium under gravity).
#include <Eigen/Dense>

#include "stackbeam/time/run_report.hpp"
#include "stackbeam/time/simulation.hpp"

namespace stackbeam::detail {

/// The loading's part of a record at one time (loading.hpp, StepRecord).
struct LoadState {
    double external_force_n = 0.0;   ///< whole spring [N]: F - m g - m y_b'' (rig: the spring force)
    double external_work_j = 0.0;    ///< whole spring [J]
    double base_displacement_m = 0.0;
    bool prescribed = false;         ///< w is prescribed: force_on_mass_n is m w''(t), not the force balance
    double force_on_mass_n = 0.0;    ///< prescribed only: m w''(t) [N]
};

/// Sets r's w, w', force on the mass, probe friction force, pair-state counts (by
/// `laws`, the pairs and their tau rule), kinetic energy, the given whole-spring strain
/// and dissipated energies [J], the loading's fields and the balance
/// e0 + external work - (kinetic + strain + dissipated) [J]. Leaves t, the
/// counters and the residual to the caller.
void fill_state(const System& system, const ContactProblem& laws, const Eigen::VectorXd& p, double w_m,
                double w_dot_m_per_s, double strain_energy_j, double dissipated_energy_j, double e0_j,
                const LoadState& load, StepRecord& r);

/// The pairs at one time (Stepper::pairs()): states by `laws` (the pairs and their tau
/// rule), forces p [N] and the relative positions rel = s + d [m], all rows; the gap of
/// a normal row is max(0, d0 - rel) with d0 the system's initial offsets.
std::vector<PairRecord> pair_records(const System& system, const ContactProblem& laws, const Eigen::VectorXd& p,
                                     const Eigen::VectorXd& rel);

/// The layer compliance for a SparseContactProblem (SparseContactProblem::layer_compliance):
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

/// A fixed-step mode's counters after one more step whose record is `r`: one step, its
/// contact iterations and factorisations added.
inline void count_step(const StepRecord& r, RunReport& report) {
    ++report.steps;
    report.contact_iterations += r.contact_iterations;
    report.factorizations += r.factorizations;
}

/// Anchors (paper, section 5): a pair that sticks keeps its d_t; every other tangential
/// row of `laws` (not bonded) is re-anchored where it is, d_t = rel_t. `p`: the forces
/// that give the states, `rel`: the relative positions s + d [m].
void reanchor(const ContactProblem& laws, const Eigen::VectorXd& p, const Eigen::VectorXd& rel, Eigen::VectorXd& d);

/// TauRule::previous_step: sets problem.tau_previous_n [N] per pair from the forces p of
/// the step before (|p_n| for a unilateral pair, max(0, F_c - p_n) at a clamp).
void set_previous_step_limits(ContactProblem& problem, const Eigen::VectorXd& p);

/// The static equilibrium of the massless stack under a force `force_n` [N] on R (meshed
/// part), as one quasi-static load step from the state with anchors d on the dense
/// compliance: k w - c^T p = F, s = C'p + c w - d, i.e. W = C' + c c^T/k, q = c F/k - d.
/// `laws` gives the pairs and tau rule, `p` the warm start and the forces on exit; d's
/// non-stuck pairs are re-anchored. Returns w [m] and the solve; throws SolverError
/// (naming `what`) if the contact solve fails.
struct StaticState {
    double w_m = 0.0;
    SolveResult solve;
};
StaticState static_equilibrium_dense(const System& system, const ContactProblem& laws, double force_n,
                                     ContactSolver& solver, Eigen::VectorXd& p, Eigen::VectorXd& d,
                                     const std::string& what);

}  // namespace stackbeam::detail
