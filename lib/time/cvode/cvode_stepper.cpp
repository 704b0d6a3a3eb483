// Mode "cvode": CVODE between contact events, root-finding on every transition,
// the contact iteration deciding the modes at events and checking every accepted
// step. The physics and the witness functions are stated in cvode_stepper.hpp.
#include "stackbeam/time/cvode_stepper.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <deque>
#include <limits>

#include "contact/active_set.hpp"
#include "time/cvode/cvode_modes.hpp"
#include "time/cvode/sundials.hpp"
#include "time/step_record.hpp"
#include "stackbeam/errors.hpp"
#include "model/mesh_note.hpp"

namespace stackbeam {
namespace {

// Pair modes: those of the active-set solvers (active_set.hpp), T_NONE for an absent
// tangential component.
using detail::CLOSED;
using detail::FREE;
using detail::OPEN;
using detail::SLIP_NEG;
using detail::SLIP_POS;
using detail::STICK;
using detail::kForceMargin;
using detail::kLookahead;
using detail::kMaxEventsAtOneTime;
using detail::kMotionMargin;
constexpr signed char N_NONE = detail::NONE, T_NONE = detail::NONE;

}  // namespace

bool ContactEvent::is_stick_slip() const {
    auto fr = [](const std::string& s) { return s == "stick" || s == "slip+" || s == "slip-"; };
    return fr(from) && fr(to);
}

struct CvodeStepper::Impl {
    const System& sys;
    SimulationOptions opt;
    int n = 0, np = 0;
    const Eigen::MatrixXd& C;  // C' [m/N]
    Eigen::VectorXd c;         // coupling [-]
    Eigen::VectorXd d;         // gaps (normal rows) and anchors (tangential rows) [m]
    Eigen::VectorXd d_chk;     // anchors of the per-step check: slip rows at the previous accepted step
    double k = 0, m = 0, f = 1;
    Loading load;              // the loading (loading.hpp), prepared
    double m_whole = 0;        // R's whole mass [kg]
    /// External force on R of the meshed part at t [N] (loading.hpp: F/f - m g - m y_b'').
    double fe(double t_s) const { return load.external_force_n(t_s, m_whole) / f; }
    /// ODE size: [w, w', D], plus the external work W_e when a loading exerts a force
    /// (under the paper's initial conditions it is identically zero and left out, so
    /// that CVODE's error norm, an RMS over the states, is the same as without it).
    int nstate = 3;
    double F_ref = 1, L_ref = 1, V_ref = 1, omega_ref = 1;
    detail::ModeSet modes;                               // the current modes
    std::vector<signed char>& nmode = modes.nmode;       // per pair: CLOSED, OPEN (N_NONE: no normal row)
    std::vector<signed char>& tmode = modes.tmode;       // per pair: STICK, SLIP_POS, SLIP_NEG, FREE (T_NONE)

    // the current mode set: p(w) = P w + r, s(w) = hs w + bs, m w'' = a1 w + a0,
    // D' = -w' (diss_a w + diss_b)
    Eigen::VectorXd P, r, hs, bs;
    double a1 = 0, a0 = 0, diss_a = 0, diss_b = 0;
    Eigen::PartialPivLU<Eigen::MatrixXd> lu;

    struct Slot { int pair; bool normal; };
    std::vector<Slot> slots;

    // CVODE
    std::unique_ptr<detail::CvodeSession> cvode;

    double t = 0.0;        // time of the last accepted point
    double t_final = 0.0;
    double dt = 0.0;
    long n_out = 0, out_index = 0;
    std::deque<std::pair<StepRecord, Eigen::VectorXd>> pending;  // records and their contact forces
    StepRecord record;
    Eigen::VectorXd p_out;

    ContactProblem chk_problem, ev_problem;
    double ev_tolerance = 0.0;  // [m] the event decisions' tolerance on ||v|| (see the constructor)
    std::unique_ptr<ContactSolver> chk_solver, ev_solver;
    std::vector<ContactEvent> events;
    CvodeStats stats;
    double e0 = 0.0;
    long iters_since = 0, facts_since = 0;
    double last_check_residual = 0.0;
    double last_event_t = -1.0;
    int events_at_this_time = 0;

