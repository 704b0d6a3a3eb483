// Mode "cvode" with leaf inertia on stacks with friction: modal inertia with a massless
// contact layer (cvode_inertia.hpp, docs/inertia.md "Mode cvode with leaf inertia and
// friction").
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
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <deque>
#include <limits>
#include <string>

#include "contact/active_set.hpp"
#include "time/cvode/cvode_modes.hpp"
#include "time/cvode/cvode_inertia.hpp"
#include "time/cvode/sundials.hpp"
#include "stackbeam/errors.hpp"
#include "model/mesh_note.hpp"
#include "time/step_record.hpp"
#include "fe/tied_shape.hpp"

namespace stackbeam::detail {

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace

struct CvodeModalStepper::Impl {
    Impl(const System& s, const SimulationOptions& o) : sys(s), opt(o) {}
    Impl(const Impl&) = delete;
    Impl& operator=(const Impl&) = delete;

    const System& sys;
    SimulationOptions opt;
    int n = 0, m = 0, np = 0, r = 0, w_dof = 0, nstate = 0;
    Eigen::MatrixXd Phi;      // retained modes, n x r (mass-normalised)
    Eigen::VectorXd om;       // their circular frequencies [rad/s]
    Eigen::MatrixXd GPhi;     // G Phi, m x r
    Eigen::MatrixXd W;        // residual compliance G R G^T, m x m [m/N]
    Eigen::VectorXd rw;       // row w of R G^T, m: w = Phi_w q + rw . p
    Eigen::VectorXd phiw;     // row w of Phi
    Eigen::VectorXd d, d_chk;
    double f = 1.0, F_ref = 1.0, L_ref = 1.0, V_ref = 1.0, m_body = 0.0;
    /// Margin of the gap witnesses (relative to L_ref): kMotionMargin, or ten times the
    /// decisions' displacement resolution if that is coarser (a gap the contact
    /// iteration cannot see closing must not count as closed).
    double gap_margin = kMotionMargin;
    ModeSet modes;
    std::vector<signed char>& nmode = modes.nmode;
    std::vector<signed char>& tmode = modes.tmode;
    // the current modes: p = P q + p0, s = Hs q + bs, q'' = A1 q + a0
    Eigen::MatrixXd P, Hs, A1;
    Eigen::VectorXd p0, bs, a0;
    std::vector<int> slip_rows;
    struct Slot { int pair; bool normal; };
    std::vector<Slot> slots;

    ContactProblem chk_problem, ev_problem;
    std::unique_ptr<ContactSolver> chk_solver, ev_solver;
    double ev_tolerance = 0.0;

    std::unique_ptr<CvodeSession> cvode;

    double t = 0.0, t_final = 0.0, dt = 0.0;
    long n_out = 0, out_index = 0;
    struct Output { StepRecord rec; Eigen::VectorXd p, rel; };
    std::deque<Output> pending;
    StepRecord record;
    Eigen::VectorXd p_out, rel_out;
    double e0 = 0.0, last_event_t = -1.0, last_check_residual = 0.0;
    double jump_dissipation = 0.0;  // friction work in force jumps at events [J, whole spring]
    int events_at_this_time = 0;
    long iters_since = 0, facts_since = 0;
    std::vector<ContactEvent> events;
    CvodeStats stats;

    const std::vector<ContactPair>& pairs() const { return chk_problem.pairs; }

    // ---- modes ------------------------------------------------------------------

