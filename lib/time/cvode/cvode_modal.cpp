// Mode "cvode" with leaf inertia on stacks with friction: modal inertia with a massless
// contact layer (cvode_modal.hpp, docs/time-integration.md "Mode cvode with leaf mass",
// stacks with friction).
//
// The motion is split (mode-acceleration method) into the retained modes of the
// unconnected stack, (K, M) phi = omega^2 phi, mass-normalised, omega <= omega_cut,
// and the quasi-static response of every mode above the cut:
//     z = Phi q + R G^T p,      R = K^-1 - Phi Omega^-2 Phi^T   (residual flexibility)
//     q'' + Omega^2 q = Phi^T G^T p                             (retained modes)
// so the contact problem at every instant is the paper's, with the residual compliance
// W = G R G^T in place of C' and the modes' motion G Phi q in place of c w:
//     s = W p + G Phi q - d      (paper eq. 7-10, conventions.hpp)
// For a set of modes p(q) = P q + r is affine and the retained modes obey a smooth
// linear ODE, q'' = (-Omega^2 + (G Phi)^T P) q + (G Phi)^T r, between events: the
// massless cvode mode (cvode_stepper.hpp: witnesses, margins, look-ahead decisions
// with the exact solver, the contact iteration at every accepted step, bisection of
// missed events) with the vector q in place of w. The contact points carry no mass, so
// a gap closes without an impact and the forces stay continuous across events. As the
// density falls the leaf modes leave the band and the model becomes the paper's
// massless one; as omega_cut rises it approaches the fully massive stack (mode
// newmark), at the price of the contact layer's high-frequency chatter.
// The retained modes are resolved by the integrator (non-stiff up to omega_cut), so
// CVODE runs Adams-Moulton with fixed-point iteration, as the massless mode.
//
// Loadings (modal_load.hpp, docs/decisions/026-loaded-modal-stepper.md): q(t) = B u(t) (gravity
// and the base's inertial force on every mass, a force on R) loads the retained modes, Fq u(t),
// and the quasi-static rest, whose motion G R B u(t) = Hq u(t) enters the contact problem:
//     s = W p + G Phi q + Hq u(t) - d,    q'' + Omega^2 q = Phi^T G^T p + Fq u(t)
// so for a set of modes p = P q + p0 + Pu u(t). The right-hand side then depends on t: under a
// loading the state carries the clock, y = [q, q', D, X, t] (t' = 1, integrated exactly; the
// witnesses and the look-ahead read t from the state), and X' = q'(t)^T z the loading's work
// int q^T dz = [q^T z] - X (modal_load.hpp). Gravity and the assembly start from the static
// state of the whole stack (as mode newmark and the massive stack).
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "stackbeam/contact/modes.hpp"
#include "time/cvode/cvode_modal.hpp"
#include "time/cvode/cvode_modes.hpp"
#include "time/cvode/modal_load.hpp"
#include "time/cvode/event_driver.hpp"
#include "stackbeam/errors.hpp"
#include "time/record.hpp"

namespace stackbeam::detail {

struct CvodeModalStepper::Impl final : EventDriver, ContactEventHooks {
    Impl(const System& system, const InitialState& start);

    int r = 0;                // retained modes
    Eigen::MatrixXd Phi;      // retained modes, n x r (mass-normalised)
    Eigen::VectorXd om;       // their circular frequencies [rad/s]
    Eigen::MatrixXd GPhi;     // G Phi, n x r
    Eigen::MatrixXd W;        // residual compliance G R G^T, n x n [m/N]
    Eigen::VectorXd rw;       // row w of R G^T, n: w = Phi_w q + rw . p
    Eigen::VectorXd phiw;     // row w of Phi
    Eigen::MatrixXd r_seat, phi_seat;  // rows theta_R, u_R of R G^T (2 x n) and of Phi (2 x r); 0 where absent
    // the current modes: p = P q + p0, s = Hs q + bs, q'' = A1 q + a0
    Eigen::MatrixXd P, Hs, A1;
    Eigen::VectorXd p0, bs, a0;
    std::vector<int> slip_rows;
    // the loading (modal_load.hpp): p gets Pu u(t), s + d gets Hsu u(t), q'' gets Au u(t);
    // state indices of the loading's work X and the clock t (-1: no loading)
    std::unique_ptr<ModalLoad> load;
    Eigen::MatrixXd Pu, Hsu, Au;
    int i_work = -1, i_clock = -1;
    double qz0 = 0.0;  // q^T z at t = 0 [J, meshed part]
    ModalLoad::Values u_of(const State& y) const { return i_clock < 0 ? ModalLoad::Values{} : load->at(y[i_clock]); }