    Impl(const System& s, const SimulationOptions& o) : sys(s), opt(o), C(s.compliance_held()) {}

    const std::vector<ContactPair>& pairs() const { return sys.pairs(); }

    // ---- modes -------------------------------------------------------------------

    /// Factorises the linear conditions of the current modes (cvode_stepper.hpp).
    /// Unknowns are the forces of the held rows S (closed normal, stuck tangential:
    /// s_row = 0, i.e. (C'p)_row = d_row - c_row w); the others follow from them:
    /// open and free rows carry 0, a slipping row p_t = sigma mu tau, affine in its
    /// pair's normal force (coulomb: -p_n; clamp: F_c - p_n). So p = T p_S + e and
    ///     (C'_S: T) p_S = d_S - c_S w - C'_S: e,
    /// an |S| x |S| LU (|S| is small when most pairs are open or slipping).
    void build_mode() {
        detail::ModeLinearization lin;
        modes.linearize(chk_problem, lin);
        const std::vector<int>& S = lin.S;
        std::vector<int> pos(n, -1);
        const int ms = static_cast<int>(S.size());
        for (int i = 0; i < ms; ++i) pos[S[i]] = i;
        // p = T p_S + e: T as (row, column, coefficient) triplets
        Eigen::MatrixXd CT = Eigen::MatrixXd::Zero(n, ms);  // C' T, all rows
        const Eigen::VectorXd& e = lin.e;
        struct Link { int row, col; double coef; };
        std::vector<Link> T;
        for (int i = 0; i < ms; ++i) T.push_back({S[i], i, 1.0});
        for (std::size_t i = 0; i < lin.coupled.size(); ++i)
            if (pos[lin.coupled[i].second] >= 0) T.push_back({lin.coupled[i].first, pos[lin.coupled[i].second], lin.coef[i]});
        for (const auto& l : T) CT.col(l.col) += l.coef * C.col(l.row);
        const Eigen::VectorXd Ce = C * e;
        Eigen::MatrixXd A(ms, ms);
        Eigen::VectorXd b1(ms), b0(ms);
        for (int i = 0; i < ms; ++i) {
            A.row(i) = CT.row(S[i]);
            b1[i] = -c[S[i]];
            b0[i] = d[S[i]] - Ce[S[i]];
        }
        Eigen::VectorXd x1 = Eigen::VectorXd::Zero(ms), x0 = Eigen::VectorXd::Zero(ms);
        if (ms > 0) {
            lu.compute(A);
            x1 = lu.solve(b1);
            x0 = lu.solve(b0);
            if (!x1.allFinite() || !x0.allFinite())
                throw SolverError("cvode mode: the contact conditions of the current modes are singular at t = " +
                                      format_value(t) + " s",
                                  stats.steps, t, 0.0);
        }
        P = Eigen::VectorXd::Zero(n);
        r = e;
        for (const auto& l : T) {
            P[l.row] += l.coef * x1[l.col];
            r[l.row] += l.coef * x0[l.col];
        }
        hs = CT * x1 + c;       // C'P + c
        bs = CT * x0 + Ce - d;  // C'r - d
        a1 = c.dot(P) - k;
        a0 = c.dot(r);
        diss_a = diss_b = 0.0;
        for (int kk = 0; kk < np; ++kk) {
            const int rt = pairs()[kk].row_t;
            if (rt >= 0 && (tmode[kk] == SLIP_POS || tmode[kk] == SLIP_NEG)) {
                diss_a += P[rt] * hs[rt];
                diss_b += r[rt] * hs[rt];
            }
        }
        ++stats.mode_factorizations;
        ++facts_since;
    }

    Eigen::VectorXd forces(double w) const { return P * w + r; }

