// The paper's closed-form step (eqs. 14-16) and its 8-step algorithm.
#include "stackbeam/simulation.hpp"

#include <cmath>
#include <limits>

#include "stackbeam/cvode_stepper.hpp"
#include "stackbeam/errors.hpp"
#include "cvode_inertia.hpp"
#include "stackbeam/newmark_stepper.hpp"
#include "mesh_note.hpp"
#include "step_record.hpp"

namespace stackbeam {

std::vector<std::string> step_record_columns() {
    return {"t",           "w",              "w_dot",          "force_on_mass",     "probe_friction_force",
            "contact_iterations", "n_stick", "n_slip",         "n_open",            "kinetic_energy",
            "strain_energy", "dissipated_energy", "energy_balance_error", "contact_residual", "factorizations",
            "spring_force", "external_force", "base_displacement", "external_work", "leaf_kinetic_energy",
            "impact_loss"};
}

std::vector<double> step_record_values(const StepRecord& r) {
    return {r.t_s,
            r.w_m,
            r.w_dot_m_per_s,
            r.force_on_mass_n,
            r.probe_friction_force_n,
            static_cast<double>(r.contact_iterations),
            static_cast<double>(r.n_stick),
            static_cast<double>(r.n_slip),
            static_cast<double>(r.n_open),
            r.kinetic_energy_j,
            r.strain_energy_j,
            r.dissipated_energy_j,
            r.energy_balance_error_j,
            r.contact_residual_m,
            static_cast<double>(r.factorizations),
            r.spring_force_n,
            r.external_force_n,
            r.base_displacement_m,
            r.external_work_j,
            r.leaf_kinetic_energy_j,
            r.impact_loss_j};
}

const char* to_string(Mode m) {
    switch (m) {
        case Mode::closed_form: return "closed-form";
        case Mode::cvode: return "cvode";
        case Mode::newmark: return "newmark";
    }
    return "?";
}

Mode parse_mode(const std::string& text, const std::string& field) {
    if (text == "closed-form") return Mode::closed_form;
    if (text == "cvode") return Mode::cvode;
    if (text == "newmark") return Mode::newmark;
    throw InputError(field, "value '" + text + "' is not a mode: allowed closed-form, cvode, newmark");
}

const char* to_string(ContactPath path) {
    switch (path) {
        case ContactPath::automatic: return "auto";
        case ContactPath::dense: return "dense";
        case ContactPath::sparse: return "sparse";
    }
    return "?";
}

ContactPath parse_contact_path(const std::string& text, const std::string& field) {
    if (text == "auto") return ContactPath::automatic;
    if (text == "dense") return ContactPath::dense;
    if (text == "sparse") return ContactPath::sparse;
    throw InputError(field, "value '" + text + "' is not a contact path: allowed auto, dense, sparse");
}

ContactPath choose_contact_path(const System& system, const SimulationOptions& options) {
    const bool exact = options.solver.kind == SolverKind::exact;
    switch (options.contact_path) {
        case ContactPath::dense: return ContactPath::dense;
        case ContactPath::sparse:
            if (!exact)
                throw InputError("contact_path", std::string("value 'sparse' needs the exact solver (solver is '") +
                                                     to_string(options.solver.kind) + "')");
            return ContactPath::sparse;
        case ContactPath::automatic: break;
    }
    return exact && system.num_components() >= kSparsePathMinComponents ? ContactPath::sparse : ContactPath::dense;
}

void SimulationOptions::validate() const {
    if (!std::isfinite(dt_s) || dt_s <= 0.0)
        throw InputError("dt", "value " + format_value(dt_s) + " is not allowed: the time step must be finite and > 0 [s]");
    if (!std::isfinite(t_end_s) || t_end_s <= 0.0)
        throw InputError("t_end", "value " + format_value(t_end_s) + " is not allowed: the end time must be finite and > 0 [s]");
    if (t_end_s / dt_s > 1e9)
        throw InputError("dt", "value " + format_value(dt_s) + " gives more than 1e9 steps to t_end = " + format_value(t_end_s) + " s");
    make_solver(solver);  // validates the solver options
    loading.validate();
    if (mode == Mode::cvode && loading.kind == LoadingKind::prescribed_displacement)
        throw InputError("loading.kind", "value 'prescribed-displacement' is not available in mode cvode: with w(t) "
                                         "imposed there is no equation of motion to integrate, each step is "
                                         "quasi-static (use mode closed-form, whose step is then exact)");
    if (mode == Mode::cvode) {
        if (!std::isfinite(cvode.rtol) || cvode.rtol < 1e-14 || cvode.rtol > 1e-2)
            throw InputError("rtol", "value " + format_value(cvode.rtol) +
                                         " is not allowed: CVODE's relative tolerance must be in [1e-14, 1e-2]");
        if (!std::isfinite(cvode.atol_m) || cvode.atol_m <= 0.0)
            throw InputError("atol", "value " + format_value(cvode.atol_m) +
                                         " is not allowed: the absolute tolerance on w must be finite and > 0 [m]");
        if (!std::isfinite(cvode.max_step_s) || cvode.max_step_s < 0.0)
            throw InputError("max_step", "value " + format_value(cvode.max_step_s) +
                                             " is not allowed: the largest step must be finite and >= 0 (0: no limit) [s]");
        if (!std::isfinite(cvode.modal_cutoff_rad_per_s) || cvode.modal_cutoff_rad_per_s < 0.0)
            throw InputError("modal_cutoff", "value " + format_value(cvode.modal_cutoff_rad_per_s) +
                                                 " is not allowed: the modal cut-off must be finite and >= 0 "
                                                 "(0: the default) [rad/s]");
        if (cvode.max_steps < 1)
            throw InputError("max_steps", "value " + std::to_string(cvode.max_steps) + " must be >= 1");
    }
    if (!std::isfinite(restitution) || restitution < 0.0 || restitution > 1.0)
        throw InputError("restitution", "value " + format_value(restitution) +
                                            " is not allowed: the restitution coefficient must be in [0, 1] "
                                            "(0: perfectly inelastic impacts, 1: elastic)");
    if (restitution > 0.0 && mode != Mode::newmark)
        throw InputError("restitution", "value " + format_value(restitution) + " is not used by mode " + to_string(mode) +
                                            ": only mode newmark with massive leaves has impacts (give 0)");
    if (mode == Mode::cvode && contact_path == ContactPath::sparse)
        throw InputError("contact_path", "value 'sparse' is not available in mode cvode: its mode sets are factorised "
                                         "on the dense compliance C' (use auto or dense)");
    if (contact_path == ContactPath::sparse && solver.kind != SolverKind::exact)
        throw InputError("contact_path", std::string("value 'sparse' needs the exact solver (solver is '") +
                                             to_string(solver.kind) + "')");
}

void require_massless_leaves(const System& system, Mode mode) {
    const auto& leaves = system.model().spec().leaves;
    for (std::size_t i = 0; i < leaves.size(); ++i)
        if (leaves[i].density_kg_per_m3 != 0.0)
            throw InputError("leaves[" + std::to_string(i) + "].density_kg_per_m3",
                             "value " + format_value(leaves[i].density_kg_per_m3) + " is not used by mode " +
                                 to_string(mode) + ", which treats the leaves as massless (the paper): give 0 "
                                 "(mode newmark integrates the leaves' inertia)");
}

ClosedFormStepper::ClosedFormStepper(const System& system, const SimulationOptions& options)
    : system_(system), options_(options) {
    options_.validate();
    require_massless_leaves(system_, Mode::closed_form);
    options_.loading.prepare();
    const Loading& load = options_.loading;
    rig_ = load.kind == LoadingKind::prescribed_displacement;
    require_loading_fits(system_.model().spec(), load);
    path_ = choose_contact_path(system_, options_);
    const int n = system_.num_components();
    const double k = system_.stiffness_n_per_m();
    const double m = system_.mass_kg();
    f_ = system_.model().whole_spring_factor();
    m_whole_ = system_.model().spec().rigid_body.mass_kg;
    omega_ = std::sqrt(k / m);
    const double x = omega_ * options_.dt_s;
    cos_ = std::cos(x);
    sin_ = std::sin(x);
    // gamma = 1 - sin(x)/x, by its series where the subtraction would cancel
    gamma_ = x < 1e-3 ? x * x / 6.0 - x * x * x * x / 120.0 : 1.0 - sin_ / x;

    problem_.pairs = system_.pairs();
    problem_.tau_rule = options_.tau_rule;
    problem_.tau_previous_n = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(problem_.pairs.size()));
    const auto& c = system_.coupling();
    d_ = system_.initial_offsets_m();
    p_ = Eigen::VectorXd::Zero(n);
    const auto& rb = system_.model().spec().rigid_body;
    const Eigen::SparseMatrix<double>& K = system_.stiffness_reduced();
    const Eigen::SparseMatrix<double>& G = system_.contact_rows();
    const int nz = static_cast<int>(K.rows());
    w_dof_ = nz - 1;
    if (path_ == ContactPath::sparse) {
        krw_ = Eigen::VectorXd(K.block(0, w_dof_, w_dof_, 1));
        gw_ = Eigen::VectorXd(G.col(w_dof_));
    }