    /// The retained modes (Phi, om) of the unconnected stack (K, M) up to the cut-off [rad/s]
    /// (CvodeOptions::modal_cutoff_rad_per_s; 0: 10 times the stack's first frequency); returns the cut.
    double retain_modes(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& M);
    /// The residual compliance W = G R G^T + C_L on the contact rows, R = K^-1 - Phi Omega^-2
    /// Phi^T, and R's rows (phiw, rw); KiGt = K^-1 G^T.
    void residual_compliance(const Eigen::MatrixXd& Gd, const Eigen::MatrixXd& KiGt);
    /// The initial state: the shared stage's z0, v0 projected on the retained modes, q = Omega^-2
    /// Phi^T K z (= Phi^T M z for exact eigenvectors; this one makes Phi q + R K z = z exactly
    /// whatever the eigen-solve's residual, so a static state stays static), q' = Phi^T M z'.
    Eigen::VectorXd initial_state_vector(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& M,
                                         const InitialState& start, int nstate) const;

    // ---- modes ------------------------------------------------------------------

    /// p(q) = P q + p0 of the current modes: the held rows S solve
    /// (W T)_S p_S = d_S - (G Phi q)_S - (W e)_S, p = T p_S + e (active_set.hpp).
    void build_mode(const ModeLinearization& lin) override {
        const int n = rows();
        const Eigen::VectorXd& d = anchors();
        const std::vector<int>& S = lin.S;
        const ModeMap T(lin, n);
        const int ms = T.columns;
        const Eigen::MatrixXd WT = T.compliance_times(W);
        const Eigen::VectorXd We = W * lin.e;
        Eigen::MatrixXd A(ms, ms), B1(ms, r), Bu(ms, ModalLoad::kChannels);
        Eigen::VectorXd b0(ms);
        for (int i = 0; i < ms; ++i) {
            A.row(i) = WT.row(S[i]);
            B1.row(i) = -GPhi.row(S[i]);
            Bu.row(i) = -load->Hq.row(S[i]);
            b0[i] = d[S[i]] - We[S[i]];
        }
        Eigen::MatrixXd X1 = Eigen::MatrixXd::Zero(ms, r), Xu = Eigen::MatrixXd::Zero(ms, ModalLoad::kChannels);
        Eigen::VectorXd x0 = Eigen::VectorXd::Zero(ms);
        if (ms > 0) {
            Eigen::PartialPivLU<Eigen::MatrixXd> lu(A);
            X1 = lu.solve(B1);
            x0 = lu.solve(b0);
            Xu = lu.solve(Bu);
            if (!X1.allFinite() || !x0.allFinite() || !Xu.allFinite())
                throw failure("the contact conditions of the current modes are singular");
        }
        P = Eigen::MatrixXd::Zero(n, r);
        Pu = Eigen::MatrixXd::Zero(n, ModalLoad::kChannels);
        p0 = lin.e;
        for (const auto& l : T.links) {
            P.row(l.row) += l.coef * X1.row(l.col);
            Pu.row(l.row) += l.coef * Xu.row(l.col);
            p0[l.row] += l.coef * x0[l.col];
        }
        Hs = W * P + GPhi;
        bs = W * p0 - d;
        Hsu = W * Pu + load->Hq;
        A1 = GPhi.transpose() * P;
        A1.diagonal() -= om.cwiseProduct(om);
        a0 = GPhi.transpose() * p0;
        Au = GPhi.transpose() * Pu + load->Fq;
        slip_rows.clear();
        for (int kk = 0; kk < num_pairs(); ++kk) {
            const int rt = pairs()[kk].row_t;
            if (rt >= 0 && (modes().tmode[kk] == SLIP_POS || modes().tmode[kk] == SLIP_NEG)) slip_rows.push_back(rt);
        }
    }