    /// Witness functions at (w, w'): positive while the modes hold.
    void witnesses(double w, double wd, double* g) const {
        for (std::size_t i = 0; i < slots.size(); ++i) {
            const int kk = slots[i].pair;
            const auto& cp = pairs()[kk];
            const auto pn = [&] { return cp.row_n >= 0 ? P[cp.row_n] * w + r[cp.row_n] : 0.0; };
            double v = 1.0;
            double margin = kForceMargin;
            if (slots[i].normal) {
                if (cp.kind == PairKind::coulomb) {
                    if (nmode[kk] == CLOSED) {
                        v = -pn() / F_ref;
                    } else {
                        v = -(hs[cp.row_n] * w + bs[cp.row_n]) / L_ref;
                        margin = kMotionMargin;
                    }
                } else {  // clamp: engaged while p_n < F_c
                    v = tmode[kk] == FREE ? (pn() - cp.preload_n) / F_ref : (cp.preload_n - pn()) / F_ref;
                }
            } else {
                const int rt = cp.row_t;
                const double pt = P[rt] * w + r[rt];
                switch (tmode[kk]) {
                    case STICK: {
                        const double tau_n = cp.kind == PairKind::clamp ? std::max(0.0, cp.preload_n - pn()) : -pn();
                        v = (cp.friction_coefficient * tau_n - std::abs(pt)) / F_ref;
                        break;
                    }
                    case SLIP_POS: v = -hs[rt] * wd / V_ref; margin = kMotionMargin; break;
                    case SLIP_NEG: v = hs[rt] * wd / V_ref; margin = kMotionMargin; break;
                    default: v = 1.0; break;
                }
            }
            g[i] = v + margin;
        }
    }

    /// The contact iteration decides the modes at (t_e, w, w'), with the forces p_cur
    /// there in the old modes (cvode_stepper.hpp). Logs the transitions; refactorises.
    /// `triggered` (root returns): the witness slots CVODE found; the old modes with
    /// those transitions applied are tried first, and kept if they hold on the
    /// look-ahead problem (the contact iteration's stop test accepts them there);
    /// otherwise, and without `triggered`, the exact contact solver decides.
    void decide_modes(double te, double w, double wd, const Eigen::VectorXd& p_cur, const std::string& cause,
                      const std::vector<int>* triggered = nullptr) {
        // s + d; in a built mode affine in w (O(n)), else (t = 0) from the forces
        const Eigen::VectorXd rel = P.size() == n ? Eigen::VectorXd(hs * w + bs + d) : Eigen::VectorXd(C * p_cur + c * w);
        const double wdd = (c.dot(p_cur) - k * w + fe(te)) / m;
        const double target = kLookahead * L_ref;
        double delta = std::numeric_limits<double>::infinity();
        if (wd != 0.0) delta = std::min(delta, target / std::abs(wd));
        if (wdd != 0.0) delta = std::min(delta, std::sqrt(2.0 * target / std::abs(wdd)));
        if (!std::isfinite(delta)) delta = 0.0;
        const double dw = wd * delta + 0.5 * wdd * delta * delta;

        // Incremental problem a look-ahead away: stuck pairs keep their anchors, every
        // other pair is anchored where it is (paper, section 5).
        Eigen::VectorXd d_la = d;
        for (int kk = 0; kk < np; ++kk) {
            const auto& cp = pairs()[kk];
            if (cp.row_t >= 0 && cp.kind != PairKind::bonded && tmode[kk] != STICK) d_la[cp.row_t] = rel[cp.row_t];
        }
        ev_problem.q = c * (w + dw) - d_la;

        // Re-anchors the pairs that start to stick; the modes become (nm, tm).
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
        if (triggered != nullptr && n > 0) {
            nm = nmode;
            tm = tmode;
            for (std::size_t i = 0; i < slots.size(); ++i) {
                if ((*triggered)[i] == 0) continue;
                const int kk = slots[i].pair;
                detail::apply_transition(pairs()[kk], slots[i].normal,
                                         pairs()[kk].row_t >= 0 ? p_cur[pairs()[kk].row_t] : 0.0, nm[kk], tm[kk]);
            }
            const Eigen::VectorXd d_saved = d;
            const std::vector<signed char> nm_saved = nmode, tm_saved = tmode;
            enter(nm, tm);
            build_mode();
            // the stop test of the contact iteration at the look-ahead, and every witness
            const double wl = w + dw, wdl = wd + wdd * delta;
            const Eigen::VectorXd pl = forces(wl);
            const double v = error_vector(ev_problem, pl, hs * wl + bs + d - d_la).norm();
            std::vector<double> g(slots.size());
            if (!slots.empty()) witnesses(wl, wdl, g.data());
            decided = v < ev_tolerance && std::all_of(g.begin(), g.end(), [](double x) { return x >= 0.0; });
            ++stats.contact_iterations;
            ++iters_since;
            d = d_saved;  // restored either way: log() below re-anchors from the old modes
            nmode = nm_saved;
            tmode = tm_saved;
        }
        if (!decided) {
            Eigen::VectorXd p_la = p_cur;
            const SolveResult res = ev_solver->solve(ev_problem, p_la);
            stats.contact_iterations += res.iterations;
            iters_since += res.iterations;
            if (!res.converged)
                throw SolverError("cvode mode: the contact iteration deciding the modes at t = " + format_value(t) +
                                      " s (" + cause + ") did not converge: " + res.message + detail::mesh_note(sys.model()),
                                  stats.steps, t, res.residual_m);
            detail::modes_from_solution(chk_problem, p_la, 1e-12 * F_ref, nm, tm);
        }

        // Log the transitions, enter the new modes, refactorise (unless the candidate was).
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
            e.from = cause == "start" ? "none" : detail::mode_label(pairs()[kk], nmode[kk], tmode[kk]);
            e.to = detail::mode_label(pairs()[kk], nm[kk], tm[kk]);
            e.cause = cause;
            e.w_m = w;
            e.w_dot_m_per_s = wd;
            events.push_back(std::move(e));
        }
        enter(nm, tm);
        if (!decided) build_mode();
        const Eigen::VectorXd p_new = forces(w);
        if (n > 0) stats.max_force_jump_n = std::max(stats.max_force_jump_n, (p_new - p_cur).lpNorm<Eigen::Infinity>());
        reset_check_anchors(w);
    }