    // 1. Gravity: the static equilibrium under R's weight, one quasi-static load step
    //    from the unloaded stack (loading.hpp): k w - c^T p = F_e, s = C'p + c w - d.
    w_ = 0.0;
    if (load.gravity_m_per_s2 > 0.0) {
        const double Fs = -m * load.gravity_m_per_s2;  // R's weight on the meshed part [N]
        const std::string what = "static equilibrium under gravity";
        if (path_ == ContactPath::dense) {
            auto solver = make_solver(options_.solver);
            const detail::StaticState st = detail::static_equilibrium_dense(system_, problem_, Fs, *solver, p_, d_, what);
            w_ = st.w_m;
            solve_ = st.solve;
        } else {
            SparseContactProblem st;
            st.K = K;
            st.G = G;
            st.b = Eigen::VectorXd::Zero(nz);
            st.b[w_dof_] = Fs;
            st.d = d_;
            st.pairs = problem_.pairs;
            st.tau_rule = problem_.tau_rule;
            st.tau_previous_n = problem_.tau_previous_n;
            SparseContactSolver solver(options_.solver, options_.sparse_tuning);
            solve_ = solver.solve(st, p_, z_);
            if (n > 0 && !solve_.converged) throw SolverError(what + ": " + solve_.message, 0, 0.0, solve_.residual_m);
            w_ = z_[w_dof_];
            detail::reanchor(problem_, p_, Eigen::VectorXd(G * z_), d_);
        }
    }
    // 2. The initial state: w(0), w'(0) (rig: the prescribed motion; base excitation:
    //    relative to the supports, whose velocity the initial absolute velocity excludes).
    double w_start = w_ + rb.initial_displacement_m;
    wd_ = rb.initial_velocity_m_per_s - load.base_velocity_m_per_s(0.0);
    if (rig_) {
        w_start = load.displacement_m.value(0.0);
        wd_ = load.displacement_m.derivative(0.0);
    }

