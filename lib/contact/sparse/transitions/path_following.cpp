// The parametric (homotopy) active-set transition of the sparse path (transitions.hpp,
// path_following; Switches::path_following, docs/decisions/040).
//
// The previous step's problem (b0, d0) was solved with modes M0; this step's is (b1, d1) on
// the same K, G and pairs. Along data(t) = data0 + t (data1 - data0), t in [0, 1], the
// solution of one set of modes is affine in t. Starting from M0 (valid at t = 0), a ratio
// test over the pairs' mode conditions finds the first t* where a mode stops being valid,
// that pair switches, and the path goes on from t*; at t = 1 the modes are this step's
// (Murty, Linear Complementarity, ch. 5: parametric principal pivoting).
//
// Every set of modes on the path is solved as a low-rank change of the base modes' linear
// problem (M0's, or the current modes' after a new base), whose factorisation (the mode
// solver's, one key) is made once: the full system in x = (z, p) is
//     K z - G^T p = b,   per contact row r one equation a_r x = f_r:
//       held (closed normal, stick)   g_r z = d_r
//       zero force (open, free)       p_r = 0
//       slip (p_t = e_t + c p_n)      p_t - c p_n = e_t
// and a set M differs from the base in the equations of a few rows C. With y_r = A0^-1 u_r
// (u_r the unit right-hand side of row r's base equation, scaled to about a metre of
// motion: one column per row that ever changes, solved with the base's factorisation,
// several in one multi-column solve where they are known together, without refinement)
// and x^(t) = A0^-1 f0(t) (the base's solution along the path),
//     x(t) = x^(t) + Y lambda(t),   H lambda = f^M_C(t) - a^M_C x^(t),   H = a^M_C Y,
// i.e. the base's equations hold on the rows outside C and M's on C (Woodbury / bordering;
// slip couplings are ordinary rows here). H is |C| x |C|, dense.
//
// The ratio test needs every pair's conditions at t = 1, but one breakpoint moves lambda
// only: a pair's condition at t = 1 moves by at most kappa_k ||d lambda_1|| (Cauchy-Schwarz
// on the rows of Y its condition reads), so a pair is evaluated exactly (its few entries of
// x^ + Y lambda, O(|C|) each) only where the accumulated bound reaches its slack to the
// acceptance; the others cannot switch.
//
// The answer at t = 1 is confirmed by the caller's active-set passes (so it is the exact
// solver's, solved with refinement); on any failure (no progress in t, too many breakpoints
// or changed rows, a singular H, or too many of the start modes' conditions failing at the
// first ratio test: a broad change, cheaper by the Newton methods; and where the switches say
// so, a pair switching back at the same t or switching too often: Switches::path_fold_ends,
// path_max_pair_switches) the caller falls back to the Newton methods.
//
// The path stays continuous where a pair takes friction with a friction limit of 0 (a pair
// that closes, a clamp back below its preload: Switches::path_clamp_slip): it slips against
// its tangential motion there, and sticks where that comes back to 0 (docs/decisions/042).
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "contact/sparse/transitions/path_base.hpp"

namespace stackbeam::detail::sparse {

namespace {

/// One run of path_following: the state its named steps share (the base and its solutions
/// x^ at t = 0 and 1, the current modes and equations, the columns' multipliers lambda at both
/// ends, the ratio test's bound) and the steps themselves, in the order the run takes them.
struct PathRun {
    SparsePath& path;
    const Step& step;
    const PathStart& start;
    SolveResult& r;
    PathStats& stats;
    const ContactProblem& laws;
    const int m, np;
    const Eigen::VectorXd& W;
    const double ts;                // the passes' acceptance [m]: a condition above it fails
    const int max_pair_switches;    // a pair switching more often: cycling
    const int rebase_rows, max_start_hits;
    modes::ModeSet cur;             // the current modes
    KeptBase* kb = nullptr;         // the base (path.kept)
    int upd0 = 0;                   // the mode solver's updates at the start
    // x^ at t = 0 and t = 1: [forces; G z] (2m entries each), both in one (multi-column,
    // refined) solve with the base's factorisation (or kept from the solves before on this base)
    Eigen::VectorXd X0h, X1h;
    std::vector<Eq> eq;             // the current set's equations
    std::vector<int> switches;      // per pair: its mode switches in this run
    std::vector<double> last_switch_t;
    std::vector<signed char> left_n, left_t;  // the modes a pair left last
    // the bound: A1 the sum of ||d lambda_1|| over the breakpoints; per pair the sum at its
    // last exact evaluation and its slack then (ts minus its largest condition at t = 1)
    double A1 = 0.0;
    std::vector<double> A1_at, slack;
    std::vector<char> dirty;
    Eigen::VectorXd L0, L1, L1_prev;  // lambda at t = 0 and 1 per column (0 outside C)
    double t = 0.0;
    int stalls = 0;
    std::vector<Hit> hits;
    std::vector<int> C;             // the rows whose equation differs from the base's
    double tmin = 2.0;              // the ratio test's first t' >= t where a condition fails
    double gmin = 0.0;              // the pair's slack (ts minus its largest condition at t = 1)

