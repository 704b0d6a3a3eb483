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

/// The first pair of `system` with a contact row that has no elastic layer (a rigid interface
/// or a point clamp), or -1 when every row has one.
int first_rigid_pair(const System& system);

/// A loading on the reduced DOFs of a stack whose leaves may have mass (loading.hpp, with the
/// leaves' own inertia): q(t) = e_w F(t)/f - (g + y_b''(t)) l [N, meshed part], with
/// l = System::vertical_inertia_kg() (the leaves' weight and R's; massless leaves: l = m e_w,
/// and e_w^T q = Loading::external_force_n / f). A prescribed displacement adds nothing (the
/// rig's force is a reaction).
class ReducedLoad {
public:
    ReducedLoad(const System& system, const Loading& prepared)
        : load_(prepared), l_(system.vertical_inertia_kg()), f_(system.model().whole_spring_factor()) {}
    /// q(t) [N, N m per reduced DOF].
    Eigen::VectorXd at(double t_s) const {
        Eigen::VectorXd q = -(load_.gravity_m_per_s2 + base_acceleration(t_s)) * l_;
        if (load_.kind == LoadingKind::applied_force) q[q.size() - 1] += load_.force_n.value(t_s) / f_;
        return q;
    }
    /// y_b''(t) [m/s^2] (base excitation), 0 otherwise.
    double base_acceleration(double t_s) const {
        return load_.kind == LoadingKind::base_excitation ? load_.displacement_m.second_derivative(t_s) : 0.0;
    }
    /// Whether q is zero at every t.
    bool none() const {
        return load_.gravity_m_per_s2 == 0.0 &&
               (load_.kind == LoadingKind::initial_conditions || load_.kind == LoadingKind::prescribed_displacement);
    }
    const Eigen::VectorXd& inertia_kg() const { return l_; }

private:
    Loading load_;
    Eigen::VectorXd l_;
    double f_;
};

/// The quasi-static state of the stack under a load b on the reduced DOFs [N, N m per DOF]
/// (w last), one load step with friction from the warm start p with `laws`' pairs and tau rule
/// and the offsets d: with R free (w_held_m NaN) K z = G^T p + b on every DOF; with R held at
/// w_held_m [m] the rows of z_r only (z_w = w_held_m). Sparse path with the exact solver and
/// options' tuning, whatever the model's size (a one-off solve). On exit p holds the forces [N]
/// and d is re-anchored (reanchor). Returns z [m, rad]; throws SolverError naming `what` if the
/// solve fails; `result` (optional) receives the solve.
Eigen::VectorXd static_state(const System& system, const ContactProblem& laws, const Eigen::VectorXd& b, double w_held_m,
                             const SimulationOptions& options, Eigen::VectorXd& p, Eigen::VectorXd& d,
                             const std::string& what, SolveResult* result = nullptr);

/// The stack before t = 0 in the steppers with leaf mass (mode newmark, the massive cvode
/// stack), each stage a static_state with R free: the assembly of free camber, clips and
/// interference (needs_assembly; no load: the interference of the offsets d resolved with friction; simulation.hpp
/// "assembly"), then the static equilibrium under `weight` [N per reduced DOF] when it is not
/// zero (gravity: -g l). Returns whether a stage ran; z [m, rad], p [N] and d (re-anchored)
/// hold the state, `result` the last solve.
bool static_stages(const System& system, const ContactProblem& laws, const Eigen::VectorXd& weight,
                   const SimulationOptions& options, Eigen::VectorXd& z, Eigen::VectorXd& p, Eigen::VectorXd& d,
                   SolveResult* result = nullptr);

/// The rig's reaction on R's DOF (w last): adds lambda u_w to the accelerations a = M^-1 r so that
/// a_w = w_dd [m/s^2], u_w = M^-1 e_w [1/kg]; returns lambda = (w_dd - a_w) / (u_w)_w [N].
inline double prescribe_w_acceleration(Eigen::VectorXd& a, const Eigen::VectorXd& u_w, double w_dd) {
    const Eigen::Index w = a.size() - 1;
    const double lambda = (w_dd - a[w]) / u_w[w];
    a += lambda * u_w;
    return lambda;
}

/// The contact rows tied in the initial velocity shape of the steppers with leaf mass (the stack
/// moving with R, nothing impacting at t = 0): every bilateral normal row, a unilateral one whose
/// gap is closed (rel - d > -1e-12 m; rel = s + d the relative positions [m]), and the tangential
/// row of a closed pair that is bonded or carries friction.
std::vector<int> closed_rows(const std::vector<ContactPair>& pairs, const Eigen::VectorXd& rel, const Eigen::VectorXd& d);

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