    if (path_ == ContactPath::dense) {
        solver_ = make_solver(options_.solver);
        if (w_start != w_ && n > 0) {  // initial contact state with R held at w(0)
            problem_.W = system_.compliance_held();
            problem_.q = c * w_start - d_;
            solve_ = solver_->solve(problem_, p_);
            if (!solve_.converged) throw SolverError("initial contact state: " + solve_.message, 0, 0.0, solve_.residual_m);
        }
        w_ = w_start;
        // The rig holds R: each step is quasi-static with R held (W = C'); otherwise eq. 16.
        problem_.W = rig_ ? system_.compliance_held()
                          : Eigen::MatrixXd(system_.compliance_held() + (gamma_ / k) * c * c.transpose());
        problem_.q = Eigen::VectorXd::Zero(n);
        rel_ = system_.compliance_held() * p_ + c * w_;
    } else {
        // Sparse path (see simulation.hpp): K_aug = K + k_R e_w e_w^T, k_R = k (1 - gamma)/gamma,
        // with 1 - gamma = sin(x)/x taken directly (no cancellation for small x).
        if (!(sin_ > 0.0) && !rig_)
            throw InputError("dt", "value " + format_value(options_.dt_s) + " gives omega dt = " + format_value(x) +
                                       " >= pi: the sparse contact path needs omega dt < pi (use the dense path)");
        const double one_minus_gamma = x < 1e-3 ? 1.0 - x * x / 6.0 + x * x * x * x / 120.0 : sin_ / x;
        sparse_solver_ = std::make_unique<SparseContactSolver>(options_.solver, options_.sparse_tuning);
        if (z_.size() == 0) z_ = system_.reduced_displacements(p_, w_);
        SparseContactProblem held;  // R held at w: the problem on z_r
        held.K = K.topLeftCorner(w_dof_, w_dof_);
        held.G = G.leftCols(w_dof_);
        held.pairs = problem_.pairs;
        held.tau_rule = problem_.tau_rule;
        held.tau_previous_n = problem_.tau_previous_n;
        if (w_start != w_ && n > 0) {  // initial contact state with R held at w(0)
            held.b = -krw_ * w_start;
            held.d = d_ - gw_ * w_start;
            SparseContactSolver initial(options_.solver, options_.sparse_tuning);
            Eigen::VectorXd zr;
            solve_ = initial.solve(held, p_, zr);
            if (!solve_.converged) throw SolverError("initial contact state: " + solve_.message, 0, 0.0, solve_.residual_m);
            z_.head(w_dof_) = zr;
            z_[w_dof_] = w_start;
        }
        w_ = w_start;
        if (rig_) {
            sparse_problem_ = std::move(held);
        } else {
            Eigen::SparseMatrix<double> Kaug = K;
            k_r_ = k * one_minus_gamma / gamma_;
            Kaug.coeffRef(w_dof_, w_dof_) += k_r_;
            Kaug.makeCompressed();
            sparse_problem_.K = std::move(Kaug);
            sparse_problem_.G = G;
            sparse_problem_.b = Eigen::VectorXd::Zero(nz);
            sparse_problem_.pairs = problem_.pairs;
            sparse_problem_.tau_rule = problem_.tau_rule;
            sparse_problem_.tau_previous_n = problem_.tau_previous_n;
        }
        sparse_problem_.d = d_;
        rel_ = G * z_;
    }
    fe_ = rig_ ? 0.0 : load.external_force_n(0.0, m_whole_) / f_;
    fill_record(0, 0);
    e0_ = record_.kinetic_energy_j + record_.strain_energy_j;
    record_.energy_balance_error_j = 0.0;
}