    /// Check anchors: stuck pairs at their anchors, the others where they are now.
    void reset_check_anchors(double w) {
        d_chk = d;
        if (n == 0) return;
        const Eigen::VectorXd rel = hs * w + bs + d;
        for (int kk = 0; kk < np; ++kk) {
            const auto& cp = pairs()[kk];
            if (cp.row_t >= 0 && cp.kind != PairKind::bonded && tmode[kk] != STICK) d_chk[cp.row_t] = rel[cp.row_t];
        }
    }

    /// True when the modes hold at (w, w'): every witness positive and the paper's
    /// incremental problem (anchors d_chk) satisfied by the mode solution to the
    /// contact tolerance. `residual` gets ||v|| (eq. 9).
    bool modes_hold(double w, double wd, double& residual, bool* witnesses_ok = nullptr) {
        std::vector<double> g(slots.size());
        if (!slots.empty()) witnesses(w, wd, g.data());
        residual = 0.0;
        if (n > 0) {
            const Eigen::VectorXd p = forces(w);
            chk_problem.q = c * w - d_chk;
            // s = C'p + c w - d_chk = (C'P + c) w + (C'r - d) + d - d_chk: O(n), no product with C'
            residual = error_vector(chk_problem, p, hs * w + bs + d - d_chk).norm();
        }
        const bool positive = std::all_of(g.begin(), g.end(), [](double v) { return v >= 0.0; });
        if (witnesses_ok) *witnesses_ok = positive;
        return positive && residual < opt.solver.tolerance_m;
    }

    // ---- CVODE -------------------------------------------------------------------

