// The shared set-up stage of the steppers (initial_state.hpp).
#include "time/initial_state.hpp"

#include <Eigen/SparseCholesky>
#include <cmath>
#include <string>
#include <vector>

#include "stackbeam/errors.hpp"
#include "fe/tied_shape.hpp"
#include "time/contact_state.hpp"
#include "time/held_seat.hpp"
#include "time/cvode/cvode_modes.hpp"
#include "time/reduced_load.hpp"
#include "time/static_stages.hpp"

namespace stackbeam::detail {

namespace {

void require_converged(const SolveResult& r) {
    if (!r.converged) throw SolverError("initial contact state: " + r.message, 0, 0.0, r.residual_m);
}

/// The contact state with R held at w0 (held_body_system) by `options`' solver on the start's
/// path: p [N] and z (w last) on exit, the pairs that slipped into it re-anchored where they are
/// (as held_seat_start and every step do): left at their anchors from before the solve, a pair
/// still slipping at step 1 was measured against the stale anchor and its friction did negative
/// work (decision 077: -2.8e-5 J at step 1 of a cosine rig stroke from 20 mm, closed-form).
void held_contact_state(const System& sys, InitialState& st, const SolverOptions& options) {
    const int w_dof = sys.num_reduced_dofs() - 1;
    StepProblem held;
    held.op = std::make_shared<const ContactOperator>(held_body_system(sys), st.path, options.kind);
    static_cast<ContactLaws&>(held) = st.laws;
    held.u = Eigen::VectorXd::Constant(1, st.w0_m);
    held.d = st.d;
    StepContactSolver solver(options, st.options.sparse_tuning);
    Eigen::VectorXd zr;
    st.solve = solver.solve(held, st.p, zr);
    require_converged(st.solve);
    if (st.z.size() != w_dof + 1) st.z = Eigen::VectorXd::Zero(w_dof + 1);
    st.z.head(w_dof) = zr;
    st.z[w_dof] = st.w0_m;
    reanchor(st.laws, st.p, relative_positions(sys, st.z, st.p), st.d);
}

/// The windup rig holds theta_R from the start (loading.seat_rotation_rad, theta_R(0) = 0 by
/// Loading::validate): on the full model the start's state is then the static one with R held at w0
/// and theta_R at theta_R(0), both prescribed, under the load b [N, N m per reduced DOF] (empty: none):
///     K_FF z_F = b_F - K_FH z_H + G_F^T p,   s = G_F z_F + c_L p - (d - G_H z_H),
/// H = {theta_R, w}, F the rest; the stiffness form on the sparse path with the exact solver (a
/// one-off solve, as static_state). The rig's moment at t = 0 is then the steppers' reaction on
/// theta_R. The pairs that slipped into the held state are re-anchored where they are (reanchor, as
/// after every step): left at their anchors from before this solve, a pair still slipping at step 1
/// was measured against the stale anchor and its friction did work (negative friction work,
/// decision 073). Returns false (nothing done) without the windup rig or on the half model.
bool held_seat_start(const System& sys, InitialState& st, const Eigen::VectorXd& b) {
    const int theta = sys.seat_rotation_dof(), nz = sys.num_reduced_dofs(), w_dof = nz - 1;
    if (!st.options.loading.windup_rig() || theta < 0) return false;
    const double theta0_rad = st.options.loading.seat_rotation_rad->value(0.0);
    const Eigen::SparseMatrix<double> S = held_seat_dofs(sys, true, true).S;  // F <- all
    Eigen::VectorXd zh = Eigen::VectorXd::Zero(nz);  // the held DOFs' values, 0 elsewhere
    zh[theta] = theta0_rad;
    zh[w_dof] = st.w0_m;
    const Eigen::SparseMatrix<double>& K = sys.stiffness_reduced();
    const Eigen::SparseMatrix<double>& G = sys.contact_rows();
    SparseStepForm form;
    form.K = S * K * S.transpose();
    form.G = G * S.transpose();
    form.layer_compliance = sparse_layer(sys);
    Eigen::VectorXd rhs = -(S * (K * zh));
    if (b.size() > 0) rhs += S * b;
    Eigen::VectorXd zf;
    if (sys.num_components() == 0) {  // no contact (a single leaf): K_FF z_F = b_F - K_FH z_H
        Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(form.K);
        zf = ldlt.solve(rhs);
        st.solve = SolveResult{};
        st.solve.converged = true;
    } else {
        StepSystem held;
        held.rows = sys.num_components();
        held.sparse = [&form] { return form; };
        StepProblem pr;
        pr.op = std::make_shared<const ContactOperator>(held, ContactPath::sparse, SolverKind::exact);
        static_cast<ContactLaws&>(pr) = st.laws;
        pr.u = rhs;
        pr.d = st.d - G * zh;
        SolverOptions exact = st.options.solver;
        exact.kind = SolverKind::exact;
        StepContactSolver solver(exact, st.options.sparse_tuning);
        st.solve = solver.solve(pr, st.p, zf);
        require_converged(st.solve);
    }
    st.z = Eigen::VectorXd(S.transpose() * zf) + zh;
    if (sys.num_components() > 0) reanchor(st.laws, st.p, relative_positions(sys, st.z, st.p), st.d);
    return true;
}

/// The massless stack: the assembly and R's weight -m g as static steps with R free (one solver
/// over both, on the start's path), then the contact state with R held at w0 (re-anchored).
void start_massless(const System& sys, InitialState& st, const SolverOptions& options) {
    const int n = sys.num_components();
    const Loading& L = st.options.loading;
    const double m = sys.mass_kg();
    StepContactSolver solver(options, st.options.sparse_tuning);
    const bool assemble = needs_assembly(sys.model().spec()) && n > 0;
    for (int stage = 0; stage < 2; ++stage) {  // 0: the assembly, 1: R's weight
        const double Fs = stage == 0 ? 0.0 : -m * L.gravity_m_per_s2;  // [N] on the meshed part
        if (stage == 0 ? !assemble : !(Fs != 0.0)) continue;
        const std::string what = stage == 0 ? "assembly of the cambered leaves" : "static equilibrium under gravity";
        StaticState s = massless_static_state(sys, st.laws, Fs, st.path, solver, st.p, st.d, what);
        st.w_static_m = s.w_m;
        st.z = std::move(s.z);
        st.solve = s.solve;
        st.pre_stressed = true;
    }
    const auto& rb = sys.model().spec().rigid_body;
    st.w0_m = st.rig ? L.displacement_m.value(0.0) : st.w_static_m + rb.initial_displacement_m;
    if (held_seat_start(sys, st, Eigen::VectorXd())) return;  // the windup rig: theta_R held too
    if (st.w0_m == st.w_static_m || n == 0) {  // z: the stages' (R at rest), or the unloaded stack's
        if (!st.pre_stressed || n == 0) st.z = sys.reduced_displacements(st.p, st.w0_m);
        return;
    }
    // the contact state with R held at w(0)
    held_contact_state(sys, st, options);
}

/// The whole stack with leaf mass: the assembly and the weight of everything as static steps, then
/// R held at w0 with the weight on, the leaves' velocity the tied shape of the closed rows times w'(0).
void start_whole_stack(const System& sys, InitialState& st, bool always_static) {
    const int n = sys.num_components(), w_dof = sys.num_reduced_dofs() - 1;
    const Loading& L = st.options.loading;
    const Eigen::VectorXd weight = -L.gravity_m_per_s2 * ReducedLoad(sys, L).inertia_kg();
    st.pre_stressed = static_stages(sys, st.laws, weight, st.options, st.z, st.p, st.d, &st.solve);
    if (st.z.size() == 0) st.z = Eigen::VectorXd::Zero(w_dof + 1);
    st.w_static_m = st.pre_stressed ? st.z[w_dof] : 0.0;
    const auto& rb = sys.model().spec().rigid_body;
    st.w0_m = st.rig ? L.displacement_m.value(0.0) : st.w_static_m + rb.initial_displacement_m;
    if (held_seat_start(sys, st, weight)) {
        // the windup rig: R held at w0 and theta_R at theta_R(0) (z set)
    } else if (st.pre_stressed || always_static) {
        if (st.w0_m != st.w_static_m)
            st.z = static_state(sys, st.laws, weight, st.w0_m, st.options, st.p, st.d, "initial contact state", &st.solve);
    } else {
        if (st.w0_m != 0.0 && n > 0) held_contact_state(sys, st, st.options.solver);
        st.z = sys.reduced_displacements(st.p, st.w0_m);
    }
    st.v0 = Eigen::VectorXd::Zero(w_dof + 1);
    if (st.wd0_m_per_s != 0.0) {
        const std::vector<int> tied = closed_rows(st.laws.pairs, relative_positions(sys, st.z, st.p), st.d);
        st.v0 = st.wd0_m_per_s * tied_shape(sys.stiffness_reduced(), sys.contact_rows(), tied, 1.0, Eigen::VectorXd::Zero(n));
    }
}

}  // namespace

InitialState initial_state(const StepperCapabilities& stepper, const System& system, const SimulationOptions& options) {
    InitialState st;
    st.options = options;
    st.options.loading.prepare(stepper.massive_leaves);  // validates the loading for the leaves' mass first
    check_capabilities(stepper, system, st.options);
    const Loading& L = st.options.loading;
    st.path = stepper.mode == Mode::cvode ? ContactPath::dense : choose_contact_path(system, st.options);
    st.laws.pairs = system.pairs();
    st.laws.tau_rule = st.options.tau_rule;
    st.laws.tau_previous_n = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(st.laws.pairs.size()));
    st.p = Eigen::VectorXd::Zero(system.num_components());
    st.d = system.initial_offsets_m();
    st.solve.converged = true;
    st.rig = L.kind == LoadingKind::prescribed_displacement;
    const auto& rb = system.model().spec().rigid_body;
    // base excitation: R's velocity relative to the supports, the initial velocity absolute (loading.hpp)
    st.wd0_m_per_s = st.rig ? L.displacement_m.derivative(0.0) : rb.initial_velocity_m_per_s - L.base_velocity_m_per_s(0.0);
    switch (stepper.start) {
        case StartKind::massless_stack: {
            start_massless(system, st, stepper.exact_start ? event_solver_options(options.solver, options.solver.tolerance_m)
                                                           : options.solver);
            break;
        }
        case StartKind::whole_stack: start_whole_stack(system, st, false); break;
        case StartKind::whole_stack_static: start_whole_stack(system, st, true); break;
        case StartKind::tied_shape: st.w0_m = rb.initial_displacement_m; break;
    }
    return st;
}

InitialState initial_state(const char* name, const System& system, const SimulationOptions& options) {
    options.validate();
    return initial_state(registered_stepper(name), system, options);
}

}  // namespace stackbeam::detail