    /// p(q) = P q + p0 of the current modes: the held rows S solve
    /// (W T)_S p_S = d_S - (G Phi q)_S - (W e)_S, p = T p_S + e (active_set.hpp).
    void build_mode() {
        ModeLinearization lin;
        modes.linearize(chk_problem, lin);
        const std::vector<int>& S = lin.S;
        const int ms = static_cast<int>(S.size());
        std::vector<int> pos(m, -1);
        for (int i = 0; i < ms; ++i) pos[S[i]] = i;
        struct Link { int row, col; double coef; };
        std::vector<Link> T;
        for (int i = 0; i < ms; ++i) T.push_back({S[i], i, 1.0});
        for (std::size_t i = 0; i < lin.coupled.size(); ++i)
            if (pos[lin.coupled[i].second] >= 0) T.push_back({lin.coupled[i].first, pos[lin.coupled[i].second], lin.coef[i]});
        Eigen::MatrixXd WT = Eigen::MatrixXd::Zero(m, ms);
        for (const auto& l : T) WT.col(l.col) += l.coef * W.col(l.row);
        const Eigen::VectorXd We = W * lin.e;
        Eigen::MatrixXd A(ms, ms), B1(ms, r);
        Eigen::VectorXd b0(ms);
        for (int i = 0; i < ms; ++i) {
            A.row(i) = WT.row(S[i]);
            B1.row(i) = -GPhi.row(S[i]);
            b0[i] = d[S[i]] - We[S[i]];
        }
        Eigen::MatrixXd X1 = Eigen::MatrixXd::Zero(ms, r);
        Eigen::VectorXd x0 = Eigen::VectorXd::Zero(ms);
        if (ms > 0) {
            Eigen::PartialPivLU<Eigen::MatrixXd> lu(A);
            X1 = lu.solve(B1);
            x0 = lu.solve(b0);
            if (!X1.allFinite() || !x0.allFinite())
                throw SolverError("cvode mode (leaf inertia): the contact conditions of the current modes are singular "
                                  "at t = " + format_value(t) + " s",
                                  stats.steps, t, 0.0);
        }
        P = Eigen::MatrixXd::Zero(m, r);
        p0 = lin.e;
        for (const auto& l : T) {
            P.row(l.row) += l.coef * X1.row(l.col);
            p0[l.row] += l.coef * x0[l.col];
        }
        Hs = W * P + GPhi;
        bs = W * p0 - d;
        A1 = GPhi.transpose() * P;
        A1.diagonal() -= om.cwiseProduct(om);
        a0 = GPhi.transpose() * p0;
        slip_rows.clear();
        for (int kk = 0; kk < np; ++kk) {
            const int rt = pairs()[kk].row_t;
            if (rt >= 0 && (tmode[kk] == SLIP_POS || tmode[kk] == SLIP_NEG)) slip_rows.push_back(rt);
        }
        ++stats.mode_factorizations;
        ++facts_since;
    }

    Eigen::VectorXd forces(const Eigen::Ref<const Eigen::VectorXd>& q) const { return P * q + p0; }

    void witnesses(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& qd,
                   double* g) const {
        const Eigen::VectorXd p = forces(q);
        for (std::size_t i = 0; i < slots.size(); ++i) {
            const int kk = slots[i].pair;
            const auto& cp = pairs()[kk];
            double v = 1.0, margin = kForceMargin;
            if (slots[i].normal) {
                const double pn = p[cp.row_n];
                if (cp.kind == PairKind::coulomb) {
                    if (nmode[kk] == CLOSED) {
                        v = -pn / F_ref;
                    } else {
                        v = -(Hs.row(cp.row_n).dot(q) + bs[cp.row_n]) / L_ref;
                        margin = gap_margin;
                    }
                } else {
                    v = tmode[kk] == FREE ? (pn - cp.preload_n) / F_ref : (cp.preload_n - pn) / F_ref;
                }
            } else {
                const int rt = cp.row_t;
                switch (tmode[kk]) {
                    case STICK:
                        v = (cp.friction_coefficient * friction_normal_force(chk_problem, kk, p) - std::abs(p[rt])) / F_ref;
                        break;
                    case SLIP_POS: v = -Hs.row(rt).dot(qd) / V_ref; margin = kMotionMargin; break;
                    case SLIP_NEG: v = Hs.row(rt).dot(qd) / V_ref; margin = kMotionMargin; break;
                    default: v = 1.0; break;
                }
            }
            g[i] = v + margin;
        }
    }

