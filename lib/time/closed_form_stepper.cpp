// The paper's closed-form step (eqs. 14-16) and its 8-step algorithm (mode closed-form).
#include "stackbeam/time/closed_form_stepper.hpp"

#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "stackbeam/contact/step.hpp"
#include "stackbeam/errors.hpp"
#include "model/mesh_note.hpp"
#include "time/contact_state.hpp"
#include "time/held_seat.hpp"
#include "time/record.hpp"
#include "time/initial_state.hpp"
#include "time/static_stages.hpp"
#include "time/stepper_access.hpp"

namespace stackbeam {

// The stepper's state and its step (the public class forwards to it).
struct ClosedFormStepper::Impl {
    Impl(const System& system, const detail::InitialState& start);

    const StepRecord& advance();
    std::vector<PairRecord> pairs() const;
    std::vector<LeafNodes> nodes() const;
    Eigen::VectorXd displacements_now() const;
    std::vector<PairState> pair_states() const;

    const System& system_;
    SimulationOptions options_;
    std::shared_ptr<const ContactOperator> op_;  // the step's operator, dense or sparse (step.hpp)
    std::unique_ptr<StepContactSolver> contact_;
    ContactLaws problem_;        // the pair laws and the previous-step limits
    StepProblem step_problem_;   // the step's problem: u = [w_next], d
    Eigen::VectorXd z_;          // z at the start (the steps': the contact solve's, when read)
    int w_dof_ = -1;
    double k_r_ = 0.0;  // stiffness form: the rigid body's spring k_R [N/m] in K_aug
    SolveResult solve_;
    Eigen::VectorXd p_, d_, rel_;
    double w_ = 0.0, wd_ = 0.0, t_ = 0.0;
    double omega_ = 0.0, cos_ = 1.0, sin_ = 0.0, gamma_ = 0.0;
    double e0_ = 0.0, dissipated_ = 0.0;
    long step_ = 0;
    StepRecord record_;
    RunReport report_;
    // Loading (loading.hpp): the external force on R of the meshed part at t [N], the
    // external work [J, whole spring].
    bool rig_ = false;
    double f_ = 1.0, m_whole_ = 0.0, fe_ = 0.0, wext_ = 0.0;
    // Seat loads S = [M - H h; H] on theta_R, u_R (loading.hpp), condensed (System::SeatCondensation):
    // R feels -g^T S besides the vertical loading fv_ (fe_ = fv_ - g^T S), the contact offsets shift by B S.
    bool seat_ = false;
    System::SeatCondensation seat_c_;
    double fv_ = 0.0;                                          // the vertical loading on R at t [N]
    Eigen::Vector2d seat_motion_ = Eigen::Vector2d::Zero();    // [theta_R; u_R] at t [rad, m]
    Eigen::Vector2d seat_loads(double t_s) const {
        return {options_.loading.seat_moment_n_m_at(t_s), options_.loading.longitudinal_force_n_at(t_s)};
    }
    /// S in the state at t: 0 at the start (the initial state is unloaded at the seat), then S(t).
    Eigen::Vector2d seat_state() const { return step_ > 0 ? seat_loads(t_) : Eigen::Vector2d::Zero(); }
    // The held-seat form (the windup rig, or seat loads with the vertical rig; decision 069): the seat
    // condensation with theta_R held where the windup rig holds it (its moment M_theta a result:
    // theta_R = b^T p - g_0 w + F_00 M_theta + F_01 H solved for M_theta, a = 1/F_00), so
    //     s = C_h p + c_h w + L v - d,   R's force on the stack f = k_h w - c_h^T p + l^T v,
    //     C_h = C' - a b b^T,  c_h = c + a g_0 b,  k_h = k + a g_0^2,
    //     L = [a b, B_u - a F_01 b],  l = [a g_0, g_1 - a g_0 F_01],   v = [theta_R; H]
    // (theta_R free: C_h = C', c_h = c, k_h = k, L = B, l = g, v = S). u = [u0; v]: u0 = w(t+dt)
    // where the vertical rig holds R, else R's vertical loading F_v, R static (the windup rig is
    // quasi-static: R's inertia is out of its loop, as newmark's) and eliminated:
    // w = (F_v - l^T v + c_h^T p) / k_h. The operator's DOFs are the free ones (held_dofs_.free).
    bool windup_ = false, held_seat_ = false;
    double seat_a_ = 0.0, seat_kh_ = 0.0;
    Eigen::VectorXd seat_b_, seat_ch_;
    Eigen::MatrixXd seat_L_;
    Eigen::Vector2d seat_l_ = Eigen::Vector2d::Zero();
    detail::HeldSeatDofs held_dofs_;                         // the held-seat form's held and free DOFs
    Eigen::Vector2d seat_full_ = Eigen::Vector2d::Zero();    // [M_theta; H] on the seat at t [N m, N]
    double spring_ = 0.0;                                    // R's force on the stack at t [N, meshed part]
    /// The held-seat form's w [m] and seat loads [M_theta; H] for its u and the forces p.
    std::pair<double, Eigen::Vector2d> held_seat_state(const Eigen::VectorXd& u, const Eigen::VectorXd& p) const;
    /// The seat loads [M_theta; H] [N m, N] at R's w [m], v = [theta_R or M; H] and the forces p.
    Eigen::Vector2d held_seat_loads(double w, const Eigen::Vector2d& v, const Eigen::VectorXd& p) const;
    /// z (every DOF) from the held-seat form's free DOFs z_F and its u.
    Eigen::VectorXd held_seat_z(const Eigen::VectorXd& zf, const Eigen::VectorXd& u) const;
    StepSystem held_seat_system();
    const StepRecord& advance_held_seat();
    /// The step's end: the state at t + dt (R at w1, w1'), the anchors, the record.
    const StepRecord& finish_step(const Eigen::VectorXd& rel1, double w1, double wd1);
    /// SolverError (step, time, residual) where the step's solve failed and options_.stop_on_nonconvergence.
    void check_solve() const;
    /// Friction work [J, whole spring] over the step from p0 to p_, rel_ to rel1 (trapezoidal: p linear).
    double friction_work(const Eigen::VectorXd& p0, const Eigen::VectorXd& rel1) const;
    /// U [J, whole spring] from z (w last) and p.
    double strain_of(const Eigen::VectorXd& z, const Eigen::VectorXd& p) const;
    /// z of the rig's state: z_r and R held at w.
    Eigen::VectorXd held_z(const Eigen::VectorXd& zr, double w) const;
    void fill_record(int iterations, int factorizations, double strain);
};

ClosedFormStepper::ClosedFormStepper(const System& system, const SimulationOptions& options)
    : impl_(std::make_unique<Impl>(system, detail::initial_state("closed-form", system, options))) {}

ClosedFormStepper::ClosedFormStepper(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

std::unique_ptr<Stepper> ClosedFormStepperAccess::build(const System& system, const detail::InitialState& start) {
    return std::unique_ptr<Stepper>(new ClosedFormStepper(std::make_unique<ClosedFormStepper::Impl>(system, start)));
}

ClosedFormStepper::~ClosedFormStepper() = default;

const StepRecord& ClosedFormStepper::advance() { return impl_->advance(); }
const StepRecord& ClosedFormStepper::current() const noexcept { return impl_->record_; }
long ClosedFormStepper::record_index() const noexcept { return impl_->step_; }
std::vector<PairRecord> ClosedFormStepper::pairs() const { return impl_->pairs(); }
std::vector<LeafNodes> ClosedFormStepper::nodes() const { return impl_->nodes(); }
Stresses ClosedFormStepper::stresses() const { return compute_stresses(impl_->system_, impl_->displacements_now(), pairs()); }
RunReport ClosedFormStepper::report() const { return impl_->report_; }
const Eigen::VectorXd& ClosedFormStepper::contact_forces() const noexcept { return impl_->p_; }
const Eigen::VectorXd& ClosedFormStepper::relative_positions() const noexcept { return impl_->rel_; }
const Eigen::VectorXd& ClosedFormStepper::anchors() const noexcept { return impl_->d_; }
std::vector<PairState> ClosedFormStepper::pair_states() const { return impl_->pair_states(); }
const StepContactSolver& ClosedFormStepper::contact_solver() const noexcept { return *impl_->contact_; }
ContactPath ClosedFormStepper::contact_path() const noexcept { return impl_->op_->path(); }
Eigen::VectorXd ClosedFormStepper::reduced_displacements() const { return impl_->displacements_now(); }
const SolveResult& ClosedFormStepper::last_solve() const noexcept { return impl_->solve_; }
const System& ClosedFormStepper::system() const noexcept { return impl_->system_; }
double ClosedFormStepper::omega_rad_per_s() const noexcept { return impl_->omega_; }

ClosedFormStepper::Impl::Impl(const System& system, const detail::InitialState& start)
    : system_(system), options_(start.options), problem_(start.laws), z_(start.z),
      solve_(start.solve), p_(start.p), d_(start.d), w_(start.w0_m), wd_(start.wd0_m_per_s), rig_(start.rig) {
    const Loading& load = options_.loading;
    const int n = system_.num_components();
    const double k = system_.stiffness_n_per_m();
    f_ = system_.model().whole_spring_factor();
    m_whole_ = system_.model().spec().rigid_body.mass_kg;
    report_.mode = Mode::closed_form;
    omega_ = std::sqrt(k / system_.mass_kg());
    const double x = omega_ * options_.dt_s;
    cos_ = std::cos(x);
    sin_ = std::sin(x);
    // gamma = 1 - sin(x)/x, by its series where the subtraction would cancel
    gamma_ = x < 1e-3 ? x * x / 6.0 - x * x * x * x / 120.0 : 1.0 - sin_ / x;
    const Eigen::VectorXd& c = system_.coupling();
    w_dof_ = system_.num_reduced_dofs() - 1;
    // The initial state (the assembly, gravity, R held at w(0): initial_state.hpp) is the start's.
    // The step's contact problem in both forms (closed_form_stepper.hpp); the operator takes one.
    // u = [w_next]. Dense: W = C' + (gamma/k) c c^T (the rig holds R: W = C'), q = c w_next - d.
    // Sparse: K_aug = K + k_R e_w e_w^T, k_R = k (1 - gamma)/gamma, b = (k/gamma) w_next e_w; the
    // rig: K_rr z_r = -K_rw w_next + G_r^T p, s = G_r z_r + c_L p - (d - G_w w_next).
    // Each form gives the step's strain energy its own way (the operator evaluates the one it took):
    // U = (p^T C' p + k w^2) / 2 on the dense form (w = w_next + gamma c^T p / k; the rig: w_next),
    // z^T K z / 2 + p^T C_L p / 2 on the sparse one (advance(): without a product with K).
    // seat loads: u = [w_next; S]; with the vertical rig, or the windup rig: the held-seat form
    seat_ = load.has_seat_load();
    windup_ = load.windup_rig();
    held_seat_ = windup_ || (rig_ && seat_);
    StepSystem sys = rig_ && !held_seat_ ? detail::held_body_system(system_) : StepSystem{};
    // the seat's motion is recorded on every full model (an asymmetric spring's seat turns under a vertical load)
    if (system_.seat_rotation_dof() >= 0) seat_c_ = system_.seat_condensation();
    const auto dense_energy = [this, k](double w, const Eigen::VectorXd& p) {
        return 0.5 * f_ * (p.dot(system_.compliance_held() * p) + k * w * w);
    };
    if (held_seat_) {
        sys = held_seat_system();
    } else if (rig_) {
        sys.dense = [this, dense_energy, held = sys.dense] {
            DenseStepForm f = held();
            f.strain_energy_j = [dense_energy](const Eigen::VectorXd& u, const Eigen::VectorXd& p) {
                return dense_energy(u[0], p);
            };
            return f;
        };
        sys.sparse = [this, held = sys.sparse] {
            SparseStepForm f = held();
            f.strain_energy_j = [this](const Eigen::VectorXd& u, const Eigen::VectorXd& p, const Eigen::VectorXd& zr,
                                       const Eigen::VectorXd&) { return strain_of(held_z(zr, u[0]), p); };
            return f;
        };
    } else {
        sys.rows = n;
        sys.dense = [&, dense_energy] {
            DenseStepForm f;
            f.W = system_.compliance_held() + (gamma_ / k) * c * c.transpose();
            f.Q.resize(n, seat_ ? 3 : 1);
            f.Q.col(0) = c;
            if (seat_) f.Q.rightCols(2) = seat_c_.B;  // s = C' p + c w + B S - d
            // z = (z_r, w) with R free at w = w_next + gamma c^T p / k (the step's w(t + dt)), and the
            // seat loads S = u.tail(2) on theta_R, u_R
            f.displacements = [this, k, &c](const Eigen::VectorXd& u, const Eigen::VectorXd& p) {
                const double w = u[0] + gamma_ * c.dot(p) / k;
                return seat_ ? system_.reduced_displacements(p, w, Eigen::Vector2d(u.tail(2)))
                             : system_.reduced_displacements(p, w);
            };
            f.strain_energy_j = [this, k, &c, dense_energy](const Eigen::VectorXd& u, const Eigen::VectorXd& p) {
                // with seat loads the free DOFs are loaded: (p^T C' p + k w^2) / 2 no longer holds; z is
                // the step's displacements (computed once per solve, as the nodes read them)
                return seat_ ? strain_of(contact_->displacements(), p) : dense_energy(u[0] + gamma_ * c.dot(p) / k, p);
            };
            return f;
        };
        sys.sparse = [&] {
            // 1 - gamma = sin(x)/x taken directly (no cancellation for small x)
            if (!(sin_ > 0.0))
                throw InputError("dt", "value " + format_value(options_.dt_s) + " gives omega dt = " + format_value(x) +
                                           " >= pi: the sparse contact path needs omega dt < pi (use the dense path)");
            const double one_minus_gamma = x < 1e-3 ? 1.0 - x * x / 6.0 + x * x * x * x / 120.0 : sin_ / x;
            SparseStepForm f;
            f.K = system_.stiffness_reduced();
            f.G = system_.contact_rows();
            f.layer_compliance = detail::sparse_layer(system_);
            k_r_ = k * one_minus_gamma / gamma_;
            f.K.coeffRef(w_dof_, w_dof_) += k_r_;
            f.K.makeCompressed();
            f.B.resize(w_dof_ + 1, seat_ ? 3 : 1);
            f.B.insert(w_dof_, 0) = k / gamma_;
            if (seat_) {  // the seat loads on their DOFs (a DOF the seat lacks carries nothing)
                if (system_.seat_rotation_dof() >= 0) f.B.insert(system_.seat_rotation_dof(), 1) = 1.0;
                if (system_.seat_axial_dof() >= 0) f.B.insert(system_.seat_axial_dof(), 2) = 1.0;
                // and their condensed force on R, -g^T S, which w_next (the dense form's) holds:
                // R's row of K_aug z = B u reads (k/gamma) (w_next + (gamma/k) g^T S)
                f.B.insert(w_dof_, 1) = seat_c_.g[0];
                f.B.insert(w_dof_, 2) = seat_c_.g[1];
            }
            f.B.makeCompressed();
            // U without a product with K, from K_aug z = b + G^T p (the solved system, K_aug = K +
            // k_R e_w e_w^T): z^T K z = b_w w + p^T (G z) - k_R w^2, with G z = rel (with an elastic
            // layer the solved system is the augmented one, sparse_solver.cpp, and p^T rel = p^T G z +
            // p^T C_L p adds the layer's energy twice over, as z^T K z does for the leaves). b_w w and
            // k_R w^2 are each about 1/gamma times U (~1e2-1e3 at dt = 1 ms): the difference loses
            // that factor of round-off, 1e-13 relative.
            f.strain_energy_j = [this, k](const Eigen::VectorXd& u, const Eigen::VectorXd& p, const Eigen::VectorXd& z,
                                          const Eigen::VectorXd& rel) {
                if (seat_) return strain_of(z, p);  // b has the seat loads' terms too: z^T K z directly
                const double zw = z[w_dof_];
                return 0.5 * f_ * (k / gamma_ * u[0] * zw + p.dot(rel) - k_r_ * zw * zw);
            };
            return f;
        };
    }
    contact_ = start_step_contact(sys, options_.contact_path, options_.solver, options_.sparse_tuning, problem_.pairs,
                                  problem_.tau_rule, step_problem_);
    op_ = step_problem_.op;
    step_problem_.u = Eigen::VectorXd::Zero(seat_ || held_seat_ ? 3 : 1);
    // relative positions and strain energy at the start: from the start's z
    rel_ = detail::relative_positions(system_, z_, p_);
    fv_ = rig_ ? 0.0 : load.external_force_n(0.0, m_whole_) / f_;
    fe_ = seat_ && !held_seat_ ? fv_ - seat_c_.g.dot(seat_loads(0.0)) : fv_;  // (seat loads: the full model, f = 1)
    if (system_.seat_rotation_dof() >= 0) seat_motion_ = seat_c_.B.transpose() * p_ - seat_c_.g * w_;
    spring_ = k * w_ - (p_.size() > 0 ? c.dot(p_) : 0.0);  // the start: no seat load on the stack
    if (windup_) {  // ...but the windup rig's moment, which holds theta_R at theta_R(0) from the start (initial_state.cpp)
        seat_full_ = held_seat_loads(w_, Eigen::Vector2d(load.seat_rotation_rad->value(0.0), 0.0), p_);
        spring_ += seat_c_.g.dot(seat_full_);
        seat_motion_ += seat_c_.F * seat_full_;
    }
    fill_record(0, 0, strain_of(z_, p_));
    e0_ = record_.kinetic_energy_j + record_.strain_energy_j;
    record_.energy_balance_error_j = 0.0;
}

double ClosedFormStepper::Impl::strain_of(const Eigen::VectorXd& z, const Eigen::VectorXd& p) const {
    // U = z^T K z / 2 + p^T C_L p / 2 = (p^T C' p + k w^2) / 2 on the meshed part, leaves and
    // elastic layer (see system.hpp)
    return f_ * (0.5 * z.dot(system_.stiffness_reduced() * z) + detail::layer_energy_j(system_, p));
}

Eigen::VectorXd ClosedFormStepper::Impl::held_z(const Eigen::VectorXd& zr, double w) const {
    Eigen::VectorXd z(w_dof_ + 1);
    z.head(w_dof_) = zr;
    z[w_dof_] = w;
    return z;
}

void ClosedFormStepper::Impl::fill_record(int iterations, int factorizations, double strain) {
    const double f = f_;
    const double k = system_.stiffness_n_per_m();
    detail::LoadState load;
    load.external_work_j = wext_;
    load.base_displacement_m = options_.loading.base_displacement_m(t_);
    if (rig_) {
        load.prescribed = true;
        load.force_on_mass_n = m_whole_ * options_.loading.displacement_m.second_derivative(t_);
        load.external_force_n = f * (k * w_ - (p_.size() > 0 ? system_.coupling().dot(p_) : 0.0));
    } else {
        load.external_force_n = f * fv_;
    }
    detail::fill_state(system_, problem_, p_, w_, wd_, strain, dissipated_, e0_, load, record_);
    if (held_seat_) {  // R's force on the stack and the seat's moment are the form's (held_seat_state)
        record_.external_force_n = f * (rig_ ? spring_ : fv_);
        record_.spring_force_n = f * spring_;
        record_.force_on_mass_n = rig_ && !windup_ ? load.force_on_mass_n : 0.0;
        record_.seat_moment_n_m = windup_ ? seat_full_[0] : seat_loads(t_)[0];
        if (windup_) {  // the windup rig leaves R's inertia out of its loop: no kinetic energy
            record_.kinetic_energy_j = 0.0;
            record_.energy_balance_error_j =
                e0_ + wext_ - (record_.strain_energy_j + record_.dissipated_energy_j);
        }
    } else if (seat_) {  // R's force on the stack with the state's seat loads (SeatCondensation), and the seat's records
        record_.spring_force_n += f * seat_c_.g.dot(seat_state());
        record_.force_on_mass_n = record_.external_force_n - record_.spring_force_n;
        record_.seat_moment_n_m = seat_loads(t_)[0];
    }
    record_.seat_rotation_rad = seat_motion_[0];
    record_.seat_axial_m = seat_motion_[1];
    record_.t_s = t_;
    record_.contact_iterations = iterations;
    record_.factorizations = factorizations;
    record_.contact_residual_m = solve_.residual_m;
}

std::pair<double, Eigen::Vector2d> ClosedFormStepper::Impl::held_seat_state(const Eigen::VectorXd& u,
                                                                              const Eigen::VectorXd& p) const {
    const Eigen::Vector2d v = u.tail(2);
    const double chp = p.size() > 0 ? seat_ch_.dot(p) : 0.0;
    const double w = rig_ ? u[0] : (u[0] - seat_l_.dot(v) + chp) / seat_kh_;
    return {w, held_seat_loads(w, v, p)};
}

Eigen::Vector2d ClosedFormStepper::Impl::held_seat_loads(double w, const Eigen::Vector2d& v, const Eigen::VectorXd& p) const {
    Eigen::Vector2d S(v[0], v[1]);
    if (windup_) {  // M_theta holds theta_R at v[0]: theta_R = b^T p - g_0 w + F_00 M_theta + F_01 H
        const double bp = p.size() > 0 ? seat_b_.dot(p) : 0.0;
        S[0] = seat_a_ * (v[0] - bp + seat_c_.g[0] * w - seat_c_.F(0, 1) * v[1]);
    }
    return S;
}

Eigen::VectorXd ClosedFormStepper::Impl::held_seat_z(const Eigen::VectorXd& zf, const Eigen::VectorXd& u) const {
    Eigen::VectorXd z(w_dof_ + 1);
    for (std::size_t i = 0; i < held_dofs_.free.size(); ++i) z[held_dofs_.free[i]] = zf[static_cast<Eigen::Index>(i)];
    if (windup_) z[system_.seat_rotation_dof()] = u[1];
    if (rig_) z[w_dof_] = u[0];
    return z;
}

StepSystem ClosedFormStepper::Impl::held_seat_system() {
    const double k = system_.stiffness_n_per_m();
    const Eigen::VectorXd& c = system_.coupling();
    const System::SeatCondensation& sc = seat_c_;
    const int theta = system_.seat_rotation_dof(), axial = system_.seat_axial_dof();
    if (windup_) {
        seat_a_ = 1.0 / sc.F(0, 0);
        seat_b_ = sc.B.col(0);
        seat_ch_ = c + seat_a_ * sc.g[0] * seat_b_;
        seat_kh_ = k + seat_a_ * sc.g[0] * sc.g[0];
        seat_L_.resize(c.size(), 2);
        seat_L_.col(0) = seat_a_ * seat_b_;
        seat_L_.col(1) = sc.B.col(1) - seat_a_ * sc.F(0, 1) * seat_b_;
        seat_l_ = {seat_a_ * sc.g[0], sc.g[1] - seat_a_ * sc.g[0] * sc.F(0, 1)};
    } else {
        seat_ch_ = c;
        seat_kh_ = k;
        seat_L_ = sc.B;
        seat_l_ = sc.g;
    }
    held_dofs_ = detail::held_seat_dofs(system_, windup_, rig_);
    StepSystem sys;
    sys.rows = system_.num_components();
    sys.dense = [this] {
        DenseStepForm f;
        f.W = system_.compliance_held();
        if (windup_) f.W -= seat_a_ * seat_b_ * seat_b_.transpose();  // C_h: symmetric to the bit (b_i b_j)
        f.Q.resize(seat_ch_.size(), 3);
        if (rig_) {  // s = C_h p + c_h w + L v - d
            f.Q.col(0) = seat_ch_;
            f.Q.rightCols(2) = seat_L_;
        } else {  // R static, eliminated: s = (C_h + c_h c_h^T / k_h) p + c_h (F_v - l^T v) / k_h + L v - d
            f.W += seat_ch_ * seat_ch_.transpose() / seat_kh_;
            f.Q.col(0) = seat_ch_ / seat_kh_;
            f.Q.rightCols(2) = seat_L_ - seat_ch_ * seat_l_.transpose() / seat_kh_;
        }
        f.displacements = [this](const Eigen::VectorXd& u, const Eigen::VectorXd& p) {  // z_F
            const auto [w, S] = held_seat_state(u, p);
            const Eigen::VectorXd z = system_.reduced_displacements(p, w, S);
            Eigen::VectorXd zf(static_cast<Eigen::Index>(held_dofs_.free.size()));
            for (std::size_t i = 0; i < held_dofs_.free.size(); ++i) zf[static_cast<Eigen::Index>(i)] = z[held_dofs_.free[i]];
            return zf;
        };
        f.strain_energy_j = [this](const Eigen::VectorXd& u, const Eigen::VectorXd& p) {
            return strain_of(held_seat_z(contact_->displacements(), u), p);
        };
        return f;
    };
    sys.sparse = [this, theta, axial] {
        // K_FF z_F = B u + G_F^T p, s = G_F z_F + c_L p - (d - E u): a held DOF h moves the free ones by
        // -K_Fh u_h and the offsets by G_h u_h; a free one takes its load (F_v on w, S_0 on theta_R, H on u_R)
        const Eigen::SparseMatrix<double>& K = system_.stiffness_reduced();
        const Eigen::SparseMatrix<double>& G = system_.contact_rows();
        const std::vector<int>& index = held_dofs_.index;
        const int nf = static_cast<int>(held_dofs_.free.size());
        std::vector<Eigen::Triplet<double>> kt, gt, bt, et;
        const int dofs[3] = {w_dof_, theta, axial};
        for (int col = 0; col < K.outerSize(); ++col)
            for (Eigen::SparseMatrix<double>::InnerIterator it(K, col); it; ++it) {
                const int r = index[static_cast<std::size_t>(it.row())], cf = index[static_cast<std::size_t>(it.col())];
                if (r >= 0 && cf >= 0) kt.emplace_back(r, cf, it.value());
                for (int j = 0; j < 3; ++j)
                    if (r >= 0 && dofs[j] >= 0 && it.col() == dofs[j] && cf < 0) bt.emplace_back(r, j, -it.value());
            }
        for (int col = 0; col < G.outerSize(); ++col)
            for (Eigen::SparseMatrix<double>::InnerIterator it(G, col); it; ++it) {
                const int cf = index[static_cast<std::size_t>(it.col())];
                if (cf >= 0) gt.emplace_back(it.row(), cf, it.value());
                for (int j = 0; j < 3; ++j)
                    if (dofs[j] >= 0 && it.col() == dofs[j] && cf < 0) et.emplace_back(it.row(), j, it.value());
            }
        for (int j = 0; j < 3; ++j)
            if (dofs[j] >= 0 && index[static_cast<std::size_t>(dofs[j])] >= 0) bt.emplace_back(index[static_cast<std::size_t>(dofs[j])], j, 1.0);
        SparseStepForm f;
        f.K.resize(nf, nf);
        f.K.setFromTriplets(kt.begin(), kt.end());
        f.G.resize(G.rows(), nf);
        f.G.setFromTriplets(gt.begin(), gt.end());
        f.layer_compliance = detail::sparse_layer(system_);
        f.B.resize(nf, 3);
        f.B.setFromTriplets(bt.begin(), bt.end());
        f.E.resize(G.rows(), 3);
        f.E.setFromTriplets(et.begin(), et.end());
        f.strain_energy_j = [this](const Eigen::VectorXd& u, const Eigen::VectorXd& p, const Eigen::VectorXd& zf,
                                   const Eigen::VectorXd&) { return strain_of(held_seat_z(zf, u), p); };
        return f;
    };
    return sys;
}

std::vector<PairState> ClosedFormStepper::Impl::pair_states() const {
    std::vector<PairState> s(problem_.pairs.size());
    for (std::size_t k = 0; k < s.size(); ++k) s[k] = pair_state(problem_, static_cast<int>(k), p_);
    return s;
}

std::vector<PairRecord> ClosedFormStepper::Impl::pairs() const {
    return detail::pair_records(system_, problem_, p_, rel_);
}

Eigen::VectorXd ClosedFormStepper::Impl::displacements_now() const {
    if (step_ == 0) return z_;
    if (held_seat_) return held_seat_z(contact_->displacements(), step_problem_.u);
    return rig_ ? held_z(contact_->displacements(), w_) : contact_->displacements();
}

std::vector<LeafNodes> ClosedFormStepper::Impl::nodes() const {
    return system_.leaf_nodes(displacements_now());
}

double ClosedFormStepper::Impl::friction_work(const Eigen::VectorXd& p0, const Eigen::VectorXd& rel1) const {
    double work = 0.0;
    for (const auto& pr : problem_.pairs)
        if (pr.row_t >= 0 && pr.kind != PairKind::bonded)
            work += 0.5 * (p0[pr.row_t] + p_[pr.row_t]) * (rel1[pr.row_t] - rel_[pr.row_t]);
    return f_ * work;
}

void ClosedFormStepper::Impl::check_solve() const {
    if (!solve_.converged && options_.stop_on_nonconvergence) {
        const double dt = options_.dt_s;
        throw SolverError("contact solve failed at step " + std::to_string(step_) + ", t = " +
                              format_value(step_ * dt) + " s: " + solve_.message + detail::mesh_note(system_.model()),
                          step_, step_ * dt, solve_.residual_m);
    }
}

// The held-seat form's step (held_seat_system): quasi-static, R's w held by the vertical rig or static
// under F_v; the work of the vertical force and of the seat's loads [M_theta; H] booked by the
// trapezoidal rule, R's kinetic energy where the vertical rig moves it (seat loads with the rig).
const StepRecord& ClosedFormStepper::Impl::advance_held_seat() {
    const double dt = options_.dt_s;
    const Loading& load = options_.loading;
    const double t1 = (step_ + 1) * dt;
    const double w0 = w_, kin0 = 0.5 * m_whole_ * wd_ * wd_;
    const Eigen::Vector2d S1 = seat_loads(t1);
    const double fv1 = rig_ ? 0.0 : load.external_force_n(t1, m_whole_) / f_;
    step_problem_.u[0] = rig_ ? load.displacement_m.value(t1) : fv1;
    step_problem_.u[1] = windup_ ? load.seat_rotation_rad->value(t1) : S1[0];
    step_problem_.u[2] = S1[1];
    if (problem_.tau_rule == TauRule::previous_step) detail::set_previous_step_limits(problem_, p_);
    const Eigen::VectorXd p0 = p_;
    step_problem_.d = d_;
    step_problem_.tau_previous_n = problem_.tau_previous_n;
    solve_ = contact_->solve(step_problem_, p_);
    ++step_;
    check_solve();
    const auto [w1, S] = held_seat_state(step_problem_.u, p_);
    const double spring1 = system_.stiffness_n_per_m() * w1 - (p_.size() > 0 ? system_.coupling().dot(p_) : 0.0) +
                           seat_c_.g.dot(S);
    const Eigen::Vector2d motion1 = seat_c_.B.transpose() * p_ - seat_c_.g * w1 + seat_c_.F * S;
    const Eigen::VectorXd rel1 = contact_->relative_positions(p_);
    dissipated_ -= friction_work(p0, rel1);
    // external work: R's vertical force on the stack over dw (the rig's, or F_v = R's force: static),
    // the seat's loads over [theta_R; u_R]; with the vertical rig and R's inertia, the kinetic energy it gives R
    const double wd1 = rig_ ? load.displacement_m.derivative(t1) : (w1 - w0) / dt;
    wext_ += f_ * 0.5 * (spring_ + spring1) * (w1 - w0) + 0.5 * (seat_full_ + S).dot(motion1 - seat_motion_);
    if (rig_ && !windup_) wext_ += 0.5 * m_whole_ * wd1 * wd1 - kin0;
    spring_ = spring1;
    seat_full_ = S;
    seat_motion_ = motion1;
    fv_ = fv1;
    return finish_step(rel1, w1, wd1);
}

const StepRecord& ClosedFormStepper::Impl::finish_step(const Eigen::VectorXd& rel1, double w1, double wd1) {
    rel_ = rel1;
    w_ = w1;
    wd_ = wd1;
    t_ = step_ * options_.dt_s;
    detail::reanchor(problem_, p_, rel_, d_);
    fill_record(solve_.iterations, solve_.factorizations, contact_->strain_energy_j(p_, rel_));
    detail::count_step(record_, report_);
    return record_;
}

const StepRecord& ClosedFormStepper::Impl::advance() {
    if (held_seat_) return advance_held_seat();
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
    } else {
        // Step 1: k1, k2 from w^t, w_dot^t; the part of w(t+dt) that does not depend on p(t+dt).
        // F = c^T p + F_e, both linear over the step (eq. 14; F_e the loading, loading.hpp).
        fe1 = load.external_force_n(t1, m_whole_) / f_;
        if (seat_) fe1 -= seat_c_.g.dot(seat_loads(t1));  // the seat loads' force on R (condensed)
        F0 = cp0 + fe_;
        w_next = w_ * cos_ + wd_ * sin_ / omega_ + F0 / k * (1.0 - cos_) - gamma_ * F0 / k + gamma_ * fe1 / k;
    }
    if (problem_.tau_rule == TauRule::previous_step) detail::set_previous_step_limits(problem_, p_);
    const Eigen::VectorXd p0 = p_;
    // Steps 2-8: resolve the contact forces at t+dt, s = W p + q (eq. 6 with eq. 16), in the
    // operator's form; K, G constant over the run. The operator's displacements are z, or z_r
    // with R's w_next (the rig), read when asked (displacements_now).
    step_problem_.u[0] = w_next;
    if (seat_) {
        const Eigen::Vector2d S1 = seat_loads(t1);
        step_problem_.u.tail(2) = S1;
    }
    step_problem_.d = d_;
    step_problem_.tau_previous_n = problem_.tau_previous_n;
    solve_ = contact_->solve(step_problem_, p_);
    ++step_;
    check_solve();
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
    const Eigen::VectorXd rel1 = contact_->relative_positions(p_);
    dissipated_ -= friction_work(p0, rel1);
    // External work, trapezoidal: the loading's force on R over dw (exact for a constant
    // force); the rig: its force on the spring over dw plus the kinetic energy it gives R.
    if (rig_) {
        const double spring0 = f_ * (k * w0 - cp0), spring1 = f_ * (k * w1 - cp1);
        wext_ += 0.5 * (spring0 + spring1) * (w1 - w0) + 0.5 * m_whole_ * wd1 * wd1 - kin0;
    } else {
        // the vertical loading's work on w, and the seat loads' on [theta_R; u_R] (not the condensed force)
        const double fv1 = load.external_force_n(t1, m_whole_) / f_;
        wext_ += 0.5 * f_ * (fv_ + fv1) * (w1 - w0);
        if (seat_) {
            const Eigen::Vector2d motion1 = seat_c_.B.transpose() * p_ - seat_c_.g * w1 + seat_c_.F * seat_loads(t1);
            wext_ += 0.5 * (seat_loads(t_) + seat_loads(t1)).dot(motion1 - seat_motion_);
            seat_motion_ = motion1;
        }
        fv_ = fv1;
        fe_ = fe1;
    }
    if (!seat_ && system_.seat_rotation_dof() >= 0) seat_motion_ = seat_c_.B.transpose() * p_ - seat_c_.g * w1;
    return finish_step(rel1, w1, wd1);
}

}  // namespace stackbeam