    static int rhs(sunrealtype tt, N_Vector yv, N_Vector ydot, void* user) {
        const auto* self = static_cast<const Impl*>(user);
        const double* yy = N_VGetArrayPointer(yv);
        double* dy = N_VGetArrayPointer(ydot);
        const double fe = self->fe(tt);
        dy[0] = yy[1];
        dy[1] = (self->a1 * yy[0] + self->a0 + fe) / self->m;
        dy[2] = -yy[1] * (self->diss_a * yy[0] + self->diss_b);
        if (self->nstate > 3) dy[3] = fe * yy[1];  // power of the external force (meshed part)
        return 0;
    }

    static int roots(sunrealtype, N_Vector yv, sunrealtype* g, void* user) {
        const auto* self = static_cast<const Impl*>(user);
        const double* yy = N_VGetArrayPointer(yv);
        self->witnesses(yy[0], yy[1], g);
        return 0;
    }

    void init_cvode(double w0, double wd0) {
        cvode = std::make_unique<detail::CvodeSession>("cvode mode", nstate);
        auto yy = cvode->y();
        yy[0] = w0;
        yy[1] = wd0;
        auto at = cvode->atol();
        at[0] = opt.cvode.atol_m;                 // w [m]
        at[1] = opt.cvode.atol_m * omega_ref;     // w' [m/s]
        at[2] = opt.cvode.atol_m * F_ref;         // D [J]
        if (nstate > 3) at[3] = opt.cvode.atol_m * F_ref;  // external work [J]
        cvode->create(CV_ADAMS, &Impl::rhs, this, opt.cvode.rtol);
        cvode->use_fixed_point();
        cvode->set_limits(opt.cvode.max_step_s);
        cvode->set_stop_time(t_final);
        if (opt.cvode.root_finding && !slots.empty()) cvode->set_roots(static_cast<int>(slots.size()), &Impl::roots);
    }

    void restart(double te, double w, double wd, double D, double We) {
        auto yy = cvode->y();
        yy[0] = w;
        yy[1] = wd;
        yy[2] = D;
        if (nstate > 3) yy[3] = We;
        cvode->reinit(te);
        ++stats.restarts;
    }

    /// State at time tau within the last step (CVODE's dense output).
    void state_at(double tau, double& w, double& wd, double& D, double& We) {
        cvode->dense_output(tau);
        const auto yy = cvode->ydky();
        w = yy[0];
        wd = yy[1];
        D = yy[2];
        We = nstate > 3 ? yy[3] : 0.0;
    }

    // ---- records -----------------------------------------------------------------

    StepRecord make_record(double tau, double w, double wd, double D, double We) {
        const Eigen::VectorXd p = n > 0 ? forces(w) : Eigen::VectorXd();
        // U = (p^T C' p + k w^2) / 2 on the meshed part, with C'p = s + d - c w = hs w + bs + d - c w (O(n))
        const double strain = 0.5 * f * ((n > 0 ? p.dot(hs * w + bs + d - c * w) : 0.0) + k * w * w);
        StepRecord rec;
        detail::LoadState ls;
        ls.external_force_n = f * fe(tau);
        ls.external_work_j = f * We;
        ls.base_displacement_m = load.base_displacement_m(tau);
        detail::fill_state(sys, chk_problem, p, w, wd, strain, f * D, e0, ls, rec);
        rec.t_s = tau;
        rec.contact_iterations = static_cast<int>(iters_since);
        rec.factorizations = static_cast<int>(facts_since);
        iters_since = facts_since = 0;
        rec.contact_residual_m = last_check_residual;
        return rec;
    }

    double output_time(long i) const { return i == n_out ? t_final : static_cast<double>(i) * dt; }

    /// Queues the records of the output times in (t, upto] (the current modes hold there).
    void emit_until(double upto) {
        long next = out_index + static_cast<long>(pending.size()) + 1;
        while (next <= n_out && output_time(next) <= upto) {
            const double tau = output_time(next);
            double w, wd, D, We;
            state_at(tau, w, wd, D, We);
            pending.emplace_back(make_record(tau, w, wd, D, We), n > 0 ? forces(w) : Eigen::VectorXd());
            ++next;
        }
    }