void detail::reanchor(const ContactProblem& laws, const Eigen::VectorXd& p, const Eigen::VectorXd& rel,
                      Eigen::VectorXd& d) {
    for (std::size_t j = 0; j < laws.pairs.size(); ++j) {
        const auto& pr = laws.pairs[j];
        if (pr.row_t < 0 || pr.kind == PairKind::bonded) continue;
        if (pair_state(laws, static_cast<int>(j), p) != PairState::stick) d[pr.row_t] = rel[pr.row_t];
    }
}

void detail::set_previous_step_limits(ContactProblem& problem, const Eigen::VectorXd& p) {
    for (int j = 0; j < static_cast<int>(problem.pairs.size()); ++j) {
        const auto& pr = problem.pairs[j];
        const double pn = pr.row_n >= 0 ? p[pr.row_n] : 0.0;
        problem.tau_previous_n[j] = pr.kind == PairKind::clamp ? std::max(0.0, pr.preload_n - pn) : std::max(0.0, -pn);
    }
}

detail::StaticState detail::static_equilibrium_dense(const System& system, const ContactProblem& laws, double force_n,
                                                     ContactSolver& solver, Eigen::VectorXd& p, Eigen::VectorXd& d,
                                                     const std::string& what) {
    const double k = system.stiffness_n_per_m();
    const Eigen::VectorXd& c = system.coupling();
    StaticState out;
    if (system.num_components() > 0) {
        ContactProblem st = laws;
        st.W = system.compliance_held() + (1.0 / k) * c * c.transpose();
        st.q = c * (force_n / k) - d;
        out.solve = solver.solve(st, p);
        if (!out.solve.converged) throw SolverError(what + ": " + out.solve.message, 0, 0.0, out.solve.residual_m);
        reanchor(st, p, Eigen::VectorXd(st.W * p + st.q + d), d);
    }
    out.w_m = (force_n + (system.num_components() > 0 ? c.dot(p) : 0.0)) / k;
    return out;
}