    PathRun(SparsePath& path_, const Step& step_, const PathStart& start_, SolveResult& r_, PathStats& stats_)
        : path(path_), step(step_), start(start_), r(r_), stats(stats_), laws(path_.laws), m(laws.size()),
          np(static_cast<int>(laws.pairs.size())), W(path_.diag()), ts(kAccept * path_.options.tolerance_m),
          max_pair_switches(path_.switches.path_max_pair_switches), rebase_rows(path_.switches.path_rebase_rows),
          max_start_hits(path_.switches.path_max_start_hits), X0h(2 * m), X1h(2 * m), switches(np, 0),
          last_switch_t(np, -1.0), left_n(np, modes::NONE), left_t(np, modes::NONE), A1_at(np, 0.0), slack(np, 0.0),
          dirty(np, 1) {
        cur.nmode = start.nmode;
        cur.tmode = start.tmode;
    }

    double rn(int q) const { return std::sqrt(kb->rn2[q]); }

    bool fail(PathStats::End end) {
        stats.end = end;
        return false;
    }

    void base_data() {
        const Eigen::VectorXd* b[2] = {&start.b, &step.b};
        const Eigen::VectorXd* d[2] = {&start.d, &step.d};
        Eigen::VectorXd* X[2] = {&X0h, &X1h};
        const int f = base_solutions(path, *kb, 2, b, d, X);
        r.factorizations += f;
        stats.factorizations += f;
    }

    void make_base() {
        const double c0 = thread_cpu_s();
        kb->set(laws, cur);
        base_data();
        stats.base_s += thread_cpu_s() - c0;
    }

    /// The base (KeptBase, path.kept): the start modes, their linear problem and key (as
    /// SparsePath::solve_modes names them, so a factorisation of M0 still current is reused), or
    /// the base kept from the last run where it is still current (path_keep_base: its columns
    /// kept, the start modes differing from it in a few rows). False where singular.
    bool start_base() {
        if (!path.kept || static_cast<int>(path.kept->col.size()) != m) path.kept = std::make_shared<KeptBase>(m);
        kb = path.kept.get();
        upd0 = path.solver.updates();
        try {
            if (keeps_base(path) && kb->current(path)) {
                const double c0 = thread_cpu_s();
                base_data();
                stats.base_s += thread_cpu_s() - c0;
                stats.kept_base = true;
            } else {
                make_base();
            }
        } catch (const SingularModes&) {
            return fail(PathStats::singular_modes);
        }
        ++r.iterations;
        mode_equations(laws, cur.nmode, cur.tmode, eq);
        return true;
    }

    /// x's entry q (a force: q < m; G z: m + q) at t = 0 and t = 1 under the current set
    /// (both ends at once: one pass over the row of Y).
    void x01(int q, double& a, double& b) const {
        a = X0h[q];
        b = X1h[q];
        if (kb->Y.size() == 0) return;
        double ya, yb;
        kb->Y.dot2(q, L0, L1, ya, yb);
        a += ya;
        b += yb;
    }