    void note_event_time(double te) {
        if (te == last_event_t) {
            if (++events_at_this_time > kMaxEventsAtOneTime)
                throw SolverError("cvode mode: more than " + std::to_string(kMaxEventsAtOneTime) +
                                      " events at t = " + format_value(te) +
                                      " s: the contact modes chatter (no consistent mode set found)",
                                  stats.steps, te, 0.0);
        } else {
            last_event_t = te;
            events_at_this_time = 0;
        }
        ++stats.events;
    }

    /// One CVODE step and what follows it; returns false at the end of the run.
    bool step_once() {
        if (t >= t_final) return false;
        double tret = t;
        const int flag = cvode->advance(t_final, CV_ONE_STEP, opt.cvode.max_steps, tret);
        const detail::CvodeCounters& cc = cvode->counters();
        stats.steps = cc.steps;
        stats.rhs_evaluations = cc.rhs_evaluations;
        stats.root_evaluations = cc.root_evaluations;
        const auto yy = cvode->y();
        const double w = yy[0], wd = yy[1], D = yy[2], We = nstate > 3 ? yy[3] : 0.0;

        if (flag == CV_ROOT_RETURN) {
            emit_until(tret);  // the old modes hold up to the root
            t = tret;
            note_event_time(tret);
            const Eigen::VectorXd p_cur = forces(w);
            std::vector<int> found(slots.size(), 0);
            cvode->root_info(found);
            decide_modes(tret, w, wd, p_cur, "root", &found);
            restart(tret, w, wd, D, We);
            return true;
        }

        // The contact iteration at the accepted step (the configured solver; the paper's
        // projected iteration by default) on the paper's incremental problem, warm-started
        // at the mode solution. Its first act is its stop test, ||v|| < tolerance at the
        // warm start (modes_hold computes exactly that v): when it passes, the iteration
        // ends there with the mode solution as its answer. Otherwise it runs, and the
        // modes hold only if its answer leaves every pair in the mode CVODE integrated.
        double residual = 0.0;
        bool witnesses_ok = false;
        bool ok = modes_hold(w, wd, residual, &witnesses_ok);
        stats.max_check_residual_m = std::max(stats.max_check_residual_m, residual);
        last_check_residual = residual;
        if (!ok && witnesses_ok && n > 0) {
            const Eigen::VectorXd pm = forces(w);
            Eigen::VectorXd p = pm;
            const SolveResult res = chk_solver->solve(chk_problem, p);  // q was set by modes_hold
            stats.contact_iterations += res.iterations;
            iters_since += res.iterations;
            last_check_residual = res.residual_m;
            ok = res.converged;
            for (int kk = 0; kk < np && ok; ++kk)
                if (pair_state(chk_problem, kk, p) != pair_state(chk_problem, kk, pm)) ok = false;
            if (ok) stats.max_check_force_difference_n = std::max(stats.max_check_force_difference_n, (p - pm).lpNorm<Eigen::Infinity>());
        }
        if (ok) {
            emit_until(tret);
            t = tret;
            reset_check_anchors(w);
            return tret < t_final;
        }

        // A missed event: locate its time by bisection on the dense output of the last step.
        const double hlast = cvode->last_step();
        double lo = tret - hlast, hi = tret;
        const double tol_t = 1e-13 * std::max(1.0, std::abs(tret)) + 1e-9 * hlast;
        while (hi - lo > tol_t) {
            const double mid = 0.5 * (lo + hi);
            double wm, wdm, Dm, Wm, res_m;
            state_at(mid, wm, wdm, Dm, Wm);
            if (modes_hold(wm, wdm, res_m)) lo = mid;
            else hi = mid;
        }
        double we, wde, De, Wee;
        state_at(hi, we, wde, De, Wee);
        emit_until(hi);
        t = hi;
        ++stats.missed_events;
        note_event_time(hi);
        decide_modes(hi, we, wde, forces(we), "check");
        restart(hi, we, wde, De, Wee);
        return true;
    }
};

