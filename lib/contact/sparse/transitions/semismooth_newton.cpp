// The semismooth Newton method of the sparse path on the natural map (transitions.hpp).
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "contact/sparse/driver/trace.hpp"
#include "contact/sparse/transitions/transitions.hpp"

namespace stackbeam::detail::sparse {

namespace {
// iteration limit, line-search grid (octaves of a), full steps taken although they raise
// the merit function
constexpr int kNewtonIterations = 60;
constexpr int kLineSearchOctaves = 12;
constexpr int kNewtonNonmonotone = 5;
// the creeping search's step length (Switches::creep_limit); the nonmonotone search's
// sufficient decrease (Switches::nonmonotone_memory)
constexpr double kCreepStep = 0.01;
constexpr double kNonmonotoneDecrease = 1e-4;

/// The modes of a start from rest: every unilateral pair open, only the bilateral rows
/// held (clamps sticking, bonds). On identical leaves most pairs open in the first steps
/// (measured: 850 of 891 pairs at 10 leaves x 100 elements), where "all closed" (the
/// stepper's modes at rest) is the worst start.
void set_open_modes(SparsePath& path) {
    for (int k = 0; k < static_cast<int>(path.laws.pairs.size()); ++k) {
        const auto& c = path.laws.pairs[k];
        if (c.row_n >= 0) path.modes.nmode[k] = modes::ModeSet::unilateral(c) ? modes::OPEN : modes::CLOSED;
        if (c.row_t >= 0) path.modes.tmode[k] = modes::STICK;
        path.modes.make_consistent(path.laws, k);
    }
}

/// The exact minimiser of theta(a) = ||F(p + a dp, s + a ds)||^2 over [a_min, 1]. Each
/// component of the natural map (SparsePath::natural_residual) is piecewise linear in a
/// along the Newton direction (s is affine in p; tau is linear in p_n on each side of its
/// kink under the current-step rule, constant under the previous-step rule), so theta is
/// piecewise quadratic with known kinks: a normal row where p_n - s_n / w changes sign, a
/// tangential row where tau's argument does and where p_t - s_t / w crosses +-mu tau. The
/// kinks are sorted and swept once, each pair's lines recomputed only at its own kinks, and
/// the quadratic of each interval minimised in closed form: O(m log m) for the whole search
/// instead of O(m) per trial point. Returns the minimiser (the caller evaluates F there).
/// The natural map's components along the step (p + a dp, s + a ds) as lines in a, piece by
/// piece (breakpoint_search).
struct StepLines {
    const ContactProblem& laws;
    const Eigen::VectorXd& diag;
    const bool prev;  // TauRule::previous_step
    const Eigen::VectorXd &p, &dp, &s, &ds;