    /// The contact iteration decides the modes at (q, q') with forces p_cur in the old
    /// modes, as cvode_stepper.cpp: CVODE's transitions applied to the old modes first,
    /// kept if the contact iteration's stop test and every witness accept them a
    /// look-ahead away; otherwise the exact solver on that look-ahead problem decides.
    void decide_modes(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& qd,
                      const Eigen::VectorXd& p_cur, const std::string& cause, const std::vector<int>* triggered) {
        const auto t_start = Clock::now();
        const double contact_before = stats.contact_time_s;
        const Eigen::VectorXd rel = W * p_cur + GPhi * q;  // s + d
        const Eigen::VectorXd qdd = P.size() > 0 ? Eigen::VectorXd(A1 * q + a0) : Eigen::VectorXd::Zero(r);
        // look-ahead: the contact points move by ~kLookahead L_ref (the fastest row)
        const double target = kLookahead * L_ref;
        const double vmax = (GPhi * qd).lpNorm<Eigen::Infinity>(), amax = (GPhi * qdd).lpNorm<Eigen::Infinity>();
        double delta = std::numeric_limits<double>::infinity();
        if (vmax > 0.0) delta = std::min(delta, target / vmax);
        if (amax > 0.0) delta = std::min(delta, std::sqrt(2.0 * target / amax));
        // ... and its forces by ~kLookahead F_ref (in the old modes: fast leaf modes move
        // the forces long before the contact points have moved far)
        if (P.size() > 0) {
            const double prate = (P * qd).lpNorm<Eigen::Infinity>();
            if (prate > 0.0) delta = std::min(delta, kLookahead * F_ref / prate);
        }
        if (!std::isfinite(delta)) delta = 0.0;
        const Eigen::VectorXd ql = q + delta * qd + 0.5 * delta * delta * qdd;
        const Eigen::VectorXd qdl = qd + delta * qdd;
        Eigen::VectorXd d_la = d;
        for (int kk = 0; kk < np; ++kk) {
            const auto& cp = pairs()[kk];
            if (cp.row_t >= 0 && cp.kind != PairKind::bonded && tmode[kk] != STICK) d_la[cp.row_t] = rel[cp.row_t];
        }
        ev_problem.q = GPhi * ql - d_la;
        auto enter = [&](const std::vector<signed char>& nm, const std::vector<signed char>& tm) {
            for (int kk = 0; kk < np; ++kk) {
                const auto& cp = pairs()[kk];
                if (cp.row_t >= 0 && cp.kind != PairKind::bonded && tm[kk] == STICK && tmode[kk] != STICK)
                    d[cp.row_t] = rel[cp.row_t];
            }
            nmode = nm;
            tmode = tm;
        };
        std::vector<signed char> nm, tm;
        bool decided = false;
        if (triggered != nullptr) {
            nm = nmode;
            tm = tmode;
            for (std::size_t i = 0; i < slots.size(); ++i) {
                if ((*triggered)[i] == 0) continue;
                const int kk = slots[i].pair;
                apply_transition(pairs()[kk], slots[i].normal, pairs()[kk].row_t >= 0 ? p_cur[pairs()[kk].row_t] : 0.0,
                                 nm[kk], tm[kk]);
            }
            const Eigen::VectorXd d_saved = d;
            const std::vector<signed char> nm_saved = nmode, tm_saved = tmode;
            enter(nm, tm);
            build_mode();
            const Eigen::VectorXd pl = forces(ql);
            const double v = error_vector(ev_problem, pl, Eigen::VectorXd(Hs * ql + bs + d - d_la)).norm();
            std::vector<double> g(slots.size());
            if (!slots.empty()) witnesses(ql, qdl, g.data());
            decided = v < ev_tolerance && std::all_of(g.begin(), g.end(), [](double x) { return x >= 0.0; });
            ++stats.contact_iterations;
            ++iters_since;
            d = d_saved;
            nmode = nm_saved;
            tmode = tm_saved;
        }
        if (!decided) {
            Eigen::VectorXd p_la = p_cur;
            const auto t_solve = Clock::now();
            const SolveResult res = ev_solver->solve(ev_problem, p_la);
            stats.contact_time_s += seconds_since(t_solve);
            stats.contact_iterations += res.iterations;
            iters_since += res.iterations;
            if (!res.converged)
                throw SolverError("cvode mode (leaf inertia): the contact iteration deciding the modes at t = " +
                                      format_value(t) + " s (" + cause + ") did not converge: " + res.message +
                                      mesh_note(sys.model()),
                                  stats.steps, t, res.residual_m);
            modes_from_solution(chk_problem, p_la, 1e-12 * F_ref, nm, tm);
            // A slipping pair slips against its slip rate: where the new modes' rate at
            // (q, q') contradicts the solver's sign beyond the margin (a rate the
            // look-ahead's motion is too short to resolve), the sign follows the rate.
            const Eigen::VectorXd d_saved = d;
            const std::vector<signed char> nm_saved = nmode, tm_saved = tmode;
            for (int pass = 0; pass < 3; ++pass) {
                enter(nm, tm);
                build_mode();
                const Eigen::VectorXd rate = Hs * qd;
                bool changed = false;
                for (int kk = 0; kk < np; ++kk) {
                    const int rt = pairs()[kk].row_t;
                    if (rt < 0) continue;
                    if (tm[kk] == SLIP_POS && rate[rt] > kMotionMargin * V_ref) { tm[kk] = SLIP_NEG; changed = true; }
                    else if (tm[kk] == SLIP_NEG && rate[rt] < -kMotionMargin * V_ref) { tm[kk] = SLIP_POS; changed = true; }
                }
                d = d_saved;
                nmode = nm_saved;
                tmode = tm_saved;
                if (!changed) break;
            }
        }
        for (int kk = 0; kk < np; ++kk) {
            const auto& cp = pairs()[kk];
            if (cp.kind == PairKind::bonded) continue;
            if (nm[kk] == nmode[kk] && tm[kk] == tmode[kk] && cause != "start") continue;
            ContactEvent e;
            e.t_s = t;
            e.pair = kk;
            const PairSpec& spec = sys.pair_spec(kk);
            e.interface_index = spec.interface_index;
            e.x_m = spec.x_m;
            e.from = cause == "start" ? "none" : mode_label(pairs()[kk], nmode[kk], tmode[kk]);
            e.to = mode_label(pairs()[kk], nm[kk], tm[kk]);
            e.cause = cause;
            e.w_m = phiw.dot(q) + rw.dot(p_cur);
            e.w_dot_m_per_s = phiw.dot(qd);
            events.push_back(std::move(e));
        }
        enter(nm, tm);
        build_mode();  // (again, if the candidate was tried: cheap at this size)
        const Eigen::VectorXd p_new = forces(q);
        // A force jump (a slip that reverses where sticking is not admissible: the
        // friction force flips from +mu tau to -mu tau) moves the massless contact layer
        // at once: its strain energy p^T W p / 2 drops, and that is friction work done
        // in the jump (the kinetic energy, q', is continuous). Booked as dissipated.
        if (cause != "start") {
            const double loss = 0.5 * f * (p_cur.dot(W * p_cur) - p_new.dot(W * p_new));
            jump_dissipation += loss;
            stats.min_jump_dissipation_j = std::min(stats.min_jump_dissipation_j, loss);
        }
        const double jump = (p_new - p_cur).lpNorm<Eigen::Infinity>();
        if (cause != "start") stats.max_force_jump_n = std::max(stats.max_force_jump_n, jump);
        reset_check_anchors(q);
        stats.event_time_s += seconds_since(t_start) - (stats.contact_time_s - contact_before);
    }