void require_loading_fits(const ModelSpec& model, const Loading& loading) {
    const auto& rb = model.rigid_body;
    if (loading.kind == LoadingKind::prescribed_displacement) {
        if (rb.initial_displacement_m != 0.0)
            throw InputError("rigid_body.initial_displacement_m",
                             "value " + format_value(rb.initial_displacement_m) +
                                 " is not allowed with a prescribed displacement: w(0) is the prescribed w(0) (give 0)");
        if (rb.initial_velocity_m_per_s != 0.0)
            throw InputError("rigid_body.initial_velocity_m_per_s",
                             "value " + format_value(rb.initial_velocity_m_per_s) +
                                 " is not allowed with a prescribed displacement: w'(0) is the prescribed one (give 0)");
    }
}

void detail::fill_state(const System& system, const ContactProblem& laws, const Eigen::VectorXd& p, double w_m,
                        double w_dot_m_per_s, double strain_energy_j, double dissipated_energy_j, double e0_j,
                        const LoadState& load, StepRecord& r) {
    const double f = system.model().whole_spring_factor();
    r.w_m = w_m;
    r.w_dot_m_per_s = w_dot_m_per_s;
    const double cp = p.size() > 0 ? system.coupling().dot(p) : 0.0;
    r.spring_force_n = f * (system.stiffness_n_per_m() * w_m - cp);
    r.external_force_n = load.external_force_n;
    r.force_on_mass_n = load.prescribed ? load.force_on_mass_n : load.external_force_n - r.spring_force_n;
    r.base_displacement_m = load.base_displacement_m;
    r.external_work_j = load.external_work_j;
    // The probe pair may carry no tangential component (mu = 0, or fixed by a support):
    // its friction force is then zero. NaN only when the model has no probe at all.
    const int probe = system.probe_pair();
    const bool has_probe = system.model().probe_pair() >= 0;
    r.probe_friction_force_n = !has_probe ? std::numeric_limits<double>::quiet_NaN()
                               : (probe >= 0 && system.pairs()[probe].row_t >= 0) ? p[system.pairs()[probe].row_t]
                                                                                   : 0.0;
    r.n_stick = r.n_slip = r.n_open = 0;
    for (int k = 0; k < static_cast<int>(laws.pairs.size()); ++k) {
        const PairState s = pair_state(laws, k, p);
        if (s == PairState::stick) ++r.n_stick;
        else if (s == PairState::slip) ++r.n_slip;
        else ++r.n_open;
    }
    r.kinetic_energy_j = 0.5 * system.model().spec().rigid_body.mass_kg * w_dot_m_per_s * w_dot_m_per_s;
    r.strain_energy_j = strain_energy_j;
    r.dissipated_energy_j = dissipated_energy_j;
    r.energy_balance_error_j =
        e0_j + load.external_work_j - (r.kinetic_energy_j + r.strain_energy_j + r.dissipated_energy_j);
}