    /// tau's argument as a line q0 + q1 a (clamp: F_c - p_n; coulomb: -p_n; tau = max(0, q))
    void tau_line(int k, double& q0, double& q1) const {
        const auto& c = laws.pairs[static_cast<std::size_t>(k)];
        const double pn0 = c.row_n >= 0 ? p[c.row_n] : 0.0, pn1 = c.row_n >= 0 ? dp[c.row_n] : 0.0;
        q0 = (c.kind == PairKind::clamp ? c.preload_n : 0.0) - pn0;
        q1 = -pn1;
    }
    /// the limit L = mu tau as a line on the piece where tau's argument has sign of q
    void limit_line(int k, double q, double q0, double q1, double& l0, double& l1) const {
        const auto& c = laws.pairs[static_cast<std::size_t>(k)];
        const double mu = c.friction_coefficient;
        l0 = l1 = 0.0;
        const bool carries = c.kind == PairKind::clamp ? (prev || q > 0.0) : (c.row_n >= 0 && q > 0.0);
        if (!carries) return;
        if (prev) {
            l0 = mu * laws.tau_previous_n[static_cast<std::size_t>(k)];
        } else {
            l0 = mu * q0;
            l1 = mu * q1;
        }
    }
    /// per pair: the lines (f0 + f1 a) of its normal and tangential components on the piece
    /// containing a (the rows of no pair, and bilateral rows, are s itself: F = s)
    void lines(int k, double a, double f[4]) const {
        const auto& c = laws.pairs[static_cast<std::size_t>(k)];
        f[0] = f[1] = f[2] = f[3] = 0.0;
        if (c.row_n >= 0) {
            f[0] = s[c.row_n];
            f[1] = ds[c.row_n];
            if (c.kind == PairKind::coulomb) {
                const double w = diag[c.row_n];
                const double an = (p[c.row_n] - s[c.row_n] / w) + a * (dp[c.row_n] - ds[c.row_n] / w);
                if (!(an < 0.0)) {  // open branch: F = w p_n
                    f[0] = w * p[c.row_n];
                    f[1] = w * dp[c.row_n];
                }
            }
        }
        if (c.row_t < 0) return;
        f[2] = s[c.row_t];
        f[3] = ds[c.row_t];
        if (c.kind == PairKind::bonded) return;
        double q0, q1, l0, l1;
        tau_line(k, q0, q1);
        limit_line(k, q0 + a * q1, q0, q1, l0, l1);
        const double w = diag[c.row_t];
        const double at = (p[c.row_t] - s[c.row_t] / w) + a * (dp[c.row_t] - ds[c.row_t] / w);
        const double L = l0 + a * l1;
        if (at > L) {  // F = w (p_t - L)
            f[2] = w * (p[c.row_t] - l0);
            f[3] = w * (dp[c.row_t] - l1);
        } else if (at < -L) {  // F = w (p_t + L)
            f[2] = w * (p[c.row_t] + l0);
            f[3] = w * (dp[c.row_t] + l1);
        }
    }
    /// the kinks of each pair in (a_min, 1), unsorted: (a, pair)
    std::vector<std::pair<double, int>> kinks(double a_min) const {
        std::vector<std::pair<double, int>> events;
        auto add_root = [&](double num, double den, double lo, double hi, int k) {  // root of num + den a in (lo, hi)
            if (den == 0.0) return;
            const double a = -num / den;
            if (a > lo && a < hi) events.emplace_back(a, k);
        };
        const int np = static_cast<int>(laws.pairs.size());
        for (int k = 0; k < np; ++k) {
            const auto& c = laws.pairs[static_cast<std::size_t>(k)];
            if (c.row_n >= 0 && c.kind == PairKind::coulomb) {
                const double w = diag[c.row_n];
                add_root(p[c.row_n] - s[c.row_n] / w, dp[c.row_n] - ds[c.row_n] / w, a_min, 1.0, k);
            }
            if (c.row_t < 0 || c.kind == PairKind::bonded) continue;
            const double w = diag[c.row_t];
            const double t0 = p[c.row_t] - s[c.row_t] / w, t1 = dp[c.row_t] - ds[c.row_t] / w;
            double q0, q1;
            tau_line(k, q0, q1);
            double a_tau = 2.0;  // tau's kink (none in the range: 2)
            if (q1 != 0.0 && -q0 / q1 > a_min && -q0 / q1 < 1.0) {
                a_tau = -q0 / q1;
                events.emplace_back(a_tau, k);
            }
            // crossings of a_t = +-L on each piece of L (at most two)
            const double cuts[3] = {a_min, std::min(a_tau, 1.0), 1.0};
            for (int piece = 0; piece < (a_tau < 1.0 ? 2 : 1); ++piece) {
                const double lo = cuts[piece], hi = cuts[piece + 1];
                const double mid = 0.5 * (lo + hi);
                double l0, l1;
                limit_line(k, q0 + mid * q1, q0, q1, l0, l1);
                add_root(t0 - l0, t1 - l1, lo, hi, k);  // a_t = L
                add_root(t0 + l0, t1 + l1, lo, hi, k);  // a_t = -L
            }
        }
        return events;
    }
};

double breakpoint_search(const SparsePath& path, const Eigen::VectorXd& p, const Eigen::VectorXd& dp,
                         const Eigen::VectorXd& s, const Eigen::VectorXd& ds, double a_min) {
    const auto& laws = path.laws;
    const int np = static_cast<int>(laws.pairs.size());
    const StepLines sl{laws, path.diag(), laws.tau_rule == TauRule::previous_step, p, dp, s, ds};
    std::vector<std::pair<double, int>> events = sl.kinks(a_min);
    std::sort(events.begin(), events.end());
    // the sweep: theta = A a^2 + B a + C on each interval, each pair's share kept so that
    // only the pairs with a kink at an interval's end are recomputed
    const int m = static_cast<int>(s.size());
    std::vector<char> in_pair(static_cast<std::size_t>(m), 0);
    std::vector<double> share(static_cast<std::size_t>(np) * 3, 0.0);
    double A = 0.0, B = 0.0, C = 0.0;
    auto update = [&](int k, double a) {
        double f[4];
        sl.lines(k, a, f);
        double* q = &share[static_cast<std::size_t>(k) * 3];
        A -= q[0];
        B -= q[1];
        C -= q[2];
        q[0] = f[1] * f[1] + f[3] * f[3];
        q[1] = 2.0 * (f[0] * f[1] + f[2] * f[3]);
        q[2] = f[0] * f[0] + f[2] * f[2];
        A += q[0];
        B += q[1];
        C += q[2];
    };
    for (int k = 0; k < np; ++k) {
        const auto& c = laws.pairs[static_cast<std::size_t>(k)];
        if (c.row_n >= 0) in_pair[static_cast<std::size_t>(c.row_n)] = 1;
        if (c.row_t >= 0) in_pair[static_cast<std::size_t>(c.row_t)] = 1;
    }
    for (int i = 0; i < m; ++i)
        if (!in_pair[static_cast<std::size_t>(i)]) {
            A += ds[i] * ds[i];
            B += 2.0 * s[i] * ds[i];
            C += s[i] * s[i];
        }
    double lo = a_min;
    {
        const double hi = events.empty() ? 1.0 : events.front().first;
        for (int k = 0; k < np; ++k) update(k, 0.5 * (lo + hi));
    }
    double best_a = 1.0, best = std::numeric_limits<double>::infinity();
    auto consider = [&](double a) {
        const double v = (A * a + B) * a + C;
        if (v < best) {
            best = v;
            best_a = a;
        }
    };
    std::size_t e = 0;
    while (true) {
        const double hi = e < events.size() ? events[e].first : 1.0;
        if (hi > lo) {
            consider(lo);
            consider(hi);
            if (A > 0.0) {
                const double a = -B / (2.0 * A);
                if (a > lo && a < hi) consider(a);
            }
        }
        if (e >= events.size()) break;
        // the pairs with a kink at hi take their lines on the next interval
        std::size_t f = e;
        while (f < events.size() && events[f].first == hi) ++f;
        const double next = f < events.size() ? events[f].first : 1.0;
        for (std::size_t g = e; g < f; ++g) update(events[g].second, 0.5 * (hi + next));
        e = f;
        lo = hi;
    }
    return best_a;
}
/// The line search along the Newton step from (p, sk) to its full step (p1, s1), theta = ||F||^2
/// at p: the step length into `a` (1 on entry), its theta returned (infinity where no trial was
/// better than none); nonmonotone_full where the nonmonotone test took the full step. pa, sa, F1:
/// workspaces.
double line_search(SparsePath& path, const Eigen::VectorXd& p, const Eigen::VectorXd& sk, const Eigen::VectorXd& p1,
                   const Eigen::VectorXd& s1, double theta, const std::vector<double>& recent, double& a,
                   bool& nonmonotone_full, Eigen::VectorXd& pa, Eigen::VectorXd& sa, Eigen::VectorXd& F1) {
    const int memory = path.switches.nonmonotone_memory;
    // line search: the smallest theta on the grid a = 2^(-j/4), j = 0 .. 4 kLineSearchOctaves
    // (each trial O(m)); theta is piecewise quadratic along the step with many kinks
    // (every component that changes branch), so the grid's best point is taken rather
    // than the first that passes Armijo's test (measured: 26 instead of 48 iterations
    // on the first step of 10 leaves x 100 elements). Where no trial lowers theta, the
    // full step is taken (non-monotone; at most kNewtonNonmonotone times).
    double grid_theta = std::numeric_limits<double>::infinity();
    const double a_min = std::pow(2.0, -static_cast<double>(kLineSearchOctaves));
    bool searched = false;
    if (memory > 0) {
        // the nonmonotone search (Grippo, Lampariello and Lucidi, SIAM J. Numer. Anal. 23
        // (1986)): the full step wherever it lowers theta below the largest of the last
        // `memory` iterates' (Switches::nonmonotone_memory; docs/decisions/037: the exact
        // minimiser creeps, 0.1-0.3 of the step per iteration for tens of iterations, where
        // the full step is the linear solution of the new modes), else the exact search
        path.natural_residual(p1, s1, F1, false);
        const double t1 = F1.squaredNorm();
        if (t1 < (1.0 - kNonmonotoneDecrease) * *std::max_element(recent.begin(), recent.end())) {
            grid_theta = t1;
            a = 1.0;
            searched = nonmonotone_full = true;
        }
    }
    if (!searched && path.switches.incremental) {
        // the exact minimiser over the grid's range (breakpoint_search), checked by one
        // evaluation of F (the sweep's sums are exact up to their round-off); the full
        // step where it is as good (p is then the linear solution of its modes)
        const double ab = breakpoint_search(path, p, p1 - p, sk, s1 - sk, a_min);
        for (const double aj : {ab, 1.0}) {
            pa = p + aj * (p1 - p);
            sa = sk + aj * (s1 - sk);
            path.natural_residual(pa, sa, F1, false);
            const double tj = F1.squaredNorm();
            if (tj < grid_theta || (aj == 1.0 && tj <= grid_theta * (1.0 + 1e-12))) {
                grid_theta = tj;
                a = aj;
            }
            if (ab == 1.0) break;
        }
        searched = grid_theta < theta;  // else the grid below decides, as before
    }
    for (int j = 0; !searched && j <= 4 * kLineSearchOctaves; ++j) {
        const double aj = std::pow(2.0, -0.25 * j);
        pa = p + aj * (p1 - p);
        sa = sk + aj * (s1 - sk);
        path.natural_residual(pa, sa, F1, false);
        const double tj = F1.squaredNorm();
        if (tj < grid_theta) {
            grid_theta = tj;
            a = aj;
        }
    }
    return grid_theta;
}
}  // namespace

/// Semismooth Newton method on the natural map (Alart-Curnier / Pang's natural-map
/// Newton, planar: the tangential direction is a scalar), for transitions where nearly
/// every pair changes mode (identical leaves starting from rest: forces and gaps ~0).
/// Each iteration:
///  1. the modes of the generalised Jacobian of F at the iterate (natural_residual): which
///     part of each min / clamp is active there;
///  2. the Newton step: the linear problem of those modes, s_S = 0, fixed and slip forces
///     (solve_modes: the sparse saddle-point system, its low-rank update or the Schur
///     complement, as for the active-set passes), giving (p1, z1); F is piecewise linear
///     in p, so this is the full Newton step p1 - p;
///  3. a line search on theta = ||F||^2 along it: s is affine in p, so
///     s(p + a (p1 - p)) = s + a (s1 - s) and theta is piecewise quadratic in a; its exact
///     minimiser over [2^-12, 1] by one sweep over the sorted kinks (breakpoint_search;
///     with Switches::incremental off, and where that finds no decrease, the best of a
///     49-point grid, each trial O(m)). Where no step decreases theta the full step is
///     taken (a non-monotone step; at most kNewtonNonmonotone of them) rather than stalling.
/// From rest (p = 0) it starts from the open modes' solution (set_open_modes).
/// Unlike block principal pivoting, the modes come from p - s / w (forces and gaps
/// together), and a damped step moves every component part of the way, so many pairs
/// change per iteration without the ping-pong of full switches. Stops when every
/// component of F is within `accept` [m] (half the active-set threshold, so the passes
/// that follow see no violated mode); returns false after kNewtonIterations or on a
/// singular set of modes (p and z are then the last iterate). From rest with
/// Switches::rest_path_violations > 0 it also returns false (p, z the linear solution of
/// the current modes) after a full step that leaves 1 to that many components of F above
/// `accept`: the caller's homotopy finishes (docs/decisions/041). On entry z must be
/// K^-1 (b + G^T p).
bool semismooth_newton(SparsePath& path, const Step& step, Eigen::VectorXd& p, Eigen::VectorXd& z, SolveResult& r) {
    const SparseStiffness& st = path.stiffness();
    const Eigen::VectorXd& d = step.d;
    const int m = static_cast<int>(d.size());
    path.best_p.resize(0);
    path.handed_over = false;
    TransitionTrace* const trace = path.observer;
    StepTrace* const tr = trace ? trace->current : nullptr;
    auto end = [&](int how, bool result) {
        if (tr) tr->newton_end = how;
        return result;
    };
    const bool from_rest = m > 0 && p.isZero(0.0);
    if (from_rest) {
        // a start from rest (no force anywhere, the first step of a run): the linear problem
        // of the open modes (set_open_modes) instead of the natural map's modes at p = 0, where
        // every closed pair sits on the kink of its friction limit (tau = 0)
        set_open_modes(path);
        ++r.iterations;
        ++r.newton_iterations;
        try {
            r.factorizations += path.solve_modes(step, p, z);
        } catch (const SingularModes&) {
            path.solver.forget();
            return end(4, false);
        }
    }
    Eigen::VectorXd sk = st.Grow * z - d, F, F1, pa, sa, p1, z1, s1;
    path.natural_residual(p, sk, F, false);
    double theta = F.squaredNorm();
    int nonmonotone = 0;
    // the iterate of smallest ||F|| (where the smoothing method starts when this one fails)
    path.best_p = p;
    double best_theta = theta;
    bool full_step = false;  // p is the linear solution of the current modes
    int creeping = 0;                 // consecutive steps below kCreepStep (Switches::creep_limit)
    const int memory = path.switches.nonmonotone_memory;
    std::vector<double> recent{theta};  // the last iterates' theta, at most `memory` (the nonmonotone search)
    // from rest, the hand-over to the homotopy (Switches::rest_path_violations)
    const int handover = from_rest ? path.switches.rest_path_violations : 0;
    for (int it = 0; it < kNewtonIterations; ++it) {
        const double roundoff = st.roundoff(d, z);
        const double accept = std::max(0.5 * kAccept * path.options.tolerance_m, roundoff);
        if (m == 0 || F.lpNorm<Eigen::Infinity>() <= accept) {
            // the modes for the passes that follow: those of the last full step (its linear
            // problem gave p, so the passes reuse its factorisation), else those at p
            if (!full_step) path.natural_residual(p, sk, F, true);
            return end(1, true);
        }
        ++r.iterations;
        ++r.newton_iterations;
        path.natural_residual(p, sk, F, true);
        NewtonIterationTrace* itr = nullptr;
        if (tr) {
            if (trace->first_n.empty()) {
                trace->first_n = path.modes.nmode;
                trace->first_t = path.modes.tmode;
            }
            tr->iterations.emplace_back();
            itr = &tr->iterations.back();
            trace->iterate(path.modes.nmode, path.modes.tmode, *itr);
        }
        p1 = p;
        try {
            r.factorizations += path.solve_modes(step, p1, z1);
        } catch (const SingularModes&) {
            path.solver.forget();
            return end(4, false);
        }
        s1 = st.Grow * z1 - d;
        bool nonmonotone_full = false;
        double a = 1.0;
        const double grid_theta = line_search(path, p, sk, p1, s1, theta, recent, a, nonmonotone_full, pa, sa, F1);
        if (!(grid_theta < theta) && !nonmonotone_full) {
            if (itr) itr->nonmonotone = true;
            if (++nonmonotone > kNewtonNonmonotone) return end(3, false);
            a = 1.0;
        }
        if (itr) itr->step = a;
        // a creeping search (the step below kCreepStep Switches::creep_limit times in a row: a
        // kink of F next to the iterate at every step) is left to the smoothing method, which
        // has no kinks (docs/decisions/037)
        creeping = a < kCreepStep ? creeping + 1 : 0;
        // (the step is taken first: it lowered theta, so best_p may be its iterate)
        const bool creep_stop = path.switches.creep_limit > 0 && creeping >= path.switches.creep_limit;
        full_step = a == 1.0;
        if (full_step) {
            p = p1;
            z = z1;
            sk = s1;
        } else {
            p += a * (p1 - p);
            z += a * (z1 - z);
            sk += a * (s1 - sk);
        }
        path.natural_residual(p, sk, F, false);
        theta = F.squaredNorm();
        if (memory > 0) {
            recent.push_back(theta);
            if (recent.size() > static_cast<std::size_t>(memory)) recent.erase(recent.begin());
        }
        // the components of F above the acceptance after the step (the trace's count and the
        // hand-over's test)
        const bool handover_test = handover > 0 && full_step;
        int violated = 0;
        if (itr || handover_test) {
            const double acc = std::max(0.5 * kAccept * path.options.tolerance_m, st.roundoff(d, z));
            for (int i = 0; i < m; ++i) violated += std::abs(F[i]) > acc;
        }
        if (itr) itr->violations += violated;
        if (theta < best_theta) {
            best_theta = theta;
            path.best_p = p;
        }
        if (creep_stop) break;
        if (handover_test && violated > 0 && violated <= handover) {
            path.handed_over = true;
            return end(5, false);
        }
    }
    return end(2, false);
}

}  // namespace stackbeam::detail::sparse