CvodeStepper::CvodeStepper(const System& system, const SimulationOptions& options)
    : impl_(std::make_unique<Impl>(system, options)) {
    Impl& s = *impl_;
    s.opt.validate();
    require_massless_leaves(system, Mode::cvode);
    if (s.opt.tau_rule != TauRule::current)
        throw InputError("tau_rule", "mode cvode takes the friction limit from the current normal force "
                                     "(tau rule 'current'); 'previous-step' is a fixed-step device of the paper");
    s.n = system.num_components();
    s.np = static_cast<int>(system.pairs().size());
    s.c = system.coupling();
    s.d = system.initial_offsets_m();
    s.k = system.stiffness_n_per_m();
    s.m = system.mass_kg();
    s.f = system.model().whole_spring_factor();
    s.load = s.opt.loading;
    s.load.prepare();
    require_loading_fits(system.model().spec(), s.load);
    s.m_whole = system.model().spec().rigid_body.mass_kg;
    s.nstate = s.load.is_free() ? 3 : 4;
    double w0 = system.model().spec().rigid_body.initial_displacement_m;
    // base excitation: w is relative to the supports, the initial velocity absolute (loading.hpp)
    const double wd0 = system.model().spec().rigid_body.initial_velocity_m_per_s - s.load.base_velocity_m_per_s(0.0);
    // The largest external force over the run (sampled; table points included) sets a
    // displacement scale F_e/k for the witnesses (gravity: the static deflection).
    double fe_max = 0.0;
    for (int i = 0; i <= 4000; ++i) fe_max = std::max(fe_max, std::abs(s.fe(s.opt.t_end_s * i / 4000.0)));
    for (double tp : s.load.force_n.times_s) fe_max = std::max(fe_max, std::abs(s.fe(tp)));

    // Scales of the run: the amplitude of R on the softest stack (no contact force),
    // the stiffest frequency (everything tied), the largest clamp preload.
    const double k_tied = system.num_components() > 0 ? system.tied_stiffness_n_per_m() / s.f : s.k;
    const double omega_free = std::sqrt(s.k / s.m);
    s.omega_ref = std::sqrt(std::max(k_tied, s.k) / s.m);
    s.L_ref = std::abs(w0) + std::abs(wd0) / omega_free + fe_max / s.k;
    if (!(s.L_ref > 0.0)) s.L_ref = 1e-3;  // at rest: nothing moves; any scale will do
    double preload = 0.0;
    for (const auto& cp : system.pairs()) preload = std::max(preload, cp.preload_n);
    s.F_ref = std::max(preload, std::max(k_tied, s.k) * s.L_ref);
    s.V_ref = s.omega_ref * s.L_ref;

    // Output grid: as the closed-form mode's steps.
    s.dt = s.opt.dt_s;
    s.n_out = static_cast<long>(std::ceil(s.opt.t_end_s / s.dt - 1e-9));
    s.t_final = static_cast<double>(s.n_out) * s.dt;

    // Witness slots: one per possible transition.
    for (int kk = 0; kk < s.np; ++kk) {
        const auto& cp = system.pairs()[kk];
        if (cp.kind == PairKind::bonded) continue;
        const bool friction = cp.row_t >= 0 && cp.friction_coefficient > 0.0;
        if (cp.kind == PairKind::coulomb && cp.row_n >= 0) s.slots.push_back({kk, true});
        if (cp.kind == PairKind::clamp && friction && cp.row_n >= 0) s.slots.push_back({kk, true});
        if (friction && (cp.kind == PairKind::clamp || cp.row_n >= 0)) s.slots.push_back({kk, false});
    }

    s.chk_problem.W = system.compliance_held();
    s.chk_problem.pairs = system.pairs();
    s.chk_problem.tau_rule = TauRule::current;
    s.chk_problem.tau_previous_n = Eigen::VectorXd::Zero(s.np);
    s.chk_problem.q = Eigen::VectorXd::Zero(s.n);  // sized: ModeSet::linearize takes n from it
    s.ev_problem = s.chk_problem;
    s.chk_solver = make_solver(s.opt.solver);
    // ||v|| of an exact active-set answer is LU round-off, ~cond(C') 1e-16 L_ref ~ 1e-11 L_ref;
    // 1e-10 L_ref accepts it and still resolves the look-ahead (1e-7 L_ref) a thousandfold.
    s.ev_tolerance = 1e-10 * s.L_ref;
    s.ev_solver = make_solver(detail::event_solver_options(s.opt.solver, s.ev_tolerance));

    // Gravity: the static equilibrium under R's weight first (as the closed-form mode):
    // k w - c^T p = -m g, s = C'p + c w - d, then the non-stuck pairs re-anchored.
    Eigen::VectorXd p0 = Eigen::VectorXd::Zero(s.n);
    double w_static = 0.0;
    if (s.load.gravity_m_per_s2 > 0.0) {
        w_static = detail::static_equilibrium_dense(system, s.ev_problem, -s.m * s.load.gravity_m_per_s2, *s.ev_solver,
                                                    p0, s.d, "static equilibrium under gravity")
                       .w_m;
        w0 += w_static;
    }
    // Initial contact state with R held at w(0) (as the closed-form mode), then the modes.
    if (w0 != w_static && s.n > 0) {
        s.ev_problem.q = s.c * w0 - s.d;
        const SolveResult r0 = s.ev_solver->solve(s.ev_problem, p0);
        if (!r0.converged) throw SolverError("initial contact state: " + r0.message, 0, 0.0, r0.residual_m);
    }
    detail::modes_from_solution(s.chk_problem, p0, 1e-12 * s.F_ref, s.nmode, s.tmode);
    s.decide_modes(0.0, w0, wd0, p0, "start");
    s.init_cvode(w0, wd0);
    s.record = s.make_record(0.0, w0, wd0, 0.0, 0.0);
    s.record.energy_balance_error_j = 0.0;
    s.e0 = s.record.kinetic_energy_j + s.record.strain_energy_j;
    s.p_out = s.n > 0 ? s.forces(w0) : Eigen::VectorXd();
}