void ClosedFormStepper::fill_record(int iterations, int factorizations, double strain_j) {
    const double f = f_;
    const double k = system_.stiffness_n_per_m();
    // U = z^T K z / 2 = (p^T C' p + k w^2) / 2 on the meshed part (see system.hpp); the
    // sparse path has z itself and never builds C'. step() passes the sparse path's U
    // (strain_j >= 0), which it has without a product with K.
    const double strain = strain_j >= 0.0 ? strain_j
                          : path_ == ContactPath::dense
                              ? 0.5 * f * (p_.dot(system_.compliance_held() * p_) + k * w_ * w_)
                              : 0.5 * f * z_.dot(system_.stiffness_reduced() * z_);
    detail::LoadState load;
    load.external_work_j = wext_;
    load.base_displacement_m = options_.loading.base_displacement_m(t_);
    if (rig_) {
        load.prescribed = true;
        load.force_on_mass_n = m_whole_ * options_.loading.displacement_m.second_derivative(t_);
        load.external_force_n = f * (k * w_ - (p_.size() > 0 ? system_.coupling().dot(p_) : 0.0));
    } else {
        load.external_force_n = f * fe_;
    }
    detail::fill_state(system_, problem_, p_, w_, wd_, strain, dissipated_, e0_, load, record_);
    record_.t_s = t_;
    record_.contact_iterations = iterations;
    record_.factorizations = factorizations;
    record_.contact_residual_m = solve_.residual_m;
}

std::vector<PairState> ClosedFormStepper::pair_states() const {
    std::vector<PairState> s(problem_.pairs.size());
    for (std::size_t k = 0; k < s.size(); ++k) s[k] = pair_state(problem_, static_cast<int>(k), p_);
    return s;
}