    Eigen::VectorXd forces_q(const Eigen::Ref<const Eigen::VectorXd>& q, const ModalLoad::Channels& u) const {
        return P * q + p0 + Pu * u;
    }
    Vec forces(const State& y) const override { return forces_q(y.head(r), u_of(y).u); }
    Vec relative(const State& y) const override { return Hs * y.head(r) + bs + anchors() + Hsu * u_of(y).u; }
    Vec relative_at_event(const State& y, const Vec& p_cur) const override { return W * p_cur + motion(y); }
    Vec motion(const State& y) const override { return GPhi * y.head(r) + load->Hq * u_of(y).u; }
    void witnesses(const State& y, double* g) const override {
        const auto q = y.head(r);
        const auto qd = y.segment(r, r);
        const ModalLoad::Values u = u_of(y);
        witnesses_from(
            forces_q(q, u.u), [&](int row) { return Hs.row(row).dot(q) + bs[row] + Hsu.row(row).dot(u.u); },
            [&](int row) { return Hs.row(row).dot(qd) + Hsu.row(row).dot(u.ud); }, g);
    }
    /// q'' of the current modes at (q, u(t)).
    Eigen::VectorXd modal_acceleration(const Eigen::Ref<const Eigen::VectorXd>& q, const ModalLoad::Channels& u) const {
        return A1 * q + a0 + Au * u;
    }

    /// The look-ahead: the contact points move by ~kLookahead L_ref (the fastest row) and
    /// the forces by ~kLookahead F_ref (in the old modes: fast leaf modes move the forces
    /// long before the contact points have moved far).
    Vec look_ahead(double, const State& y, const Vec&) const override {
        const auto q = y.head(r);
        const auto qd = y.segment(r, r);
        const ModalLoad::Values u = u_of(y);
        const Eigen::VectorXd qdd = P.size() > 0 ? modal_acceleration(q, u.u) : Eigen::VectorXd::Zero(r);
        const double target = kLookahead * scales().L_ref_m;
        const double vmax = (GPhi * qd + load->Hq * u.ud).lpNorm<Eigen::Infinity>();
        const double amax = (GPhi * qdd + load->Hq * u.udd).lpNorm<Eigen::Infinity>();
        double delta = std::numeric_limits<double>::infinity();
        if (vmax > 0.0) delta = std::min(delta, target / vmax);
        if (amax > 0.0) delta = std::min(delta, std::sqrt(2.0 * target / amax));
        if (P.size() > 0) {
            const double prate = (P * qd + Pu * u.ud).lpNorm<Eigen::Infinity>();
            if (prate > 0.0) delta = std::min(delta, kLookahead * scales().F_ref_n / prate);
        }
        if (!std::isfinite(delta)) delta = 0.0;
        Vec yl = y;
        yl.head(r) = q + delta * qd + 0.5 * delta * delta * qdd;
        yl.segment(r, r) = qd + delta * qdd;
        if (i_clock >= 0) yl[i_clock] += delta;
        return yl;
    }

    void body_motion(const State& y, const Vec& p_cur, double& w, double& wd) const override {
        w = phiw.dot(y.head(r)) + rw.dot(p_cur) + load->wq.dot(u_of(y).u);
        wd = phiw.dot(y.segment(r, r));
    }

    /// A slipping pair slips against its slip rate at (q, q') (EventDriver::signs_follow_slip_rates).
    void correct_decision(const State& y, const Vec& rel, std::vector<signed char>& nm,
                          std::vector<signed char>& tm) override {
        signs_follow_slip_rates(rel, nm, tm, [&] { return Vec(Hs * y.segment(r, r) + Hsu * u_of(y).ud); });
    }

