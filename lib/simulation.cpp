// The paper's closed-form step (eqs. 14-16) and its 8-step algorithm.
#include "stackbeam/simulation.hpp"

#include <cmath>
#include <limits>

#include "stackbeam/cvode_stepper.hpp"
#include "stackbeam/errors.hpp"
#include "step_record.hpp"

namespace stackbeam {

std::vector<std::string> step_record_columns() {
    return {"t",           "w",              "w_dot",          "force_on_mass",     "probe_friction_force",
            "contact_iterations", "n_stick", "n_slip",         "n_open",            "kinetic_energy",
            "strain_energy", "dissipated_energy", "energy_balance_error", "contact_residual", "factorizations"};
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
            static_cast<double>(r.factorizations)};
}

const char* to_string(Mode m) {
    switch (m) {
        case Mode::closed_form: return "closed-form";
        case Mode::cvode: return "cvode";
    }
    return "?";
}

Mode parse_mode(const std::string& text, const std::string& field) {
    if (text == "closed-form") return Mode::closed_form;
    if (text == "cvode") return Mode::cvode;
    throw InputError(field, "value '" + text + "' is not a mode: allowed closed-form, cvode");
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
        if (cvode.max_steps < 1)
            throw InputError("max_steps", "value " + std::to_string(cvode.max_steps) + " must be >= 1");
    }
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
                                 "(the leaves' inertia is not integrated in time yet; modal_analysis() uses it)");
}

ClosedFormStepper::ClosedFormStepper(const System& system, const SimulationOptions& options)
    : system_(system), options_(options) {
    options_.validate();
    require_massless_leaves(system_, Mode::closed_form);
    path_ = choose_contact_path(system_, options_);
    const int n = system_.num_components();
    const double k = system_.stiffness_n_per_m();
    const double m = system_.mass_kg();
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
    w_ = system_.model().spec().rigid_body.initial_displacement_m;
    wd_ = system_.model().spec().rigid_body.initial_velocity_m_per_s;

    if (path_ == ContactPath::dense) {
        solver_ = make_solver(options_.solver);
        if (w_ != 0.0 && n > 0) {  // initial contact state with R held at w(0)
            problem_.W = system_.compliance_held();
            problem_.q = c * w_ - d_;
            solve_ = solver_->solve(problem_, p_);
            if (!solve_.converged) throw SolverError("initial contact state: " + solve_.message, 0, 0.0, solve_.residual_m);
        }
        problem_.W = system_.compliance_held() + (gamma_ / k) * c * c.transpose();
        problem_.q = Eigen::VectorXd::Zero(n);
        rel_ = system_.compliance_held() * p_ + c * w_;
    } else {
        // Sparse path (see simulation.hpp): K_aug = K + k_R e_w e_w^T, k_R = k (1 - gamma)/gamma,
        // with 1 - gamma = sin(x)/x taken directly (no cancellation for small x).
        if (!(sin_ > 0.0))
            throw InputError("dt", "value " + format_value(options_.dt_s) + " gives omega dt = " + format_value(x) +
                                       " >= pi: the sparse contact path needs omega dt < pi (use the dense path)");
        const double one_minus_gamma = x < 1e-3 ? 1.0 - x * x / 6.0 + x * x * x * x / 120.0 : sin_ / x;
        const Eigen::SparseMatrix<double>& K = system_.stiffness_reduced();
        const int nz = static_cast<int>(K.rows());
        w_dof_ = nz - 1;
        sparse_solver_ = std::make_unique<SparseContactSolver>(options_.solver);
        z_ = system_.reduced_displacements(p_, w_);
        if (w_ != 0.0 && n > 0) {  // initial contact state with R held at w(0): the problem on z_r
            const Eigen::SparseMatrix<double>& G = system_.contact_rows();
            SparseContactProblem held;
            held.K = K.topLeftCorner(w_dof_, w_dof_);
            held.G = G.leftCols(w_dof_);
            held.b = -Eigen::VectorXd(K.block(0, w_dof_, w_dof_, 1)) * w_;
            held.d = d_ - Eigen::VectorXd(G.col(w_dof_)) * w_;
            held.pairs = problem_.pairs;
            held.tau_rule = problem_.tau_rule;
            held.tau_previous_n = problem_.tau_previous_n;
            SparseContactSolver initial(options_.solver);
            Eigen::VectorXd zr;
            solve_ = initial.solve(held, p_, zr);
            if (!solve_.converged) throw SolverError("initial contact state: " + solve_.message, 0, 0.0, solve_.residual_m);
            z_.head(w_dof_) = zr;
        }
        Eigen::SparseMatrix<double> Kaug = K;
        k_r_ = k * one_minus_gamma / gamma_;
        Kaug.coeffRef(w_dof_, w_dof_) += k_r_;
        Kaug.makeCompressed();
        sparse_problem_.K = std::move(Kaug);
        sparse_problem_.G = system_.contact_rows();
        sparse_problem_.b = Eigen::VectorXd::Zero(nz);
        sparse_problem_.d = d_;
        sparse_problem_.pairs = problem_.pairs;
        sparse_problem_.tau_rule = problem_.tau_rule;
        sparse_problem_.tau_previous_n = problem_.tau_previous_n;
        rel_ = system_.contact_rows() * z_;
    }
    fill_record(0, 0);
    e0_ = record_.kinetic_energy_j + record_.strain_energy_j;
    record_.energy_balance_error_j = 0.0;
}