    /// The current set's multipliers: its changed rows C (past rebase_rows a new base), their
    /// columns, and lambda at both ends from the bordered system. False where it ends.
    bool solve_changed_rows() {
        changed_rows(eq, kb->eqs, C);
        if (stats.start_rows < 0 && stats.kept_base) stats.start_rows = static_cast<int>(C.size());
        if (rebase_rows > 0 && static_cast<int>(C.size()) > rebase_rows) {
            // a new base: the current modes factorised (the columns and the bound start again)
            make_base();
            eq = kb->eqs;
            A1 = 0.0;
            std::fill(dirty.begin(), dirty.end(), 1);
            L1_prev.resize(0);
            C.clear();
            ++stats.rebases;
        }
        const int nc = static_cast<int>(C.size());
        stats.end_rows = nc;
        if (nc > kMaxChangedRows) return fail(PathStats::too_many_rows);
        const int fc = add_columns(path, *kb, C, true, stats);
        r.factorizations += fc;
        stats.factorizations += fc;
        L0.setZero(kb->Y.padded());
        L1.setZero(kb->Y.padded());
        if (nc > 0) {
            const auto& col = kb->col;
            const Eigen::MatrixXd H = bordered_matrix(eq, C, kb->Y, col, W, m);
            const Eigen::VectorXd F0 = bordered_rhs(eq, C, W, m, [&](int r) { return eq[r].rhs(r, start.d); }, X0h);
            const Eigen::VectorXd F1 = bordered_rhs(eq, C, W, m, [&](int r) { return eq[r].rhs(r, step.d); }, X1h);
            const Eigen::PartialPivLU<Eigen::MatrixXd> lu(H);
            if (!(lu.rcond() > 1e-14)) return fail(PathStats::singular);
            const Eigen::VectorXd l0 = lu.solve(F0), l1 = lu.solve(F1);
            for (int j = 0; j < nc; ++j) {
                L0[col[C[j]]] = l0[j];
                L1[col[C[j]]] = l1[j];
            }
        }
        // the bound's step: lambda_1's change since the last breakpoint
        Eigen::VectorXd prev = Eigen::VectorXd::Zero(L1.size());
        prev.head(std::min(L1_prev.size(), L1.size())) = L1_prev.head(std::min(L1_prev.size(), L1.size()));
        A1 += (L1 - prev).norm();
        L1_prev = L1;
        return true;
    }

    /// One condition g [m], affine in t from g0 at t = 0 to g1 at t = 1: where it passes the
    /// acceptance on the rest of the path, a hit (pair k to mode `to`) at the first such t.
    void test(int k, bool normal, signed char to, double g0, double g1) {
        gmin = std::min(gmin, ts - g1);
        const double gc = g0 + t * (g1 - g0);
        if (!(g1 > ts) || !(g1 > gc)) return;  // valid at t = 1 and not rising
        const double th = gc >= ts ? t : t + (1.0 - t) * (ts - gc) / (g1 - gc);
        tmin = std::min(tmin, th);
        hits.push_back({k, normal, to, th});
    }

    /// Pair k's conditions moved by at most kappa x the bound's growth since its last exact
    /// evaluation: true where that stays within its slack then (no test needed).
    bool bounded_away(int k, bool nrow, bool trow) const {
        if (dirty[k]) return false;
        const auto& c = laws.pairs[k];
        const int rn_ = c.row_n, rt = c.row_t;
        const double mu = c.friction_coefficient;
        // the largest move of its conditions at t = 1 per unit of ||d lambda_1||
        double kappa = 0.0;
        if (nrow) kappa = cur.nmode[k] == modes::CLOSED ? W[rn_] * rn(rn_) : rn(m + rn_);
        if (trow) {
            const double Wt = W[rt], pn = rn_ >= 0 ? rn(rn_) : 0.0;
            double kt = c.kind == PairKind::clamp ? mu * Wt * pn : 0.0;
            if (cur.tmode[k] == modes::STICK) kt = std::max(kt, Wt * (rn(rt) + mu * pn));
            else if (cur.tmode[k] == modes::SLIP_POS || cur.tmode[k] == modes::SLIP_NEG) kt = std::max(kt, rn(m + rt));
            kappa = std::max(kappa, kt);
        }
        return kappa * (A1 - A1_at[k]) < slack[k];
    }

