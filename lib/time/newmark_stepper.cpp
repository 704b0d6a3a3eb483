// Mode "newmark": average-acceleration Newmark on the massive leaves with the paper's
// contact problem at every step (newmark_stepper.hpp, docs/time-integration.md).
#include "stackbeam/time/newmark_stepper.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>

#include "stackbeam/contact/step.hpp"
#include "stackbeam/errors.hpp"
#include "model/mesh_note.hpp"
#include "time/accurate_sum.hpp"
#include "time/contact_state.hpp"
#include "time/record.hpp"
#include "time/reduced_load.hpp"
#include "time/held_seat.hpp"
#include "time/rig_reaction.hpp"
#include "time/stack_properties.hpp"
#include "time/initial_state.hpp"
#include "time/stepper_access.hpp"
#include "fe/tied_shape.hpp"

namespace stackbeam {

// The stepper's state and its step (the public class forwards to it).
struct NewmarkStepper::Impl {
    Impl(const System& system, const detail::InitialState& start);

    const StepRecord& advance();
    std::vector<PairRecord> pairs() const;

    struct Factor {
        Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> llt;   // K_eff (its check: positive definite)
        Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> mass;  // M (massive leaves)
    };
    const System& system_;
    SimulationOptions options_;
    Factor factor_;
    Eigen::SparseMatrix<double> K_, M_;
    Eigen::SparseMatrix<double> gt_;      // G^T (all DOFs: the step's residual, step_residual)
    std::shared_ptr<const ContactOperator> op_;  // the step's operator, dense or sparse (step.hpp)
    std::unique_ptr<StepContactSolver> contact_;
    ContactLaws problem_;        // the pair laws and the previous-step limits
    StepProblem step_problem_;   // the step's problem: u = r / kappa, d
    std::unique_ptr<ImpactProjection> projection_;  // the impact law's projection (massive leaves)
    SolveResult solve_;
    Eigen::VectorXd z_, v_, a_, p_, d_, rel_;
    std::vector<char> massless_;  // DOFs whose row of M is zero (statically condensed)
    bool massive_leaves_ = false;
    double t_ = 0.0;
    double e0_ = 0.0, dissipated_ = 0.0, impact_loss_ = 0.0;
    long step_ = 0;
    StepRecord record_;
    RunReport report_;
    detail::ReducedLoad load_;                 // the loading's q(t) on the reduced DOFs
    bool rig_ = false;                         // w prescribed (the vertical rig)
    // The rigs: the prescribed DOFs H (ascending; w by the vertical rig, theta_R by the windup rig,
    // loading.hpp), each with its function of time, and the free DOFs F, the rest.
    std::vector<int> prescribed_;
    std::vector<const TimeFunction*> prescribed_f_;
    Eigen::SparseMatrix<double> S_;            // F <- all: the free rows (nf x n)
    bool free_leading_ = true;                 // F = the first nf DOFs (H the last ones)
    Eigen::MatrixXd keff_h_, g_h_;             // K_eff's free rows and G's, on the columns of H
    Eigen::MatrixXd u_h_;                      // M^-1 E_H [1/kg, 1/(kg m^2)] (massive leaves)
    Eigen::VectorXd rig_force_;                // lambda per prescribed DOF at t [N, N m, meshed part]
    double body_mass_on_w_ = 0.0;              // R's mass in M_'s w entry [kg, whole spring] (0: the windup rig)
    double external_work_ = 0.0;               // the loading's (or the rig's) work [J, meshed part]
    Eigen::SparseMatrix<double> C_;            // structural damping alpha M + beta K (empty: none)
    double damping_energy_ = 0.0;              // its work [J, meshed part]
    void fill_record(int iterations, int factorizations);
    /// The accelerations at t = 0 from the equations of motion (the massless DOFs condensed).
    void initial_accelerations();
    /// Massless leaves: z at t = 0 refined once against K z0 + M a0 = q(0) + G^T p0 (refine_start's note).
    void refine_start();
    /// K_eff factorised and the step's contact operator (on K_eff / kappa, dense or sparse).
    void factorise_step();
    /// Massive leaves with a rig: M a = r + E_H lambda with a_H = z_p''(t); lambda [N, N m] in lambda.
    Eigen::VectorXd accelerations_with_rig(double t_s, const Eigen::VectorXd& r, Eigen::VectorXd* lambda) const;
    /// The residual of the step's equation at z1 (all DOFs, the rigs' rows included) from K, M, C
    /// and p_ on z_, v_, a_ (the step's start), q0 and q1 the loading at t0, t1 (empty: none).
    Eigen::VectorXd step_residual(const Eigen::VectorXd& z1, const Eigen::VectorXd& q0, const Eigen::VectorXd& q1) const;
    /// The prescribed DOFs' values z_H(t) [m, rad] (derivative 0), velocities (1) or accelerations (2).
    Eigen::VectorXd prescribed_at(double t_s, int derivative) const;
    /// The free rows of a matrix on the reduced DOFs, S A S^T.
    Eigen::SparseMatrix<double> free_block(const Eigen::SparseMatrix<double>& A) const;
    /// Massless leaves with a rig (static: M = 0): lambda = (K z - G^T p - q)_H at t [N, N m].
    Eigen::VectorXd static_rig_forces(double t_s) const;
    double project_velocities(const Eigen::VectorXd& p0, const Eigen::VectorXd& gv0);
};

NewmarkStepper::NewmarkStepper(const System& system, const SimulationOptions& options)
    : impl_(std::make_unique<Impl>(system, detail::initial_state(detail::newmark_row(system).name, system, options))) {}

NewmarkStepper::NewmarkStepper(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

std::unique_ptr<Stepper> NewmarkStepperAccess::build(const System& system, const detail::InitialState& start) {
    return std::unique_ptr<Stepper>(new NewmarkStepper(std::make_unique<NewmarkStepper::Impl>(system, start)));
}

NewmarkStepper::~NewmarkStepper() = default;

const StepRecord& NewmarkStepper::advance() { return impl_->advance(); }
const StepRecord& NewmarkStepper::current() const noexcept { return impl_->record_; }
long NewmarkStepper::record_index() const noexcept { return impl_->step_; }
std::vector<PairRecord> NewmarkStepper::pairs() const { return impl_->pairs(); }
std::vector<LeafNodes> NewmarkStepper::nodes() const { return impl_->system_.leaf_nodes(impl_->z_); }
Stresses NewmarkStepper::stresses() const {
    if (!impl_->massive_leaves_) return compute_stresses(impl_->system_, impl_->z_, pairs());
    // the leaves' distributed loads at t (decision 061): a and v of the step's update (M a = G^T p - K z - C v + q)
    const double a_frame = impl_->options_.loading.gravity_m_per_s2 + impl_->load_.base_acceleration(impl_->t_);
    return compute_stresses(impl_->system_, impl_->z_, pairs(), LeafMotion{impl_->a_, impl_->v_, a_frame, impl_->options_.damping});
}
RunReport NewmarkStepper::report() const { return impl_->report_; }
const Eigen::VectorXd& NewmarkStepper::displacements() const noexcept { return impl_->z_; }
const Eigen::VectorXd& NewmarkStepper::velocities() const noexcept { return impl_->v_; }
const Eigen::VectorXd& NewmarkStepper::accelerations() const noexcept { return impl_->a_; }
const Eigen::VectorXd& NewmarkStepper::contact_forces() const noexcept { return impl_->p_; }
const Eigen::VectorXd& NewmarkStepper::anchors() const noexcept { return impl_->d_; }
const SolveResult& NewmarkStepper::last_solve() const noexcept { return impl_->solve_; }
ContactPath NewmarkStepper::contact_path() const noexcept { return impl_->op_->path(); }

NewmarkStepper::Impl::Impl(const System& system, const detail::InitialState& start)
    : system_(system), options_(start.options),
      problem_(start.laws), solve_(start.solve), z_(start.z), v_(start.v0), p_(start.p), d_(start.d),
      load_(system, start.options.loading), rig_(start.rig) {
    report_.mode = Mode::newmark;
    const auto& leaves = system_.model().spec().leaves;
    massive_leaves_ = !leaves.empty() && leaves[0].density_kg_per_m3 > 0.0;
    K_ = system_.stiffness_reduced();
    // The windup rig is quasi-static as the vertical rig: R's inertia (m on w and u_R, J) is not in its loop.
    const bool windup = options_.loading.windup_rig();
    M_ = system_.mass_reduced(!windup);
    body_mass_on_w_ = windup ? 0.0 : system_.model().spec().rigid_body.mass_kg;
    // the held DOFs H in held_seat_dofs' order (theta_R, then w), each with its prescribed motion
    detail::HeldSeatDofs dofs = detail::held_seat_dofs(system_, windup, rig_);
    prescribed_ = std::move(dofs.held);
    if (windup) prescribed_f_.push_back(&*options_.loading.seat_rotation_rad);
    if (rig_) prescribed_f_.push_back(&options_.loading.displacement_m);
    S_ = std::move(dofs.S);
    free_leading_ = dofs.free_leading;
    rig_force_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(prescribed_.size()));
    if (options_.damping.active()) {  // structural damping C = alpha M + beta K (massive leaves)
        C_ = options_.damping.rayleigh_alpha_per_s * M_ + options_.damping.rayleigh_beta_s * K_;
        C_.makeCompressed();
    }
    // The initial state (the assembly, gravity, R held at w(0), the leaves moving with R in the
    // tied shape: initial_state.hpp) is the start's.
    rel_ = detail::relative_positions(system_, z_, p_);
    if (massive_leaves_) {
        factor_.mass.compute(M_);
        if (factor_.mass.info() != Eigen::Success)
            throw SolverError("newmark: the mass matrix is singular", 0, 0.0, 0.0);
    }
    initial_accelerations();
    factorise_step();
    if (!massive_leaves_) refine_start();
    // Impact law: the velocity projection on the held rows, on the form of the step's operator
    // (ImpactProjection, step.hpp)
    if (massive_leaves_ && system_.num_components() > 0)
        projection_ = std::make_unique<ImpactProjection>(M_, factor_.mass, system_.contact_rows(), *op_);
    solve_ = SolveResult{};
    solve_.converged = true;
    fill_record(0, 0);
    e0_ = record_.kinetic_energy_j + record_.strain_energy_j;
    record_.energy_balance_error_j = 0.0;
}

void NewmarkStepper::Impl::initial_accelerations() {
    // DOFs without mass (leaves of density 0) are condensed statically: no velocity, no acceleration.
    const int n = static_cast<int>(K_.rows());
    massless_.assign(static_cast<std::size_t>(n), 0);
    std::vector<int> massive;
    for (int i = 0; i < n; ++i) {
        if (M_.coeff(i, i) > 0.0) massive.push_back(i);
        else massless_[i] = 1;
    }
    // From the equations of motion on the massive DOFs: M_SS a_S = (G^T p0 - K z0 + q(0))_S (the
    // massless rows of the residual are zero: static shape); the rig's reaction keeps
    // w'' = w_p''(0) (accelerations_with_rig).
    const Eigen::SparseMatrix<double>& G = system_.contact_rows();
    const Eigen::VectorXd r0 = Eigen::VectorXd(G.transpose() * p_) - K_ * z_ + load_.at(0.0) -
                               (C_.nonZeros() > 0 ? Eigen::VectorXd(C_ * v_) : Eigen::VectorXd::Zero(n));
    if (!prescribed_.empty() && !massive_leaves_) {
        // massless leaves with a rig (the windup rig): M = 0 (mass_reduced(false)), every step static
        a_ = Eigen::VectorXd::Zero(n);
        rig_force_ = static_rig_forces(0.0);
    } else if (!prescribed_.empty()) {  // M^-1 E_H, once: the rigs' reactions per unit force
        const int nh = static_cast<int>(prescribed_.size());
        Eigen::MatrixXd eh = Eigen::MatrixXd::Zero(n, nh);
        for (int h = 0; h < nh; ++h) eh(prescribed_[h], h) = 1.0;
        u_h_ = factor_.mass.solve(eh);
        a_ = accelerations_with_rig(0.0, r0, &rig_force_);
    } else if (massive.empty()) {
        a_ = Eigen::VectorXd::Zero(n);  // nothing has mass (an empty factorisation is UB in Eigen)
    } else {
        const int ns = static_cast<int>(massive.size());
        Eigen::SparseMatrix<double> S(ns, n);
        std::vector<Eigen::Triplet<double>> st;
        for (int i = 0; i < ns; ++i) st.emplace_back(i, massive[i], 1.0);
        S.setFromTriplets(st.begin(), st.end());
        const Eigen::SparseMatrix<double> Mss = S * M_ * S.transpose();
        Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> mf(Mss);
        if (mf.info() != Eigen::Success)
            throw SolverError("newmark: the mass matrix of the massive DOFs is singular", 0, 0.0, 0.0);
        a_ = S.transpose() * Eigen::VectorXd(mf.solve(S * r0));
    }
    for (int i = 0; i < n; ++i)
        if (massless_[i]) v_[i] = a_[i] = 0.0;
}

void NewmarkStepper::Impl::refine_start() {
    // Massless leaves: the step's energy identity uses the equations at both ends of the step,
    // K z0 + M a0 = q(0) + G^T p0 at t = 0 too (newmark_stepper.hpp), and the start's static solve
    // meets them only to ~eps |K| |z| a row. On soak seed 20 (two rigid clamps 1.2 mm apart,
    // 2.5e12 N/m, 0.076 m of sag) that residual's work over the first step was 3.5e-8 J, the
    // whole of the run's balance error (1.9e-11 S; decision 075). One pass of refinement on the
    // free rows, its residual in twice the working precision, then the accelerations (and a
    // rig's forces) again from the refined z.
    detail::AccurateVector rho(z_.size());
    rho.add_product(K_, z_, -1.0);
    rho.add_product(M_, a_, -1.0);
    if (p_.size() > 0) rho.add_product(gt_, p_);
    if (!load_.none()) rho.add(load_.at(0.0));
    if (C_.nonZeros() > 0) rho.add_product(C_, v_, -1.0);
    const Eigen::VectorXd r = rho.value();
    const Eigen::VectorXd dzF = factor_.llt.solve(prescribed_.empty() ? r : Eigen::VectorXd(S_ * r));
    z_ += prescribed_.empty() ? dzF : Eigen::VectorXd(S_.transpose() * dzF);
    rel_ = detail::relative_positions(system_, z_, p_);
    initial_accelerations();
}

void NewmarkStepper::Impl::factorise_step() {
    // K_eff = K + 4 M / dt^2, factorised once. The contact force enters the step as
    // kappa G^T p1: kappa = 1 (massless leaves: the trapezoidal rule) or 2 (massive leaves:
    // the contact impulse over the step is dt p1, newmark_stepper.hpp).
    // The rigs: z_H1 = z_p(t1) is given (w by the vertical rig, theta_R by the windup rig), so the step
    // solves the rows of the free DOFs F only:
    // K_eff,FF z_F1 = r_F - K_eff,FH z_H1 + kappa G_F^T p1, s = G_F z_F1 + G_H z_H1 + c_L p1 - d.
    const double dt = options_.dt_s;
    const int n = static_cast<int>(K_.rows()), m = system_.num_components();
    const Eigen::SparseMatrix<double>& G = system_.contact_rows();
    const double kappa = massive_leaves_ ? 2.0 : 1.0;
    Eigen::SparseMatrix<double> Keff = K_ + (4.0 / (dt * dt)) * M_;
    if (C_.nonZeros() > 0) Keff += (2.0 / dt) * C_;  // the trapezoidal damping force -C (z1 - z0) / dt
    Keff.makeCompressed();
    const int nf = n - static_cast<int>(prescribed_.size());
    Eigen::SparseMatrix<double> KeffF = free_block(Keff);
    Eigen::SparseMatrix<double> GF = free_leading_ ? Eigen::SparseMatrix<double>(G.leftCols(nf))
                                                   : Eigen::SparseMatrix<double>(G * S_.transpose());
    if (!prescribed_.empty()) {
        const int nh = static_cast<int>(prescribed_.size());
        keff_h_.resize(nf, nh);
        g_h_.resize(m, nh);
        for (int h = 0; h < nh; ++h) {
            keff_h_.col(h) = S_ * Eigen::VectorXd(Keff.col(prescribed_[h]));
            g_h_.col(h) = Eigen::VectorXd(G.col(prescribed_[h]));
        }
    }
    gt_ = G.transpose();
    factor_.llt.compute(KeffF);
    if (factor_.llt.info() != Eigen::Success)
        throw SolverError("newmark: K + 4 M / dt^2 is not positive definite", 0, 0.0, 0.0);
    // The step's contact problem, (K_eff / kappa) z1 = r / kappa + G^T p1, s = G z1 + c_L p1 - d:
    // u = r / kappa (the load on z itself), the operator dense (W = G (K_eff / kappa)^-1 G^T + C_L
    // from its factor) or sparse (step.hpp).
    StepSystem sys;
    sys.rows = m;
    sys.sparse = [&] {
        SparseStepForm f;
        f.K = (1.0 / kappa) * KeffF;
        f.G = GF;
        f.layer_compliance = detail::sparse_layer(system_);
        return f;
    };
    contact_ = start_step_contact(sys, options_.contact_path, options_.solver, options_.sparse_tuning, problem_.pairs,
                                  problem_.tau_rule, step_problem_);
    op_ = step_problem_.op;
}

Eigen::VectorXd NewmarkStepper::Impl::accelerations_with_rig(double t_s, const Eigen::VectorXd& r,
                                                             Eigen::VectorXd* lambda) const {
    // M a = r + E_H lambda with a_H = z_p''(t): (M^-1)_HH lambda = z_p'' - (M^-1 r)_H
    Eigen::VectorXd a = factor_.mass.solve(r);
    const Eigen::VectorXd l = detail::prescribe_accelerations(a, u_h_, prescribed_, prescribed_at(t_s, 2));
    if (lambda) *lambda = l;
    return a;
}

Eigen::VectorXd NewmarkStepper::Impl::step_residual(const Eigen::VectorXd& z1, const Eigen::VectorXd& q0,
                                                    const Eigen::VectorXd& q1) const {
    // The step's equation (factorise_step) with z1 = z0 + dz, as in the energy identity
    // (newmark_stepper.hpp): K_eff z1 = r + kappa G^T p1 is, term by term,
    //   massive:  K (z0 + z1) + c M dz + (2/dt) C dz = (4/dt) M v0 + q0 + q1 + 2 G^T p1,
    //   massless: K z1 + c M dz + (2/dt) C dz = M ((4/dt) v0 + a0) + q1 + G^T p1,
    // c = 4/dt^2 [1/s^2]. dz = z1 - z0 is exact in double where z1 and z0 are within a factor 2
    // of each other (Sterbenz), so the inertia and damping terms round with |dz|, not |z|; the
    // elastic and contact terms are summed in twice the working precision (their terms reach
    // 2e11 N on a short stiff element, their sum is the step's force). Residual [N, N m], all DOFs.
    const double dt = options_.dt_s, c = 4.0 / (dt * dt);
    const Eigen::VectorXd dz = z1 - z_;
    detail::AccurateVector rho(z1.size());
    rho.add_product(K_, z1, -1.0);
    Eigen::VectorXd inertia = (4.0 / dt) * v_ - c * dz;  // M times it: the inertia terms
    if (massive_leaves_) {
        rho.add_product(K_, z_, -1.0);
        if (q0.size() > 0) rho.add(q0);
    } else {
        inertia += a_;
    }
    rho.add_product(M_, inertia);
    if (q1.size() > 0) rho.add(q1);
    if (C_.nonZeros() > 0) rho.add_product(C_, Eigen::VectorXd((-2.0 / dt) * dz));
    if (p_.size() > 0) rho.add_product(gt_, p_, massive_leaves_ ? 2.0 : 1.0);
    return rho.value();
}

Eigen::VectorXd NewmarkStepper::Impl::prescribed_at(double t_s, int derivative) const {
    Eigen::VectorXd z(static_cast<Eigen::Index>(prescribed_.size()));
    for (std::size_t h = 0; h < prescribed_.size(); ++h) {
        const TimeFunction& f = *prescribed_f_[h];
        z[h] = derivative == 0 ? f.value(t_s) : derivative == 1 ? f.derivative(t_s) : f.second_derivative(t_s);
    }
    return z;
}

Eigen::SparseMatrix<double> NewmarkStepper::Impl::free_block(const Eigen::SparseMatrix<double>& A) const {
    const int nf = static_cast<int>(S_.rows());
    if (free_leading_) return A.topLeftCorner(nf, nf);
    return Eigen::SparseMatrix<double>(S_ * A * S_.transpose());
}

Eigen::VectorXd NewmarkStepper::Impl::static_rig_forces(double t_s) const {
    Eigen::VectorXd r = K_ * z_ - system_.contact_rows().transpose() * p_;
    if (!load_.none()) r -= load_.at(t_s);
    Eigen::VectorXd l(static_cast<Eigen::Index>(prescribed_.size()));
    for (std::size_t h = 0; h < prescribed_.size(); ++h) l[h] = r[prescribed_[h]];
    return l;
}

void NewmarkStepper::Impl::fill_record(int iterations, int factorizations) {
    const double f = system_.model().whole_spring_factor();
    const auto& body = system_.model().spec().rigid_body;
    const int w_dof = static_cast<int>(z_.size()) - 1;
    // leaves and layer; z^T K z in twice the working precision (a fine mesh's form cancels: accurate_sum.hpp)
    const double strain = f * (0.5 * detail::accurate_quadratic_form(K_, z_) + detail::layer_energy_j(system_, p_));
    const Loading& L = options_.loading;
    detail::LoadState ls;  // the loading's force on R (the rig: the load cell's), whole spring, and its work
    // the vertical rig's reaction is the last of rig_force_ (w is the last DOF)
    ls.external_force_n = rig_ ? f * rig_force_[rig_force_.size() - 1] - body_mass_on_w_ * a_[w_dof]
                               : L.external_force_n(t_, body.mass_kg);
    ls.external_work_j = f * external_work_;
    ls.base_displacement_m = L.base_displacement_m(t_);
    detail::fill_state(system_, problem_, p_, z_[w_dof], v_[w_dof], strain, dissipated_, e0_, ls, record_);
    // a seat load or the windup rig loads theta_R, so k w - c^T p (every free DOF unloaded) is not R's
    // force on the stack: it is w's row of K z - G^T p (massless leaves; massive ones: below)
    if (!massive_leaves_ && (L.has_seat_load() || L.windup_rig()))
        record_.spring_force_n = f * (detail::accurate_dot(Eigen::VectorXd(K_.col(w_dof)), z_) -
                                      Eigen::VectorXd(system_.contact_rows().col(w_dof)).dot(p_));
    const double kinetic = 0.5 * f * detail::accurate_quadratic_form(M_, v_);
    // M_ holds R's mass but under the windup rig (R's inertia out of its loop): then the kinetic
    // energy is the leaves' alone, else it holds R's m w'^2 / 2 (fill_state's)
    const double body_kinetic = L.windup_rig() ? 0.0 : record_.kinetic_energy_j;
    record_.kinetic_energy_j = kinetic;
    record_.leaf_kinetic_energy_j = kinetic - body_kinetic;
    record_.impact_loss_j = impact_loss_;
    // R is attached to the w DOF: the force on it is m w''. With massive leaves the force of R on
    // the stack follows from R's balance (m w'' = F - spring force); the rig's load cell reads
    // the force on the spring (the leaves' inertia included).
    record_.force_on_mass_n = body_mass_on_w_ * a_[w_dof];
    if (massive_leaves_)
        record_.spring_force_n = rig_ ? record_.external_force_n : record_.external_force_n - record_.force_on_mass_n;
    record_.damping_energy_j = f * damping_energy_;
    // the seat (full model): theta_R, u_R, and the moment on the spring there, the applied M - H h plus
    // the windup rig's reaction (its first prescribed DOF, theta_R)
    const int theta = system_.seat_rotation_dof(), axial = system_.seat_axial_dof();
    record_.seat_rotation_rad = theta >= 0 ? z_[theta] : 0.0;
    record_.seat_axial_m = axial >= 0 ? z_[axial] : 0.0;
    record_.seat_moment_n_m = L.seat_moment_n_m_at(t_) + (L.windup_rig() ? rig_force_[0] : 0.0);
    record_.energy_balance_error_j = e0_ + record_.external_work_j -
                                     (record_.kinetic_energy_j + record_.strain_energy_j + record_.dissipated_energy_j +
                                      impact_loss_ + record_.damping_energy_j);
    record_.t_s = t_;
    record_.contact_iterations = iterations;
    record_.factorizations = factorizations;
    record_.contact_residual_m = solve_.residual_m;
}

double NewmarkStepper::Impl::project_velocities(const Eigen::VectorXd& p0, const Eigen::VectorXd& gv0) {
    // The held components at t1: normal rows of closed pairs (compressed, or bilateral),
    // tangential rows of sticking and bonded pairs. Their relative velocity is set to zero
    // by the impulse G_C^T l that changes the kinetic energy least (M-orthogonal projection):
    //     (G_C M^-1 G_C^T) l = G_C v,   v <- v - M^-1 G_C^T l,
    // the inelastic impact law (restitution 0); the kinetic energy it removes,
    // 1/2 (v- - v+)^T M (v- - v+) >= 0, is returned [J, whole spring].
    // Rows with an elastic layer are not held: their force is the layer's, a function of the
    // state, and a closure there is not an impact (system.hpp).
    std::vector<int> held;
    const Eigen::VectorXd& layer = system_.layer_compliance_m_per_n();
    for (std::size_t j = 0; j < problem_.pairs.size(); ++j) {
        const auto& pr = problem_.pairs[j];
        const PairState st = pair_state(problem_, static_cast<int>(j), p_);
        if (pr.row_n >= 0 && layer[pr.row_n] == 0.0 && (pr.kind != PairKind::coulomb || p_[pr.row_n] < 0.0))
            held.push_back(pr.row_n);
        if (pr.row_t >= 0 && layer[pr.row_t] == 0.0 && (pr.kind == PairKind::bonded || st == PairState::stick) &&
            (pr.row_n < 0 || pr.kind != PairKind::coulomb || p_[pr.row_n] < 0.0))
            held.push_back(pr.row_t);
    }
    if (held.empty()) return 0.0;
    const int nh = static_cast<int>(held.size());
    // Restitution e (SimulationOptions::restitution): a unilateral normal component closed
    // at t1 that was open at t0 (p0_n = 0) and approaching (s_n' = (G v0)_n > 0) leaves
    // with G_n v+ = b_n = -e (G v0)_n; every other held component with 0. The impulse
    // solves (G_C M^-1 G_C^T) l = G_C v - b and the kinetic energy removed is
    // 1/2 l^T (G_C v + b) = (1 - e^2) times the e = 0 loss of the closing rows.
    Eigen::VectorXd b = Eigen::VectorXd::Zero(nh);
    const double e = options_.restitution;
    if (e > 0.0) {
        for (int i = 0; i < nh; ++i) {
            const int row = held[i];
            for (const auto& pr : problem_.pairs) {
                if (pr.row_n != row || pr.kind != PairKind::coulomb) continue;
                if (p0[row] == 0.0 && gv0[row] > 0.0) b[i] = -e * gv0[row];
            }
        }
    }
    return projection_->project(held, b, e != 0.0, system_.model().whole_spring_factor(), step_,
                                step_ * options_.dt_s, v_);
}

std::vector<PairRecord> NewmarkStepper::Impl::pairs() const {
    return detail::pair_records(system_, problem_, p_, rel_);
}

const StepRecord& NewmarkStepper::Impl::advance() {
    const double dt = options_.dt_s;
    const Eigen::SparseMatrix<double>& G = system_.contact_rows();
    // r: the step's load with p1 = 0 (newmark_stepper.hpp). Massive leaves: the elastic force
    // by the trapezoidal rule, the contact impulse implicit; massless: Newmark as printed.
    const double kappa = massive_leaves_ ? 2.0 : 1.0;
    // The loading q(t) (detail::ReducedLoad) by the trapezoidal rule with massive leaves (r gets
    // q0 + q1 = 2 qbar), at t1 with massless ones (Newmark as printed).
    const double t1 = (step_ + 1) * dt;
    const bool loaded = !load_.none();
    const Eigen::VectorXd q0 = loaded ? load_.at(t_) : Eigen::VectorXd();
    const Eigen::VectorXd q1 = loaded ? load_.at(t1) : Eigen::VectorXd();
    Eigen::VectorXd r = massive_leaves_
                            ? Eigen::VectorXd(M_ * Eigen::VectorXd((4.0 / (dt * dt)) * z_ + (4.0 / dt) * v_) -
                                              detail::accurate_product(K_, z_))  // K z0 cancels on a fine mesh
                            : Eigen::VectorXd(M_ * Eigen::VectorXd((4.0 / (dt * dt)) * z_ + (4.0 / dt) * v_ + a_));
    if (loaded) r += massive_leaves_ ? Eigen::VectorXd(q0 + q1) : q1;
    const bool damped = C_.nonZeros() > 0;
    if (damped) r += (2.0 / dt) * detail::accurate_product(C_, z_);  // K_eff holds (2/dt) C: the step's damping force is -C (z1 - z0)/dt
    // The rigs: the step's problem on z_F with z_H1 given (constructor)
    const bool held = !prescribed_.empty();
    const Eigen::VectorXd zH1 = held ? prescribed_at(t1, 0) : Eigen::VectorXd();
    const Eigen::VectorXd rF = held ? Eigen::VectorXd(S_ * r - keff_h_ * zH1) : r;
    const Eigen::VectorXd dF = held ? Eigen::VectorXd(d_ - g_h_ * zH1) : d_;
    if (problem_.tau_rule == TauRule::previous_step) detail::set_previous_step_limits(problem_, p_);
    const Eigen::VectorXd p0 = p_;
    const Eigen::VectorXd gv0 = massive_leaves_ && options_.restitution > 0.0 ? Eigen::VectorXd(G * v_) : Eigen::VectorXd();
    Eigen::VectorXd zF;
    step_problem_.u = rF / kappa;
    step_problem_.d = dF;
    step_problem_.tau_previous_n = problem_.tau_previous_n;
    solve_ = contact_->solve(step_problem_, p_, zF);
    // One step of iterative refinement with the residual in twice the working precision
    // (accurate_sum.hpp): K_eff's factor and z = v + Y p leave a residual ~ cond(K_eff) eps |b|, a
    // spurious force whose work showed in the balance (1e-8 of the run's energy on
    // graduated_elastic.toml; 1.9e-13 after one pass; more passes measured no better: decision
    // 065). The residual is the step's equation itself on K, M and C (step_residual), not on the
    // matrix K_eff: K_eff's entries are rounded sums, and on a short stiff element that rounding,
    // eps |K| ~ 3e-4 N/m an entry at 12 EI / l^3 = 2.5e12 N/m, times a deflection of 0.076 m is a
    // force of 2e-5 N the energies (on K and M) do not see (decision 075).
    const auto full = [&](const Eigen::VectorXd& zf) {
        if (!held) return zf;
        Eigen::VectorXd z = S_.transpose() * zf;
        for (std::size_t h = 0; h < prescribed_.size(); ++h) z[prescribed_[h]] = zH1[h];
        return z;
    };
    if (solve_.converged) {
        const Eigen::VectorXd rho = step_residual(full(zF), q0, q1);
        zF += factor_.llt.solve(held ? Eigen::VectorXd(S_ * rho) : rho);
    }
    Eigen::VectorXd z1 = full(zF);
    ++step_;
    if (!solve_.converged && options_.stop_on_nonconvergence) {
        throw SolverError("contact solve failed at step " + std::to_string(step_) + ", t = " +
                              format_value(step_ * dt) + " s: " + solve_.message + detail::mesh_note(system_.model()),
                          step_, step_ * dt, solve_.residual_m);
    }
    // The contact forces' work over the step (newmark_stepper.hpp): p1^T G (z1 - z0) with
    // massive leaves, (p0 + p1)^T G (z1 - z0) / 2 with massless ones. Friction on the
    // tangential components; the rest (normal components, bonds) is the impact loss.
    const Eigen::VectorXd rel1 = detail::relative_positions(system_, z1, p_);
    const Eigen::VectorXd pbar = massive_leaves_ ? Eigen::VectorXd(p_) : Eigen::VectorXd(0.5 * (p0 + p_));
    double friction_work = 0.0, other_work = 0.0;
    for (const auto& pr : problem_.pairs) {
        if (pr.row_t >= 0) {
            const double wk = pbar[pr.row_t] * (rel1[pr.row_t] - rel_[pr.row_t]);
            (pr.kind == PairKind::bonded ? other_work : friction_work) += wk;
        }
        if (pr.row_n >= 0) other_work += pbar[pr.row_n] * (rel1[pr.row_n] - rel_[pr.row_n]);
    }
    const double f = system_.model().whole_spring_factor();
    dissipated_ -= f * friction_work;
    impact_loss_ -= f * other_work;
    // Massive leaves with an elastic layer: the leaves feel the layer's force as the step's
    // implicit impulse p1 while the layer's energy changes by the work of its average force,
    // so the step loses (p1 - p0)^T C_L (p1 - p0) / 2 >= 0 (first order in dt; 0 for a steady
    // force). It is the scheme's loss, booked with the impact loss so the balance closes.
    // (The trapezoidal rule on the layer rows would not lose it, but with rows that open and
    // close it was measured to pump energy into the layer's high frequencies: the paper
    // friction case with 7850 kg/m^3 leaves at dt = 1e-4 s diverged within 0.05 s.)
    if (massive_leaves_ && system_.has_layer()) {
        const Eigen::VectorXd dp = p_ - p0;
        impact_loss_ += f * 0.5 * dp.dot(system_.layer_compliance_m_per_n().cwiseProduct(dp));
    }
    // The loading's work over the step, qbar^T (z1 - z0) (trapezoidal, as the step takes it).
    if (loaded) external_work_ += 0.5 * (q0 + q1).dot(z1 - z_);
    // Newmark's update of v and a (beta = 1/4, gamma = 1/2): v1 = 2 (z1 - z0)/dt - v0.
    if (massive_leaves_) {
        const Eigen::VectorXd v1 = (2.0 / dt) * (z1 - z_) - v_;
        for (const int h : prescribed_) {
            // A rig's mean force over the step from its DOF's row of the step's momentum balance,
            // M (v1 - v0) = dt [-K (z0 + z1)/2 + G^T p1 + qbar + lambda_bar e_h], and its work
            // lambda_bar (z1_h - z0_h): the balance closes as for the other forces. Only the row is
            // needed: M, K and C are symmetric, so row h is column h.
            double lambda_bar = detail::accurate_dot(Eigen::VectorXd(M_.col(h)), Eigen::VectorXd((v1 - v_) / dt)) +
                                0.5 * detail::accurate_dot(Eigen::VectorXd(K_.col(h)), Eigen::VectorXd(z_ + z1)) -
                                (p_.size() > 0 ? G.col(h).dot(p_) : 0.0);  // (a single leaf has no contact rows)
            if (loaded) lambda_bar -= 0.5 * (q0[h] + q1[h]);
            if (damped) lambda_bar += detail::accurate_dot(Eigen::VectorXd(C_.col(h)), Eigen::VectorXd((z1 - z_) / dt));
            external_work_ += lambda_bar * (z1[h] - z_[h]);
        }
        // the damping force's work over the step, (z1 - z0)^T C (z1 - z0) / dt >= 0
        if (damped) damping_energy_ += detail::accurate_quadratic_form(C_, Eigen::VectorXd(z1 - z_)) / dt;
        v_ = v1;
        Eigen::VectorXd r1 = G.transpose() * p_ - K_ * z1;  // M a1 = G^T p1 - K z1 - C v1 + q1 (+ the rig's lambda1 e_w)
        if (loaded) r1 += q1;
        if (damped) r1 -= C_ * v_;
        a_ = held ? accelerations_with_rig(t1, r1, &rig_force_) : Eigen::VectorXd(factor_.mass.solve(r1));
    } else {
        const Eigen::VectorXd a1 = (4.0 / (dt * dt)) * (z1 - z_ - dt * v_) - a_;
        v_ += 0.5 * dt * (a_ + a1);
        a_ = a1;
    }
    Eigen::VectorXd zH0(static_cast<Eigen::Index>(prescribed_.size()));
    for (std::size_t h = 0; h < prescribed_.size(); ++h) zH0[h] = z_[prescribed_[h]];
    z_ = std::move(z1);
    for (int i = 0; i < static_cast<int>(z_.size()); ++i)
        if (massless_[i]) v_[i] = a_[i] = 0.0;
    if (held && !massive_leaves_) {
        // massless leaves with a rig (static, M = 0): lambda = (K z - G^T p - q)_H at t1, and its work
        // over the step by the trapezoidal rule (as the loading's)
        const Eigen::VectorXd lambda1 = static_rig_forces(t1);
        external_work_ += 0.5 * (rig_force_ + lambda1).dot(zH1 - zH0);
        rig_force_ = lambda1;
    }
    rel_ = rel1;
    if (massive_leaves_) impact_loss_ += project_velocities(p0, gv0);
    t_ = t1;
    detail::reanchor(problem_, p_, rel_, d_);  // paper, section 5
    fill_record(solve_.iterations, solve_.factorizations);
    detail::count_step(record_, report_);
    return record_;
}

}  // namespace stackbeam