void detail::fill_state(const System& system, const ContactProblem& laws, const Eigen::VectorXd& p, double w_m,
                        double w_dot_m_per_s, double strain_energy_j, double dissipated_energy_j, double e0_j,
                        StepRecord& r) {
    const double f = system.model().whole_spring_factor();
    r.w_m = w_m;
    r.w_dot_m_per_s = w_dot_m_per_s;
    r.force_on_mass_n = f * (system.coupling().dot(p) - system.stiffness_n_per_m() * w_m);
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
    r.energy_balance_error_j = e0_j - (r.kinetic_energy_j + r.strain_energy_j + r.dissipated_energy_j);
}

void ClosedFormStepper::fill_record(int iterations, int factorizations, double strain_j) {
    const double f = system_.model().whole_spring_factor();
    const double k = system_.stiffness_n_per_m();
    // U = z^T K z / 2 = (p^T C' p + k w^2) / 2 on the meshed part (see system.hpp); the
    // sparse path has z itself and never builds C'. step() passes the sparse path's U
    // (strain_j >= 0), which it has without a product with K.
    const double strain = strain_j >= 0.0 ? strain_j
                          : path_ == ContactPath::dense
                              ? 0.5 * f * (p_.dot(system_.compliance_held() * p_) + k * w_ * w_)
                              : 0.5 * f * z_.dot(system_.stiffness_reduced() * z_);
    detail::fill_state(system_, problem_, p_, w_, wd_, strain, dissipated_, e0_, record_);
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
    // Step 1: k1, k2 from w^t, w_dot^t; the part of w(t+dt) that does not depend on p(t+dt).
    const double F0 = c.dot(p_);
    const double w_free = w_ * cos_ + wd_ * sin_ / omega_ + F0 / k * (1.0 - cos_) - gamma_ * F0 / k;
    // Steps 2-8: resolve the contact forces at t+dt, s = W p + q (eq. 6 with eq. 16).
    if (path_ == ContactPath::dense) problem_.q = c * w_free - d_;
    if (problem_.tau_rule == TauRule::previous_step)
        for (int j = 0; j < static_cast<int>(problem_.pairs.size()); ++j) {
            const auto& pr = problem_.pairs[j];
            const double pn = pr.row_n >= 0 ? p_[pr.row_n] : 0.0;
            problem_.tau_previous_n[j] = pr.kind == PairKind::clamp ? std::max(0.0, pr.preload_n - pn) : std::max(0.0, -pn);
        }
    const Eigen::VectorXd p0 = p_;
    if (path_ == ContactPath::dense) {
        solve_ = solver_->solve(problem_, p_);
    } else {
        sparse_problem_.b[w_dof_] = k / gamma_ * w_free;
        sparse_problem_.d = d_;
        sparse_problem_.tau_previous_n = problem_.tau_previous_n;
        solve_ = sparse_solver_->solve(sparse_problem_, p_, z_, step_ > 0);  // K, G constant over the run
    }
    ++step_;
    if (!solve_.converged && options_.stop_on_nonconvergence)
        throw SolverError("contact solve failed at step " + std::to_string(step_) + ", t = " +
                              format_value(step_ * dt) + " s: " + solve_.message,
                          step_, step_ * dt, solve_.residual_m);
    const double F1 = c.dot(p_);
    const double w1 = w_free + gamma_ * F1 / k;
    const double wd1 = wd_ * cos_ - w_ * omega_ * sin_ + F0 / k * omega_ * sin_ + (F1 - F0) / (k * dt) * (1.0 - cos_);
    // Friction work, trapezoidal in time (p linear over the step, eq. 14), on the slip increments.
    // G z on the sparse path: the solver's s = G z - d at the solution, plus d
    const Eigen::VectorXd rel1 = path_ == ContactPath::dense
                                     ? Eigen::VectorXd(problem_.W * p_ + problem_.q + d_)
                                     : Eigen::VectorXd(sparse_solver_->relative_positions() + sparse_problem_.d);
    double work = 0.0;
    for (const auto& pr : problem_.pairs)
        if (pr.row_t >= 0 && pr.kind != PairKind::bonded)
            work += 0.5 * (p0[pr.row_t] + p_[pr.row_t]) * (rel1[pr.row_t] - rel_[pr.row_t]);
    dissipated_ -= system_.model().whole_spring_factor() * work;
    rel_ = rel1;
    w_ = w1;
    wd_ = wd1;
    t_ = step_ * dt;
    // Anchors (paper, section 5): a pair that sticks keeps its d_t; any other is re-anchored where it is.
    for (std::size_t j = 0; j < problem_.pairs.size(); ++j) {
        const auto& pr = problem_.pairs[j];
        if (pr.row_t < 0 || pr.kind == PairKind::bonded) continue;
        if (pair_state(problem_, static_cast<int>(j), p_) != PairState::stick) d_[pr.row_t] = rel_[pr.row_t];
    }
    // Sparse path: U = z^T K z / 2 without a product with K, from K_aug z = b + G^T p
    // (the solved system, K_aug = K + k_R e_w e_w^T): z^T K z = b_w w + p^T (G z) - k_R w^2,
    // with G z = rel_ (made above). b_w w and k_R w^2 are each about 1/gamma times U
    // (~1e2-1e3 at dt = 1 ms): the difference loses that factor of round-off, 1e-13 relative.
    double strain = -1.0;
    if (path_ == ContactPath::sparse) {
        const double zw = z_[w_dof_];
        strain = 0.5 * system_.model().whole_spring_factor() *
                 (sparse_problem_.b[w_dof_] * zw + p_.dot(rel_) - k_r_ * zw * zw);
    }
    fill_record(solve_.iterations, solve_.factorizations, strain);
    return record_;
}

std::vector<StepRecord> simulate(const System& system, const SimulationOptions& options,
                                 const std::function<void(const StepRecord&)>& on_step, RunReport* report) {
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
    if (options.mode == Mode::cvode) {
        CvodeStepper stepper(system, options);
        keep(stepper.current());
        for (long i = 0; i < n; ++i) keep(stepper.advance());
        rep.cvode = stepper.stats();
        rep.events = stepper.events();
        rep.steps = rep.cvode.steps;
        rep.contact_iterations = rep.cvode.contact_iterations;
        rep.factorizations = rep.cvode.mode_factorizations;
    } else {
        ClosedFormStepper stepper(system, options);
        keep(stepper.current());
        for (long i = 0; i < n; ++i) {
            keep(stepper.step());
            rep.contact_iterations += out.back().contact_iterations;
            rep.factorizations += out.back().factorizations;
        }
        rep.steps = n;
    }
    if (report) *report = std::move(rep);
    return out;
}

}  // namespace stackbeam