    /// Pair k's tangential conditions under its current mode (pn0, pn1: its normal force at both ends).
    void test_tangential(int k, double pn0, double pn1) {
        const auto& c = laws.pairs[k];
        const int rt = c.row_t;
        const bool clamp = c.kind == PairKind::clamp;
        const double mu = c.friction_coefficient;
        const double Wt = W[rt];
        // friction lost past the clamp's preload; the friction limit, affine in p_n
        const double rel0 = mu * (pn0 - c.preload_n) * Wt, rel1 = mu * (pn1 - c.preload_n) * Wt;
        const double lim0 = mu * (clamp ? c.preload_n - pn0 : -pn0), lim1 = mu * (clamp ? c.preload_n - pn1 : -pn1);
        switch (cur.tmode[k]) {
            case modes::STICK: {
                double pt0, pt1;
                x01(rt, pt0, pt1);
                if (clamp) test(k, false, modes::FREE, rel0, rel1);
                test(k, false, modes::SLIP_POS, (pt0 - lim0) * Wt, (pt1 - lim1) * Wt);
                test(k, false, modes::SLIP_NEG, (-pt0 - lim0) * Wt, (-pt1 - lim1) * Wt);
                break;
            }
            case modes::SLIP_POS:
            case modes::SLIP_NEG: {
                const double sigma = cur.tmode[k] == modes::SLIP_POS ? 1.0 : -1.0;
                double s0, s1;
                x01(m + rt, s0, s1);
                if (clamp) test(k, false, modes::FREE, rel0, rel1);
                test(k, false, modes::STICK, sigma * (s0 - start.d[rt]), sigma * (s1 - step.d[rt]));
                break;
            }
            case modes::FREE:
                if (clamp) test(k, false, modes::STICK, -rel0, -rel1);
                break;
            default: break;
        }
    }

    /// The ratio test: every pair's conditions on the rest of the path (those bounded away from
    /// their kinks skipped), its hits into `hits` and the first into tmin.
    void ratio_test() {
        tmin = 2.0;
        hits.clear();
        gmin = 0.0;
        for (int k = 0; k < np; ++k) {
            const auto& c = laws.pairs[k];
            const bool nrow = c.row_n >= 0 && modes::ModeSet::unilateral(c);
            const bool trow = !(c.row_t < 0 || c.kind == PairKind::bonded || c.friction_coefficient == 0.0 ||
                                (modes::ModeSet::unilateral(c) && cur.tmode[k] == modes::FREE));
            if (!nrow && !trow) continue;
            ++stats.pair_tests;
            if (bounded_away(k, nrow, trow)) continue;
            ++stats.evaluations;
            dirty[k] = 0;
            A1_at[k] = A1;
            gmin = std::numeric_limits<double>::infinity();
            const int rn_ = c.row_n;
            // the pair's normal force at both ends (its normal test, its friction limit)
            double pn0 = 0.0, pn1 = 0.0;
            if (rn_ >= 0 && (trow || (nrow && cur.nmode[k] == modes::CLOSED))) x01(rn_, pn0, pn1);
            if (nrow) {
                if (cur.nmode[k] == modes::CLOSED) {
                    test(k, true, modes::OPEN, pn0 * W[rn_], pn1 * W[rn_]);
                } else if (cur.nmode[k] == modes::OPEN) {
                    double g0, g1;
                    x01(m + rn_, g0, g1);
                    test(k, true, modes::CLOSED, g0 - start.d[rn_], g1 - step.d[rn_]);
                }
            }
            if (trow) test_tangential(k, pn0, pn1);
            slack[k] = gmin;
        }
    }

    /// The tangential mode of pair pc taking friction with a friction limit of 0 at tmin (one that
    /// closes, a clamp back below its preload, path_clamp_slip): it sticks only where its
    /// tangential position is at this step's anchor (s_t = 0), else it slips against s_t (the
    /// natural map's decision at p_t = 0): the path stays continuous, and sticks where s_t comes
    /// back to 0 (sticking at once would jump s_t to the anchor).
    signed char friction_from_zero(const ContactPair& pc) const {
        const int rt = pc.row_t;
        double s0, s1;
        x01(m + rt, s0, s1);
        const double stc = (1.0 - tmin) * (s0 - start.d[rt]) + tmin * (s1 - step.d[rt]);
        return std::abs(stc) <= ts ? modes::STICK : stc < 0.0 ? modes::SLIP_POS : modes::SLIP_NEG;
    }