    /// A force jump (a slip that reverses where sticking is not admissible: the friction
    /// force flips from +mu tau to -mu tau) moves the massless contact layer at once: its
    /// strain energy p^T W p / 2 drops, and that is friction work done in the jump (the
    /// kinetic energy, q', is continuous). Booked as dissipated.
    void after_event(const std::string& cause, const Vec& p_cur, const Vec& p_new) override {
        book_force_jump(cause, 0.5 * spring_factor() * (p_cur.dot(W * p_cur) - p_new.dot(W * p_new)), p_cur, p_new);
    }

    // ---- CVODE ------------------------------------------------------------------

    /// y = [q, q', D (, X, t)] (file comment): q'' of the current modes, D' the friction power
    /// -sum_slip p_t ds_t/dt >= 0, X' = q'(t)^T z (modal_load.hpp), t' = 1.
    void derivatives(double, const double* Y, double* D) const override {
        const Eigen::Map<const Eigen::VectorXd> q(Y, r), qd(Y + r, r);
        Eigen::Map<Eigen::VectorXd>(D, r) = qd;
        if (i_clock < 0) {  // initial conditions only: y = [q, q', D]
            Eigen::Map<Eigen::VectorXd>(D + r, r) = A1 * q + a0;
            double pw = 0.0;
            for (int rt : slip_rows) pw -= (P.row(rt).dot(q) + p0[rt]) * Hs.row(rt).dot(qd);
            D[2 * r] = pw;
            return;
        }
        const ModalLoad::Values u = load->at(Y[i_clock]);
        Eigen::Map<Eigen::VectorXd>(D + r, r) = modal_acceleration(q, u.u);
        const Eigen::VectorXd p = forces_q(q, u.u);
        double pw = 0.0;
        for (int rt : slip_rows) pw -= p[rt] * (Hs.row(rt).dot(qd) + Hsu.row(rt).dot(u.ud));
        D[2 * r] = pw;
        D[i_work] = load->q_dot_z(q, p, u.u, u.ud);
        D[i_clock] = 1.0;
    }

    /// A break of the loading (a table's point, ModalLoad::breaks): the next piece of u(t). Where
    /// u jumps (the clamped base spline's y'' at its first and last points) q and q' are
    /// continuous but the quasi-static rest R (G^T p + B u) jumps with u (and p with Pu u):
    /// the rest is a massless linear spring, so the loading's work over the jump is exactly the
    /// trapezoid (q- + q+)^T (z+ - z-) / 2 (its strain energy's change), i.e. the integral X of
    /// q'^T z takes (q+ - q-)^T (z- + z+) / 2 (file comment: work = [q^T z] - X). A slipping
    /// pair's slider jumps by Hsu du: its friction work, the trapezoid of its force, to D.
    void cross_loading_break(double t_s, Vec& y) override {
        if (i_clock < 0) return;
        const auto q = y.head(r);
        const ModalLoad::Values before = u_of(y);
        const Vec p_before = forces(y);
        load->enter_piece(t_s);
        const ModalLoad::Values after = u_of(y);
        const Vec p_after = forces(y);
        const ModalLoad::Channels du = after.u - before.u;
        y[i_work] += 0.5 * (load->q_dot_z(q, p_before, before.u, du) + load->q_dot_z(q, p_after, after.u, du));
        for (int rt : slip_rows) y[2 * r] -= 0.5 * (p_before[rt] + p_after[rt]) * Hsu.row(rt).dot(du);
    }

    /// q^T z at t = 0 (the loading's work, make_record) from the decided modes' forces.
    void started(const State& Y) override {
        const ModalLoad::Values u0 = u_of(Y);
        qz0 = load->q_dot_z(Y.head(r), forces(Y), u0.u, u0.u);
    }