    void reset_check_anchors(const Eigen::Ref<const Eigen::VectorXd>& q) {
        d_chk = d;
        const Eigen::VectorXd rel = Hs * q + bs + d;
        for (int kk = 0; kk < np; ++kk) {
            const auto& cp = pairs()[kk];
            if (cp.row_t >= 0 && cp.kind != PairKind::bonded && tmode[kk] != STICK) d_chk[cp.row_t] = rel[cp.row_t];
        }
    }

    bool modes_hold(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& qd,
                    double& residual, bool* witnesses_ok = nullptr) {
        std::vector<double> g(slots.size());
        if (!slots.empty()) witnesses(q, qd, g.data());
        const Eigen::VectorXd p = forces(q);
        chk_problem.q = GPhi * q - d_chk;
        residual = error_vector(chk_problem, p, Eigen::VectorXd(Hs * q + bs + d - d_chk)).norm();
        const bool positive = std::all_of(g.begin(), g.end(), [](double v) { return v >= 0.0; });
        if (witnesses_ok) *witnesses_ok = positive;
        return positive && residual < opt.solver.tolerance_m;
    }

    // ---- CVODE ------------------------------------------------------------------

    static int rhs(sunrealtype, N_Vector yv, N_Vector ydot, void* user) {
        const auto* s = static_cast<const Impl*>(user);
        const int r = s->r;
        const double* Y = N_VGetArrayPointer(yv);
        double* D = N_VGetArrayPointer(ydot);
        const Eigen::Map<const Eigen::VectorXd> q(Y, r), qd(Y + r, r);
        Eigen::Map<Eigen::VectorXd>(D, r) = qd;
        Eigen::Map<Eigen::VectorXd>(D + r, r) = s->A1 * q + s->a0;
        double pw = 0.0;  // friction power -sum_slip p_t ds_t/dt >= 0
        for (int rt : s->slip_rows) pw -= (s->P.row(rt).dot(q) + s->p0[rt]) * s->Hs.row(rt).dot(qd);
        D[2 * r] = pw;
        return 0;
    }

    static int roots(sunrealtype, N_Vector yv, sunrealtype* g, void* user) {
        const auto* s = static_cast<const Impl*>(user);
        const double* Y = N_VGetArrayPointer(yv);
        s->witnesses(Eigen::Map<const Eigen::VectorXd>(Y, s->r), Eigen::Map<const Eigen::VectorXd>(Y + s->r, s->r), g);
        return 0;
    }