    /// The breakpoint at tmin: the pairs that hit within kSameT of it switch (a pair's normal
    /// switch before its tangential), their equations updated. False where the run ends there
    /// (too many breakpoints, stalled, a fold, a cycle).
    bool switch_pairs() {
        if (++stats.breakpoints > kMaxBreakpoints) return fail(PathStats::too_many_breakpoints);
        stalls = tmin - t <= kSameT ? stalls + 1 : 0;
        if (stalls > kMaxStalls) return fail(PathStats::stalled);
        hits.erase(std::remove_if(hits.begin(), hits.end(), [&](const Hit& h) { return h.t > tmin + kSameT; }),
                   hits.end());
        std::stable_sort(hits.begin(), hits.end(), [](const Hit& a, const Hit& b) { return a.normal > b.normal; });
        std::vector<char> done(np, 0);
        for (const Hit& h : hits) {
            if (done[h.k]) continue;
            done[h.k] = 1;
            dirty[h.k] = 1;
            // back to the modes it left at the same t: the path folds, or a degenerate
            // vertex (several pairs at their kinks at one t) resolves by switching a pair
            // back (path_fold_ends false: it goes on, the stalls' limit bounds it)
            const signed char to_n = h.normal ? h.to : cur.nmode[h.k], to_t = h.normal ? cur.tmode[h.k] : h.to;
            if (path.switches.path_fold_ends && last_switch_t[h.k] >= 0.0 && tmin - last_switch_t[h.k] <= kSameT &&
                (h.normal ? to_n == left_n[h.k] : to_t == left_t[h.k]))
                return fail(PathStats::folded);
            if (++switches[h.k] > max_pair_switches && max_pair_switches > 0) return fail(PathStats::cycled);
            last_switch_t[h.k] = tmin;
            left_n[h.k] = cur.nmode[h.k];
            left_t[h.k] = cur.tmode[h.k];
            const auto& pc = laws.pairs[h.k];
            if (h.normal) {
                cur.nmode[h.k] = h.to;
                if (h.to == modes::CLOSED && pc.row_t >= 0) cur.tmode[h.k] = friction_from_zero(pc);
            } else if (h.to == modes::STICK && cur.tmode[h.k] == modes::FREE && path.switches.path_clamp_slip) {
                cur.tmode[h.k] = friction_from_zero(pc);
            } else {
                cur.tmode[h.k] = h.to;
            }
            cur.make_consistent(laws, h.k);
            Eq en, et;
            pair_equations(pc, cur.nmode[h.k], cur.tmode[h.k], en, et);
            if (pc.row_n >= 0) eq[pc.row_n] = en;
            if (pc.row_t >= 0) eq[pc.row_t] = et;
        }
        t = tmin;
        return true;
    }

    /// From the base to t = 1, one breakpoint at a time. False where it ends before.
    bool follow() {
        try {
            for (;;) {
                if (!solve_changed_rows()) return false;
                ratio_test();
                if (stats.breakpoints == 0 && stats.rebases == 0) {
                    stats.start_hits = static_cast<int>(hits.size());
                    if (max_start_hits > 0 && stats.start_hits > max_start_hits)
                        return fail(PathStats::too_many_start_hits);
                }
                if (hits.empty()) return true;  // the modes hold up to t = 1
                if (!switch_pairs()) return false;
            }
        } catch (const SingularModes&) {
            return fail(PathStats::singular_modes);
        }
    }

    /// The end: the modes at t = 1 into path.modes, the forces x at t = 1 into p.
    void finish(Eigen::VectorXd& p) {
        stats.updates += path.solver.updates() - upd0;
        stats.end = PathStats::reached;
        path.modes.nmode = cur.nmode;
        path.modes.tmode = cur.tmode;
        p = X1h.head(m);
        if (kb->Y.size() > 0)
            for (int q = 0; q < m; ++q) p[q] += kb->Y.dot(q, L1);
    }
};

}  // namespace

bool path_following(SparsePath& path, const Step& step, const PathStart& start, Eigen::VectorXd& p,
                    Eigen::VectorXd& z, SolveResult& r, PathStats& stats) {
    struct Clock {  // the whole run's CPU time, whatever the return
        double& total;
        double t0;
        ~Clock() { total += thread_cpu_s() - t0; }
    } clock{stats.total_s, thread_cpu_s()};
    if (path.laws.tau_rule != TauRule::current) {
        stats.end = PathStats::not_applicable;
        return false;
    }
    static_cast<void>(z);  // (not set: the passes after it solve the end modes again)
    path.solves_since_path = 0;
    PathRun run(path, step, start, r, stats);
    if (!run.start_base() || !run.follow()) return false;
    run.finish(p);
    return true;
}
}  // namespace stackbeam::detail::sparse