    /// The modal coordinates carry energy (q' in sqrt(J), mass-normalised): the same absolute
    /// tolerance on every coordinate, from the user's atol on w as an amplitude of the body's mode
    /// (sqrt(m) omega atol) and rtol of the motion's energy.
    void tolerances(const State& Y, Eigen::Ref<Vec> A) const override {
        const double e_meshed = 0.5 * Y.segment(r, r).squaredNorm() + 0.5 * Y.head(r).dot(om.cwiseProduct(om).cwiseProduct(Y.head(r)));
        const double a_e = std::max(std::sqrt(system().mass_kg()) * scales().omega_rad_per_s * options().cvode.atol_m,
                                    options().cvode.rtol * std::sqrt(2.0 * e_meshed));
        for (int i = 0; i < r; ++i) {
            A[i] = a_e / om[i];  // q_i: energy-norm amplitude omega_i q_i
            A[r + i] = a_e;      // q_i'
        }
        A[2 * r] = a_e * a_e;    // D [J, meshed part]
        if (i_clock >= 0) {
            A[i_work] = a_e * a_e;                                     // X [J, meshed part]
            A[i_clock] = 1e-12 * std::max(1.0, options().t_end_s);     // t [s]: t' = 1 is integrated exactly
        }
    }

    // ---- records ----------------------------------------------------------------

    /// The split above, z = Phi q + R (G^T p + B u) with R = K^-1 - Phi Omega^-2 Phi^T: the
    /// retained modes' motion plus the quasi-static response of the modes above the cut to the
    /// contact forces and the loading (modal_load.hpp; its row w is make_record's w). K's factor
    /// is made on the first call (only a run that asks for the nodes pays for it).
    /// The motion at an output for the stresses (event_driver.hpp): the modes' part Phi eta'' alone.
    /// With z = Phi eta + R f (f = G^T p + B u, R = K^-1 - Phi Omega^-2 Phi^T, mass-normalised modes),
    /// K z = M Phi Omega^2 eta + f - M Phi Phi^T f = f - M Phi eta'': M (Phi eta'') + K z = f holds
    /// exactly, the quasi-static rest R f carrying no inertia. f's B u = -(g + y_b'') l + e_w F/f:
    /// the frame's acceleration is -u_0.
    LeafMotion leaf_motion(double, const State& Y, const Vec&) const override {
        LeafMotion m;
        const ModalLoad::Values u = u_of(Y);
        m.acceleration = Phi * modal_acceleration(Y.head(r), u.u);
        m.frame_acceleration_m_per_s2 = -u.u[0];
        return m;
    }

    Vec displacements(const State& Y, const Vec& p) const override {
        if (!stiffness_factor)
            stiffness_factor = std::make_unique<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>>(system().stiffness_reduced());
        const Vec gtp = system().contact_rows().transpose() * p;  // G^T p [N, N m]
        const Vec phi_gtp = Phi.transpose() * gtp;
        Vec z = Phi * Vec(Y.head(r) - phi_gtp.cwiseQuotient(om.cwiseProduct(om))) + stiffness_factor->solve(gtp);
        if (i_clock >= 0) z += load->RB * u_of(Y).u;
        return z;
    }
    mutable std::unique_ptr<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>> stiffness_factor;