const StepRecord& ClosedFormStepper::step() {
    const double k = system_.stiffness_n_per_m();
    const double dt = options_.dt_s;
    const auto& c = system_.coupling();
    const Loading& load = options_.loading;
    const double t1 = (step_ + 1) * dt;
    const double w0 = w_;
    const double cp0 = c.dot(p_);  // c^T p at t [N]
    const double kin0 = 0.5 * m_whole_ * wd_ * wd_;
    double w_next = 0.0, fe1 = 0.0, F0 = 0.0;
    if (rig_) {
        // The rig: w(t+dt) prescribed, the contact problem quasi-static with R held there.
        w_next = load.displacement_m.value(t1);
        if (path_ == ContactPath::dense) problem_.q = c * w_next - d_;
    } else {
        // Step 1: k1, k2 from w^t, w_dot^t; the part of w(t+dt) that does not depend on p(t+dt).
        // F = c^T p + F_e, both linear over the step (eq. 14; F_e the loading, loading.hpp).
        fe1 = load.external_force_n(t1, m_whole_) / f_;
        F0 = cp0 + fe_;
        w_next = w_ * cos_ + wd_ * sin_ / omega_ + F0 / k * (1.0 - cos_) - gamma_ * F0 / k + gamma_ * fe1 / k;
        // Steps 2-8: resolve the contact forces at t+dt, s = W p + q (eq. 6 with eq. 16).
        if (path_ == ContactPath::dense) problem_.q = c * w_next - d_;
    }
    if (problem_.tau_rule == TauRule::previous_step) detail::set_previous_step_limits(problem_, p_);
    const Eigen::VectorXd p0 = p_;
    if (path_ == ContactPath::dense) {
        solve_ = solver_->solve(problem_, p_);
    } else if (rig_) {
        sparse_problem_.b = -krw_ * w_next;
        sparse_problem_.d = d_ - gw_ * w_next;
        sparse_problem_.tau_previous_n = problem_.tau_previous_n;
        Eigen::VectorXd zr = z_.head(w_dof_);
        solve_ = sparse_solver_->solve(sparse_problem_, p_, zr, step_ > 0);  // the held K, G constant over the run
        z_.head(w_dof_) = zr;
        z_[w_dof_] = w_next;
    } else {
        sparse_problem_.b[w_dof_] = k / gamma_ * w_next;
        sparse_problem_.d = d_;
        sparse_problem_.tau_previous_n = problem_.tau_previous_n;
        solve_ = sparse_solver_->solve(sparse_problem_, p_, z_, step_ > 0);  // K, G constant over the run
    }
    ++step_;
    if (!solve_.converged && options_.stop_on_nonconvergence) {
        throw SolverError("contact solve failed at step " + std::to_string(step_) + ", t = " +
                              format_value(step_ * dt) + " s: " + solve_.message + detail::mesh_note(system_.model()),
                          step_, step_ * dt, solve_.residual_m);
    }
    const double cp1 = c.dot(p_);  // c^T p at t + dt [N]
    double w1 = 0.0, wd1 = 0.0;
    if (rig_) {
        w1 = w_next;
        wd1 = load.displacement_m.derivative(t1);
    } else {
        const double F1 = cp1 + fe1;
        w1 = w_next + gamma_ * cp1 / k;
        wd1 = wd_ * cos_ - w_ * omega_ * sin_ + F0 / k * omega_ * sin_ + (F1 - F0) / (k * dt) * (1.0 - cos_);
    }
    // Friction work, trapezoidal in time (p linear over the step, eq. 14), on the slip increments.
    // G z on the sparse path: the solver's s = G z - d at the solution, plus d (the rig's
    // held problem is posed on z_r with d - G_w w: add R's part G_w w back)
    Eigen::VectorXd rel1;
    if (path_ == ContactPath::dense) rel1 = problem_.W * p_ + problem_.q + d_;
    else if (rig_) rel1 = sparse_solver_->relative_positions() + sparse_problem_.d + gw_ * w_next;
    else rel1 = sparse_solver_->relative_positions() + sparse_problem_.d;
    double work = 0.0;
    for (const auto& pr : problem_.pairs)
        if (pr.row_t >= 0 && pr.kind != PairKind::bonded)
            work += 0.5 * (p0[pr.row_t] + p_[pr.row_t]) * (rel1[pr.row_t] - rel_[pr.row_t]);
    dissipated_ -= f_ * work;
    // External work, trapezoidal: the loading's force on R over dw (exact for a constant
    // force); the rig: its force on the spring over dw plus the kinetic energy it gives R.
    if (rig_) {
        const double spring0 = f_ * (k * w0 - cp0), spring1 = f_ * (k * w1 - cp1);
        wext_ += 0.5 * (spring0 + spring1) * (w1 - w0) + 0.5 * m_whole_ * wd1 * wd1 - kin0;
    } else {
        wext_ += 0.5 * f_ * (fe_ + fe1) * (w1 - w0);
        fe_ = fe1;
    }
    rel_ = rel1;
    w_ = w1;
    wd_ = wd1;
    t_ = step_ * dt;
    detail::reanchor(problem_, p_, rel_, d_);
    // Sparse path: U = z^T K z / 2 without a product with K, from K_aug z = b + G^T p
    // (the solved system, K_aug = K + k_R e_w e_w^T): z^T K z = b_w w + p^T (G z) - k_R w^2,
    // with G z = rel_ (made above). b_w w and k_R w^2 are each about 1/gamma times U
    // (~1e2-1e3 at dt = 1 ms): the difference loses that factor of round-off, 1e-13 relative.
    // (The rig's held problem is another system: fill_record takes z^T K z there.)
    double strain = -1.0;
    if (path_ == ContactPath::sparse && !rig_) {
        const double zw = z_[w_dof_];
        strain = 0.5 * f_ * (sparse_problem_.b[w_dof_] * zw + p_.dot(rel_) - k_r_ * zw * zw);
    }
    fill_record(solve_.iterations, solve_.factorizations, strain);
    return record_;
}

namespace {

/// The pairs at one time from the forces p and the relative positions rel = s + d.
std::vector<PairRecord> pair_records(const System& system, const ContactProblem& laws, const Eigen::VectorXd& p,
                                     const Eigen::VectorXd& rel) {
    std::vector<PairRecord> out(laws.pairs.size());
    const Eigen::VectorXd& d0 = system.initial_offsets_m();
    for (std::size_t k = 0; k < out.size(); ++k) {
        const ContactPair& pr = laws.pairs[k];
        const PairSpec& spec = system.pair_spec(static_cast<int>(k));
        PairRecord& r = out[k];
        r.pair = static_cast<int>(k);
        r.interface_index = spec.interface_index;
        r.x_m = spec.x_m;
        r.state = pair_state(laws, static_cast<int>(k), p);
        if (pr.row_n >= 0) {
            r.p_n_n = p[pr.row_n];
            r.gap_m = std::max(0.0, d0[pr.row_n] - rel[pr.row_n]);
        }
        if (pr.row_t >= 0) {
            r.p_t_n = p[pr.row_t];
            r.slip_m = rel[pr.row_t];
        }
    }
    return out;
}

}  // namespace