    void restart(double te) {
        const auto t0 = Clock::now();
        cvode->reinit(te);
        ++stats.restarts;
        stats.event_time_s += seconds_since(t0);
    }

    // ---- records ----------------------------------------------------------------

    /// The record at time tau of state Y: w = Phi_w q + rw . p; energies: kinetic
    /// |q'|^2 / 2 (mass-normalised modes; the contact layer is massless), strain
    /// (q^T Omega^2 q + p^T W p) / 2 (the cross terms vanish: Phi^T K R = 0).
    StepRecord make_record(double tau, const Eigen::Ref<const Eigen::VectorXd>& Y, Eigen::VectorXd& p,
                           Eigen::VectorXd& rel) const {
        const auto q = Y.head(r);
        const auto qd = Y.segment(r, r);
        p = forces(q);
        rel = W * p + GPhi * q;
        const Eigen::VectorXd qdd = A1 * q + a0;
        const double w = phiw.dot(q) + rw.dot(p);
        const double wd = phiw.dot(qd) + rw.dot(P * qd);
        const double wdd = phiw.dot(qdd) + rw.dot(P * qdd);
        const double strain = 0.5 * f * (q.dot(om.cwiseProduct(om).cwiseProduct(q)) + p.dot(W * p));
        StepRecord rec;
        fill_state(sys, chk_problem, p, w, wd, strain, f * Y[2 * r] + jump_dissipation, e0, LoadState{}, rec);
        const double kinetic = 0.5 * f * qd.squaredNorm();
        rec.leaf_kinetic_energy_j = kinetic - rec.kinetic_energy_j;
        rec.kinetic_energy_j = kinetic;
        rec.impact_loss_j = 0.0;
        rec.force_on_mass_n = m_body * wdd;
        rec.energy_balance_error_j = e0 - (kinetic + strain + rec.dissipated_energy_j);
        rec.t_s = tau;
        rec.contact_iterations = static_cast<int>(iters_since);
        rec.factorizations = static_cast<int>(facts_since);
        rec.contact_residual_m = last_check_residual;
        return rec;
    }

    double output_time(long i) const { return i == n_out ? t_final : static_cast<double>(i) * dt; }

    void emit_until(double upto) {
        long next = out_index + static_cast<long>(pending.size()) + 1;
        while (next <= n_out && output_time(next) <= upto) {
            const double tau = output_time(next);
            cvode->dense_output(tau);
            Output o;
            o.rec = make_record(tau, cvode->ydky(), o.p, o.rel);
            iters_since = facts_since = 0;
            pending.push_back(std::move(o));
            ++next;
        }
    }

    void note_event_time(double te) {
        if (te == last_event_t) {
            if (++events_at_this_time > kMaxEventsAtOneTime)
                throw SolverError("cvode mode (leaf inertia): more than " + std::to_string(kMaxEventsAtOneTime) +
                                      " events at t = " + format_value(te) +
                                      " s: the contact modes chatter (no consistent mode set found)",
                                  stats.steps, te, 0.0);
        } else {
            last_event_t = te;
            events_at_this_time = 0;
        }
        ++stats.events;
    }