    /// The record at time tau of state Y: w = Phi_w q + rw . p + wq . u; energies: kinetic
    /// |q'|^2 / 2 (mass-normalised modes; the contact layer is massless), strain z^T K z / 2 +
    /// p^T C_L p / 2 = (q^T Omega^2 q + f^T R f + p^T C_L p) / 2 with f = G^T p + B u (the cross
    /// terms vanish: Phi^T K R = 0, R K R = R), i.e. q^T Omega^2 q / 2 + p^T W p / 2 + p^T Hq u +
    /// u^T Rqq u / 2; the loading's work [q^T z] - X (modal_load.hpp).
    StepRecord make_record(double tau, const State& Y, Vec& p, Vec& rel) const override {
        const auto q = Y.head(r);
        const auto qd = Y.segment(r, r);
        const ModalLoad::Values u = u_of(Y);
        p = forces_q(q, u.u);
        rel = W * p + motion(Y);
        const Eigen::VectorXd qdd = modal_acceleration(q, u.u);
        const double w = phiw.dot(q) + rw.dot(p) + load->wq.dot(u.u);
        const double wd = phiw.dot(qd) + rw.dot(P * qd + Pu * u.ud) + load->wq.dot(u.ud);
        const double wdd = phiw.dot(qdd) + rw.dot(P * qdd + Pu * u.udd) + load->wq.dot(u.udd);
        const double f = spring_factor();
        const double strain = 0.5 * f *
                              (q.dot(om.cwiseProduct(om).cwiseProduct(q)) + p.dot(W * p) +
                               2.0 * p.dot(load->Hq * u.u) + u.u.dot(load->Rqq * u.u));
        LoadState ls;  // the loading's force on R and its work, whole spring
        if (i_clock >= 0) {
            const Loading& L = options().loading;
            ls.external_force_n = L.external_force_n(tau, body_mass_kg());
            ls.external_work_j = f * (load->q_dot_z(q, p, u.u, u.u) - qz0 - Y[i_work]);
            ls.base_displacement_m = L.base_displacement_m(tau);
        }
        StepRecord rec;
        fill_state(system(), laws(), p, w, wd, strain, f * Y[2 * r] + jump_dissipation_j(), initial_energy_j(), ls, rec);
        finish_inertia_record(rec, 0.5 * f * qd.squaredNorm(), body_mass_kg() * wdd);
        // the seat (full model; loading.hpp): theta_R, u_R as w above, and the applied moment M - H h
        const int seat[2] = {system().seat_rotation_dof(), system().seat_axial_dof()};
        double motion[2] = {0.0, 0.0};
        for (int j = 0; j < 2; ++j)
            if (seat[j] >= 0) motion[j] = phi_seat.row(j).dot(q) + r_seat.row(j).dot(p) + load->RB.row(seat[j]).dot(u.u);
        rec.seat_rotation_rad = motion[0];
        rec.seat_axial_m = motion[1];
        rec.seat_moment_n_m = options().loading.seat_moment_n_m_at(tau);
        return rec;
    }

};

double CvodeModalStepper::Impl::retain_modes(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& M) {
    // modes of the unconnected stack (K, M), dense: n is a few hundred on the example
    const Eigen::MatrixXd Kd(K), Md(M);
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(Kd, Md);
    if (eig.info() != Eigen::Success || !(eig.eigenvalues().minCoeff() > 0.0))
        throw SolverError("cvode mode (leaf inertia): the modal analysis of the stack failed (K or M not positive "
                          "definite)", 0, 0.0, 0.0);
    const Eigen::VectorXd omega = eig.eigenvalues().cwiseSqrt();
    // default cut: 10 times the stack's first frequency (the body's mode with the leaves'
    // mass in it); the leaf bending modes above respond quasi-statically
    const double cut = options().cvode.modal_cutoff_rad_per_s > 0.0 ? options().cvode.modal_cutoff_rad_per_s : 10.0 * omega[0];
    r = 0;
    while (r < ndof() && omega[r] <= cut) ++r;
    if (r == 0)
        throw InputError("modal_cutoff", "value " + format_value(cut) + " rad/s is below the stack's first frequency " +
                                             format_value(omega[0]) + " rad/s: no mode would carry the motion");
    Phi = eig.eigenvectors().leftCols(r);
    om = omega.head(r);
    return cut;
}

void CvodeModalStepper::Impl::residual_compliance(const Eigen::MatrixXd& Gd, const Eigen::MatrixXd& KiGt) {
    GPhi = Gd * Phi;
    const Eigen::MatrixXd GPhiS = GPhi * om.cwiseInverse().asDiagonal();
    W = Gd * KiGt - GPhiS * GPhiS.transpose();
    W = 0.5 * (W + W.transpose()).eval();
    W.diagonal() += system().layer_compliance_m_per_n();  // the elastic layer, massless (system.hpp)
    phiw = Phi.row(w_dof()).transpose();
    rw = Eigen::VectorXd::Zero(Gd.rows());  // no contact rows (a single leaf): empty (a row of an n x 0 block is UB in Eigen)
    if (Gd.rows() > 0) rw = KiGt.row(w_dof()).transpose() - GPhi * om.cwiseProduct(om).cwiseInverse().cwiseProduct(phiw);
    // the seat's rows likewise, for its records: [theta_R; u_R] = phi_seat q + r_seat p + (R B)_seat u
    phi_seat = Eigen::MatrixXd::Zero(2, Phi.cols());
    r_seat = Eigen::MatrixXd::Zero(2, Gd.rows());
    const int seat[2] = {system().seat_rotation_dof(), system().seat_axial_dof()};
    for (int j = 0; j < 2; ++j) {
        if (seat[j] < 0) continue;
        phi_seat.row(j) = Phi.row(seat[j]);
        if (Gd.rows() > 0)
            r_seat.row(j) = KiGt.row(seat[j]) - (GPhi * om.cwiseProduct(om).cwiseInverse().cwiseProduct(
                                                             Eigen::VectorXd(Phi.row(seat[j]).transpose()))).transpose();
    }
}

Eigen::VectorXd CvodeModalStepper::Impl::initial_state_vector(const Eigen::SparseMatrix<double>& K,
                                                              const Eigen::SparseMatrix<double>& M,
                                                              const InitialState& start, int nstate) const {
    Eigen::VectorXd Y = Eigen::VectorXd::Zero(nstate);
    Y.head(r) = (Phi.transpose() * (K * start.z)).cwiseQuotient(om.cwiseProduct(om));
    Y.segment(r, r) = Phi.transpose() * (M * start.v0);
    return Y;
}

CvodeModalStepper::Impl::Impl(const System& system, const InitialState& start)
    : EventDriver(system, start.options, "cvode mode (leaf inertia)") {
    const Eigen::SparseMatrix<double>& K = system.stiffness_reduced();
    const Eigen::SparseMatrix<double> M = system.mass_reduced();
    EventStart es;
    es.modal_cutoff_rad_per_s = retain_modes(K, M);
    es.retained_modes = r;
    // residual flexibility R = K^-1 - Phi Omega^-2 Phi^T, on the contact rows
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> kf(K);
    const Eigen::MatrixXd Gd(system.contact_rows());
    // no contact rows (a single leaf): an n x 0 block (a solve with an empty right-hand side is UB in Eigen)
    residual_compliance(Gd, Gd.rows() > 0 ? Eigen::MatrixXd(kf.solve(Eigen::MatrixXd(Gd.transpose())))
                                          : Eigen::MatrixXd(K.rows(), 0));
    load = std::make_unique<ModalLoad>(system, options().loading, Phi, om, kf);
    es.nstate = 2 * r + 1;
    if (!load->none()) {  // the loading's work X and the clock t (file comment)
        i_work = 2 * r + 1;
        i_clock = 2 * r + 2;
        es.nstate = 2 * r + 3;
        es.loading_breaks_s = load->breaks(options().t_end_s);  // CVODE stops at each (cross_loading_break)
    }
    // the initial state: the assembly and gravity's static state, R held at w(0), the leaves moving
    // with R in the tied shape (the shared stage, initial_state.hpp: whole_stack_static)
    es.y0 = initial_state_vector(K, M, start, es.nstate);
    es.scales = event_scales(system, leaf_mass_scale_inputs(system, options().loading));
    es.compliance = W;
    // forces resolved to the witnesses' margin, 1e-9 F_ref, through the residual compliance (its
    // entries are far smaller than C''s: most of the leaves' flexibility is in the retained modes)
    // (a stack without contact rows, a single leaf, has no events: any positive tolerance)
    es.event_tolerance_m = W.size() > 0 ? 1e-9 * es.scales.F_ref_n * W.diagonal().maxCoeff() : 1e-12;
    // the gap witnesses' margin: kMotionMargin, or ten times the decisions' displacement
    // resolution if that is coarser (a gap the contact iteration cannot see closing must not count as closed)
    es.gap_margin = std::max(kMotionMargin, 10.0 * es.event_tolerance_m / es.scales.L_ref_m);
    es.events = this;  // contact events (ContactEventHooks)
    this->start(start, es);
}

CvodeModalStepper::CvodeModalStepper(const System& system, const InitialState& start)
    : EventStepper(std::make_unique<Impl>(system, start)) {}

}  // namespace stackbeam::detail