CvodeStepper::~CvodeStepper() = default;

const StepRecord& CvodeStepper::advance() {
    Impl& s = *impl_;
    if (s.out_index >= s.n_out)
        throw InputError("advance", "the run has reached t_end = " + format_value(s.t_final) + " s");
    while (s.pending.empty()) {
        if (!s.step_once() && s.pending.empty())
            throw SolverError("cvode mode: reached t = " + format_value(s.t) + " s without the output at " +
                                  format_value(s.output_time(s.out_index + 1)) + " s",
                              s.stats.steps, s.t, 0.0);
    }
    s.record = std::move(s.pending.front().first);
    s.p_out = std::move(s.pending.front().second);
    s.pending.pop_front();
    ++s.out_index;
    return s.record;
}

const StepRecord& CvodeStepper::current() const noexcept { return impl_->record; }
long CvodeStepper::num_outputs() const noexcept { return impl_->n_out; }
long CvodeStepper::record_index() const noexcept { return impl_->out_index; }
std::vector<PairRecord> CvodeStepper::pairs() const {
    const Impl& s = *impl_;
    const Eigen::VectorXd rel = s.p_out.size() > 0 ? Eigen::VectorXd(s.C * s.p_out + s.c * s.record.w_m) : Eigen::VectorXd();
    return detail::pair_records(s.sys, s.chk_problem, s.p_out, rel);
}
RunReport CvodeStepper::report() const { return detail::event_report(impl_->stats, impl_->events); }
const Eigen::VectorXd& CvodeStepper::contact_forces() const noexcept { return impl_->p_out; }
const std::vector<ContactEvent>& CvodeStepper::events() const noexcept { return impl_->events; }
const CvodeStats& CvodeStepper::stats() const noexcept { return impl_->stats; }
const System& CvodeStepper::system() const noexcept { return impl_->sys; }

}  // namespace stackbeam