    bool step_once() {
        if (t >= t_final) return false;
        double tret = t;
        const auto t_cv = Clock::now();
        const int flag = cvode->advance(t_final, CV_ONE_STEP, opt.cvode.max_steps, tret);
        stats.cvode_time_s += seconds_since(t_cv);
        const CvodeCounters& cc = cvode->counters();
        stats.steps = cc.steps;
        stats.rhs_evaluations = cc.rhs_evaluations;
        stats.root_evaluations = cc.root_evaluations;
        Eigen::VectorXd Y = cvode->y();
        if (flag == CV_ROOT_RETURN) {
            emit_until(tret);
            t = tret;
            note_event_time(tret);
            std::vector<int> found(slots.size(), 0);
            cvode->root_info(found);
            decide_modes(Y.head(r), Y.segment(r, r), forces(Y.head(r)), "root", &found);
            restart(tret);
            return true;
        }
        // the contact iteration at the accepted step (as cvode_stepper.cpp)
        const auto t_check = Clock::now();
        double residual = 0.0;
        bool witnesses_ok = false;
        bool ok = modes_hold(Y.head(r), Y.segment(r, r), residual, &witnesses_ok);
        stats.max_check_residual_m = std::max(stats.max_check_residual_m, residual);
        last_check_residual = residual;
        if (!ok && witnesses_ok) {
            const Eigen::VectorXd pm = forces(Y.head(r));
            Eigen::VectorXd p = pm;
            const SolveResult res = chk_solver->solve(chk_problem, p);  // q set by modes_hold
            stats.contact_iterations += res.iterations;
            iters_since += res.iterations;
            last_check_residual = res.residual_m;
            ok = res.converged;
            for (int kk = 0; kk < np && ok; ++kk)
            if (ok)
                stats.max_check_force_difference_n =
                    std::max(stats.max_check_force_difference_n, (p - pm).lpNorm<Eigen::Infinity>());
        }
        stats.contact_time_s += seconds_since(t_check);
        if (ok) {
            emit_until(tret);
            t = tret;
            reset_check_anchors(Y.head(r));
            return tret < t_final;
        }
        const double hlast = cvode->last_step();
        double lo = tret - hlast, hi = tret;
        const double tol_t = 1e-13 * std::max(1.0, std::abs(tret)) + 1e-9 * hlast;
        while (hi - lo > tol_t) {
            const double mid = 0.5 * (lo + hi);
            cvode->dense_output(mid);
            const Eigen::VectorXd Ym = cvode->ydky();
            double rm = 0.0;
            if (modes_hold(Ym.head(r), Ym.segment(r, r), rm)) lo = mid;
            else hi = mid;
        }
        cvode->dense_output(hi);
        Y = cvode->ydky();
        emit_until(hi);
        cvode->y() = Y;
        t = hi;
        ++stats.missed_events;
        note_event_time(hi);
        decide_modes(Y.head(r), Y.segment(r, r), forces(Y.head(r)), "check", nullptr);
        restart(hi);
        return true;
    }
};

CvodeModalStepper::~CvodeModalStepper() = default;

CvodeModalStepper::CvodeModalStepper(const System& system, const SimulationOptions& options)
    : impl_(std::make_unique<Impl>(system, options)) {
    Impl& s = *impl_;
    s.opt.validate();
    require_uniform_leaf_mass(system, "cvode");
    require_initial_conditions_only(s.opt.loading, "mode cvode with leaf mass");
    if (s.opt.tau_rule != TauRule::current)
        throw InputError("tau_rule", "mode cvode takes the friction limit from the current normal force "
                                     "(tau rule 'current'); 'previous-step' is a fixed-step device of the paper");
    const Eigen::SparseMatrix<double>& K = system.stiffness_reduced();
    const Eigen::SparseMatrix<double> M = system.mass_reduced();
    const Eigen::SparseMatrix<double>& G = system.contact_rows();
    s.n = static_cast<int>(K.rows());
    s.w_dof = s.n - 1;
    s.m = system.num_components();
    s.np = static_cast<int>(system.pairs().size());
    s.f = system.model().whole_spring_factor();
    s.d = system.initial_offsets_m();
    const auto& body = system.model().spec().rigid_body;
    s.m_body = body.mass_kg;

    // modes of the unconnected stack (K, M), dense: n is a few hundred on the example
    const Eigen::MatrixXd Kd(K), Md(M);
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(Kd, Md);
    if (eig.info() != Eigen::Success || !(eig.eigenvalues().minCoeff() > 0.0))
        throw SolverError("cvode mode (leaf inertia): the modal analysis of the stack failed (K or M not positive "
                          "definite)", 0, 0.0, 0.0);
    const Eigen::VectorXd omega = eig.eigenvalues().cwiseSqrt();
    // default cut: 10 times the stack's first frequency (the body's mode with the leaves'
    // mass in it); the leaf bending modes above respond quasi-statically
    const double cut = s.opt.cvode.modal_cutoff_rad_per_s > 0.0 ? s.opt.cvode.modal_cutoff_rad_per_s : 10.0 * omega[0];
    s.r = 0;
    while (s.r < s.n && omega[s.r] <= cut) ++s.r;
    if (s.r == 0)
        throw InputError("modal_cutoff", "value " + format_value(cut) + " rad/s is below the stack's first frequency " +
                                             format_value(omega[0]) + " rad/s: no mode would carry the motion");
    s.Phi = eig.eigenvectors().leftCols(s.r);
    s.om = omega.head(s.r);
    s.nstate = 2 * s.r + 1;
    s.stats.retained_modes = s.r;
    s.stats.modal_cutoff_rad_per_s = cut;

    // residual flexibility R = K^-1 - Phi Omega^-2 Phi^T, on the contact rows
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> kf(K);
    const Eigen::MatrixXd Gd(G);
    const Eigen::MatrixXd KiGt = kf.solve(Eigen::MatrixXd(Gd.transpose()));  // n x m
    s.GPhi = Gd * s.Phi;
    const Eigen::MatrixXd GPhiS = s.GPhi * s.om.cwiseInverse().asDiagonal();
    s.W = Gd * KiGt - GPhiS * GPhiS.transpose();
    s.W = 0.5 * (s.W + s.W.transpose()).eval();
    s.phiw = s.Phi.row(s.w_dof).transpose();
    s.rw = KiGt.row(s.w_dof).transpose() - s.GPhi * s.om.cwiseProduct(s.om).cwiseInverse().cwiseProduct(s.phiw);

    // scales (cvode_stepper.cpp): R's amplitude on the tied stack, its frequency
    const double omega_t = std::sqrt(system.tied_stiffness_n_per_m() / body.mass_kg);
    s.L_ref = std::abs(body.initial_displacement_m) + std::abs(body.initial_velocity_m_per_s) / omega_t;
    if (!(s.L_ref > 0.0)) s.L_ref = 1e-3;
    s.V_ref = omega_t * s.L_ref;
    double preload = 0.0;
    for (const auto& cp : system.pairs()) preload = std::max(preload, cp.preload_n);
    s.F_ref = std::max(preload, system.tied_stiffness_n_per_m() / s.f * s.L_ref);

    s.chk_problem.W = s.W;
    s.chk_problem.pairs = system.pairs();
    s.chk_problem.tau_rule = TauRule::current;
    s.chk_problem.tau_previous_n = Eigen::VectorXd::Zero(s.np);
    s.chk_problem.q = Eigen::VectorXd::Zero(s.m);
    s.ev_problem = s.chk_problem;
    s.chk_solver = make_solver(s.opt.solver);
    // forces resolved to the witnesses' margin, 1e-9 F_ref, through the residual
    // compliance (its entries are far smaller than C''s: most of the leaves'
    // flexibility is in the retained modes)
    s.ev_tolerance = 1e-9 * s.F_ref * s.W.diagonal().maxCoeff();
    s.gap_margin = std::max(kMotionMargin, 10.0 * s.ev_tolerance / s.L_ref);
    s.ev_solver = make_solver(event_solver_options(s.opt.solver, s.ev_tolerance));

    // witness slots, as the massless mode
    for (int kk = 0; kk < s.np; ++kk) {
        const auto& cp = system.pairs()[kk];
        if (cp.kind == PairKind::bonded) continue;
        const bool friction = cp.row_t >= 0 && cp.friction_coefficient > 0.0;
        if (cp.kind == PairKind::coulomb && cp.row_n >= 0) s.slots.push_back({kk, true});
        if (cp.kind == PairKind::clamp && friction && cp.row_n >= 0) s.slots.push_back({kk, true});
        if (friction && (cp.kind == PairKind::clamp || cp.row_n >= 0)) s.slots.push_back({kk, false});
    }

    // initial state: the leaves at rest in the static shape of w(0) (z = 0 on the
    // paper example) moving with R: the tied shape per unit w times w'(0), projected
    // on the retained modes (q = Phi^T M z, mass-normalised)
    std::vector<int> tied;
    for (const auto& pr : system.pairs()) {
        if (pr.row_n >= 0) tied.push_back(pr.row_n);
        if (pr.row_t >= 0 && (pr.kind == PairKind::bonded || pr.friction_coefficient > 0.0)) tied.push_back(pr.row_t);
    }
    const Eigen::VectorXd z0 = tied_shape(K, G, tied, body.initial_displacement_m, s.d);
    const Eigen::VectorXd v0 = body.initial_velocity_m_per_s * tied_shape(K, G, tied, 1.0, Eigen::VectorXd::Zero(s.m));
    s.dt = s.opt.dt_s;
    s.n_out = static_cast<long>(std::ceil(s.opt.t_end_s / s.dt - 1e-9));
    s.t_final = static_cast<double>(s.n_out) * s.dt;
    s.cvode = std::make_unique<CvodeSession>("cvode mode (leaf inertia)", s.nstate);
    auto Y = s.cvode->y();
    Y.head(s.r) = s.Phi.transpose() * (M * z0);
    Y.segment(s.r, s.r) = s.Phi.transpose() * (M * v0);
    Y[2 * s.r] = 0.0;

    // initial modes: from the contact problem at q(0), then decided a look-ahead on
    Eigen::VectorXd p_init = Eigen::VectorXd::Zero(s.m);
    {
        s.ev_problem.q = s.GPhi * Eigen::VectorXd(Y.head(s.r)) - s.d;
        const SolveResult r0 = s.ev_solver->solve(s.ev_problem, p_init);
        if (!r0.converged) throw SolverError("initial contact state: " + r0.message, 0, 0.0, r0.residual_m);
    }
    modes_from_solution(s.chk_problem, p_init, 1e-12 * s.F_ref, s.nmode, s.tmode);
    s.build_mode();
    s.decide_modes(Y.head(s.r), Y.segment(s.r, s.r), p_init, "start", nullptr);

    // tolerances: the modal coordinates carry energy (q' in sqrt(J)/..., mass-normalised):
    // the same absolute tolerance on every coordinate, from the user's atol on w as an
    // amplitude of the body's mode (sqrt(m) omega atol) and rtol of the motion's energy
    {
        const double e_meshed = 0.5 * Y.segment(s.r, s.r).squaredNorm() +
                                0.5 * Y.head(s.r).dot(s.om.cwiseProduct(s.om).cwiseProduct(Y.head(s.r)));
        const double a_e = std::max(std::sqrt(system.mass_kg()) * omega_t * s.opt.cvode.atol_m,
                                    s.opt.cvode.rtol * std::sqrt(2.0 * e_meshed));
        auto A = s.cvode->atol();
        for (int i = 0; i < s.r; ++i) {
            A[i] = a_e / s.om[i];  // q_i: energy-norm amplitude omega_i q_i
            A[s.r + i] = a_e;      // q_i'
        }
        A[2 * s.r] = a_e * a_e;    // D [J, meshed part]
    }
    Eigen::VectorXd p_rec, rel_rec;
    s.record = s.make_record(0.0, Y, p_rec, rel_rec);
    s.iters_since = s.facts_since = 0;  // counted in the initial record (as the massless mode)
    s.e0 = s.record.kinetic_energy_j + s.record.strain_energy_j;
    s.record.energy_balance_error_j = 0.0;
    s.p_out = p_rec;
    s.rel_out = rel_rec;

    s.cvode->create(CV_ADAMS, &Impl::rhs, &s, s.opt.cvode.rtol);
    s.cvode->use_fixed_point();
    s.cvode->set_limits(s.opt.cvode.max_step_s);
    s.cvode->set_stop_time(s.t_final);
    if (s.opt.cvode.root_finding && !s.slots.empty()) s.cvode->set_roots(static_cast<int>(s.slots.size()), &Impl::roots);
}

const StepRecord& CvodeModalStepper::advance() {
    Impl& s = *impl_;
    if (s.out_index >= s.n_out)
        throw InputError("advance", "the run has reached t_end = " + format_value(s.t_final) + " s");
    while (s.pending.empty()) {
        if (!s.step_once() && s.pending.empty())
            throw SolverError("cvode mode (leaf inertia): reached t = " + format_value(s.t) +
                                  " s without the output at " + format_value(s.output_time(s.out_index + 1)) + " s",
                              s.stats.steps, s.t, 0.0);
    }
    s.record = std::move(s.pending.front().rec);
    s.p_out = std::move(s.pending.front().p);
    s.rel_out = std::move(s.pending.front().rel);
    s.pending.pop_front();
    ++s.out_index;
    return s.record;
}

const StepRecord& CvodeModalStepper::current() const noexcept { return impl_->record; }
const CvodeStats& CvodeModalStepper::stats() const noexcept { return impl_->stats; }
const std::vector<ContactEvent>& CvodeModalStepper::events() const noexcept { return impl_->events; }
const Eigen::VectorXd& CvodeModalStepper::contact_forces() const noexcept { return impl_->p_out; }
const Eigen::VectorXd& CvodeModalStepper::relative_positions() const noexcept { return impl_->rel_out; }
long CvodeModalStepper::record_index() const noexcept { return impl_->out_index; }
std::vector<PairRecord> CvodeModalStepper::pairs() const {
    return pair_records(impl_->sys, impl_->chk_problem, impl_->p_out, impl_->rel_out);
}
RunReport CvodeModalStepper::report() const { return event_report(impl_->stats, impl_->events); }

}  // namespace stackbeam::detail