std::vector<StepRecord> simulate(const System& system, const SimulationOptions& options,
                                 const std::function<void(const StepRecord&)>& on_step, RunReport* report,
                                 const PairObserver& on_pairs) {
    options.validate();
    const long n = static_cast<long>(std::ceil(options.t_end_s / options.dt_s - 1e-9));
    std::vector<StepRecord> out;
    out.reserve(static_cast<std::size_t>(n) + 1);
    auto keep = [&](const StepRecord& r) {
        out.push_back(r);
        if (on_step) on_step(out.back());
    };
    RunReport rep;
    rep.mode = options.mode;
    // The event-driven cvode steppers: records, per-pair output (rel: the pairs'
    // relative positions s + d at the output), counters and the event log.
    ContactProblem cvode_laws;
    cvode_laws.pairs = system.pairs();
    cvode_laws.tau_rule = TauRule::current;
    auto run_events = [&](auto& stepper, const auto& relative_positions) {
        auto pairs_out = [&] {
            if (on_pairs)
                on_pairs(out.back().t_s, pair_records(system, cvode_laws, stepper.contact_forces(), relative_positions()));
        };
        keep(stepper.current());
        pairs_out();
        for (long i = 0; i < n; ++i) {
            keep(stepper.advance());
            pairs_out();
        }
        rep.cvode = stepper.stats();
        rep.events = stepper.events();
        rep.steps = rep.cvode.steps;
        rep.contact_iterations = rep.cvode.contact_iterations;
        rep.factorizations = rep.cvode.mode_factorizations;
    };
    if (options.mode == Mode::cvode && detail::has_leaf_mass(system) && detail::has_mode_changes(system)) {
        detail::CvodeModalStepper stepper(system, options);  // docs/inertia.md
        run_events(stepper, [&] { return stepper.relative_positions(); });
    } else if (options.mode == Mode::cvode && detail::has_leaf_mass(system)) {
        detail::CvodeInertiaStepper stepper(system, options);  // docs/inertia.md
        keep(stepper.current());
        for (long i = 0; i < n; ++i) keep(stepper.advance());
        rep.cvode = stepper.stats();
        rep.steps = rep.cvode.steps;
    } else if (options.mode == Mode::cvode) {
        CvodeStepper stepper(system, options);
        run_events(stepper, [&] {
            const Eigen::VectorXd& p = stepper.contact_forces();
            return p.size() > 0 ? Eigen::VectorXd(system.compliance_held() * p + system.coupling() * out.back().w_m)
                                : Eigen::VectorXd();
        });
    } else if (options.mode == Mode::newmark) {
        NewmarkStepper stepper(system, options);
        keep(stepper.current());
        for (long i = 0; i < n; ++i) {
            keep(stepper.step());
            rep.contact_iterations += out.back().contact_iterations;
            rep.factorizations += out.back().factorizations;
        }
        rep.steps = n;
    } else {
        ClosedFormStepper stepper(system, options);
        auto pairs_out = [&] {
            if (on_pairs)
                on_pairs(out.back().t_s, pair_records(system, stepper.last_problem(), stepper.contact_forces(),
                                                      stepper.relative_positions()));
        };
        keep(stepper.current());
        pairs_out();
        for (long i = 0; i < n; ++i) {
            keep(stepper.step());
            pairs_out();
            rep.contact_iterations += out.back().contact_iterations;
            rep.factorizations += out.back().factorizations;
        }
        rep.steps = n;
    }
    if (report) *report = std::move(rep);
    return out;
}

}  // namespace stackbeam
