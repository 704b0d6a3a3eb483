#pragma once
// Internal, a study aid (docs/decisions/036): what the sparse path's transition steps do,
// recorded per step when SparsePathTuning::observer points at a TransitionTrace (the benchmark's
// `trace` argument). Off (nullptr) by default: nothing is recorded and nothing costs.
#include <algorithm>
#include <ctime>
#include <functional>
#include <string>
#include <unordered_set>
#include <vector>

namespace stackbeam::detail::sparse {

/// The thread's CPU time [s] (the trace's phase and route times).
inline double thread_cpu_s() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// How ModeSolver::solve answered one call (docs/decisions/038): the current key's cached
/// factorisation; the Schur way's dense LU, its low-rank (Woodbury) update of the base's LU,
/// or the base's own set again; a sparse LU (KLU on the fixed pattern, or the held set's own
/// system); the bordered update of the last sparse LU; the primal route; the homotopy's kept
/// base with its columns (docs/decisions/045: a set near the base solved without a factorisation).
enum Route : int {
    route_cached,
    route_schur_lu,
    route_schur_update,
    route_schur_base,
    route_fixed_lu,
    route_lu,
    route_border,
    route_primal,
    route_kept,
    route_count
};
inline const char* route_name(int r) {
    static const char* const names[route_count] = {"cached", "schur-LU", "schur-update", "schur-base",
                                                   "fixed-LU", "own-LU", "border", "primal", "kept-base"};
    return names[r];
}

/// Per route: the calls, their CPU time [s] (ModeSolver::solve, factorisation and solves) and
/// their held rows summed (a mean set size per route); a fixed-pattern LU's pivoted
/// factorisations (the rest are refactorisations on the last pivot sequence).
struct RouteStats {
    long count[route_count] = {};
    double seconds[route_count] = {};
    double held[route_count] = {};
    long fixed_pivoted = 0;
    void add(const RouteStats& o, double sign = 1.0) {
        for (int r = 0; r < route_count; ++r) {
            count[r] += static_cast<long>(sign) * o.count[r];
            seconds[r] += sign * o.seconds[r];
            held[r] += sign * o.held[r];
        }
        fixed_pivoted += static_cast<long>(sign) * o.fixed_pivoted;
    }
    long solves() const {  // calls that made a new set's solve (all but the cached ones)
        long s = 0;
        for (int r = 1; r < route_count; ++r) s += count[r];
        return s;
    }
};

/// What one path_following did (the trace's counts, docs/decisions/040).
struct PathStats {
    enum End { not_run, reached, not_applicable, singular, too_many_rows, too_many_breakpoints, stalled, folded, cycled,
               singular_modes, too_many_start_hits };
    End end = not_run;
    int breakpoints = 0;     ///< mode switches along the path (hits within kGroupT of each other count once)
    int columns = 0;         ///< columns A0^-1 u_r solved with the base modes' factorisation (one per changed row)
    int column_blocks = 0;   ///< multi-column solves that made them
    int factorizations = 0;  ///< factorisations of the base modes (0 when still current)
    int updates = 0;         ///< the mode solver's bordered updates for them
    int rebases = 0;         ///< new bases (rebase_rows)
    int start_hits = 0;      ///< conditions of the start modes that fail before t = 1 (the first ratio test's)
    long evaluations = 0;    ///< pairs whose conditions were evaluated exactly at a ratio test
    long pair_tests = 0;     ///< pairs x ratio tests (the rest were bounded away from their kinks)
    /// the base kept from the last path run (Switches::path_keep_base, docs/decisions/045): true when
    /// this run started on it, its rows differing from the start modes then (-1 on a new base), and
    /// the rows differing from the (last) base at the end
    bool kept_base = false;
    int start_rows = -1, end_rows = 0;
    // CPU time [s] (thread): the columns' solves, the base factorisations and solves, the rest
    double column_s = 0.0, base_s = 0.0, total_s = 0.0;
};

/// The phases of a solve: the passes from the previous modes, the homotopy (with its
/// confirming passes; Switches::path_following), the semismooth Newton method,
/// the passes that confirm a Newton method's answer, the smoothing Newton method, the Tresca
/// fixed point (its box QPs and the passes after it).
enum Phase : int { phase_passes, phase_path, phase_semismooth, phase_confirm, phase_smoothing, phase_tresca, phase_count };
inline const char* phase_name(int p) {
    static const char* const names[phase_count] = {"passes", "path", "semismooth", "confirm", "smoothing", "tresca"};
    return names[p];
}

/// One iteration of the semismooth Newton method.
struct NewtonIterationTrace {
    int n_changes = 0;     ///< pairs whose normal mode (open / closed) changed from the last iterate's
    int t_changes = 0;     ///< pairs whose tangential mode (stick / slip+ / slip- / free) changed
    int returns = 0;       ///< of those, pairs back in a mode they had left earlier in this step
    double step = 1.0;     ///< the line search's step length (1: the full step)
    bool nonmonotone = false;
    int violations = 0;    ///< components of F above the acceptance after the step
};

/// One solve (one time step).
struct StepTrace {
    int pass_solves = 0;          ///< mode-set solves of the passes from the previous modes (step 1)
    bool passes_settled = false;
    std::vector<NewtonIterationTrace> iterations;
    /// how the semismooth method ended: 0 not run, 1 converged, 2 iteration limit,
    /// 3 no decrease (nonmonotone limit), 4 singular modes, 5 handed to the homotopy from rest
    /// (Switches::rest_path_violations; its run is then `path`)
    int newton_end = 0;
    bool newton_confirmed = false;  ///< the passes after it found no violation
    int confirm_solves = 0;         ///< mode-set solves of the passes after the Newton method
    int smoothing_iterations = 0;
    bool smoothing_ok = false;
    int solves = 0, factorizations = 0;
    int pairs = 0;                  ///< pairs with a normal or tangential row
    int pairs_changed = 0;          ///< distinct pairs that changed mode in the Newton iterations
    int max_changes_per_pair = 0;   ///< the most mode changes of one pair in the Newton iterations
    // distances to the step's final modes (pairs whose normal / tangential mode differs; -1 n/a)
    int start_n = -1, start_t = -1;  ///< the previous step's final modes (the passes' start)
    int pred_n = -1, pred_t = -1;    ///< the modes at the last two steps' (p, s) extrapolated
    int first_n = -1, first_t = -1;  ///< the semismooth method's first modes (extrapolated p, its s)
    int passes_n = -1, passes_t = -1;  ///< the modes the passes from the previous modes ended with
    int recallable = 0;    ///< new-set solves of a set already solved in this step (docs/decisions/038)
    int seen_earlier = 0;  ///< new-set solves of a set solved in an earlier step, not this one
    RouteStats phase[phase_count];     ///< the mode solver's calls per phase (docs/decisions/038)
    double phase_s[phase_count] = {};  ///< CPU time per phase [s] (its solves and everything else)
    // the homotopy (Switches::path_following, path_following.cpp; docs/decisions/040), or from
    // rest its run from a covering start (Switches::rest_path_violations, docs/decisions/041)
    PathStats path;                 ///< what it did (path.end not_run: not run)
    bool path_confirmed = false;    ///< it reached t = 1 and the passes from its modes settled
    int path_confirm_solves = 0;    ///< mode-set solves of the passes after it
};

}  // namespace stackbeam::detail::sparse

namespace stackbeam {

/// The sparse path's observer (SparsePathTuning::observer; public by name only: the public header
/// sparse_methods.hpp declares it, a study aid defined here, internally detail::sparse::TransitionTrace).
struct SparsePathObserver {
    using StepTrace = detail::sparse::StepTrace;
    using RouteStats = detail::sparse::RouteStats;
    using NewtonIterationTrace = detail::sparse::NewtonIterationTrace;
    static double thread_cpu_s() { return detail::sparse::thread_cpu_s(); }

    std::vector<StepTrace> steps;
    StepTrace* current = nullptr;  ///< the step being recorded (the solver's)
    RouteStats routes;             ///< the mode solver's calls so far (ModeSolver::solve adds to it)
    /// tests (docs/decisions/045): every solve on the homotopy's kept base checked against the same
    /// modes solved from scratch by a mode solver of its own (Eigen's SparseLU of the whole system):
    /// how many, the largest differences of p and z relative to their largest entries; and the same
    /// for a second from-scratch solve (KLU of the held set's system, where built) against it
    bool check_kept = false;
    int kept_checked = 0;
    double kept_p_diff = 0.0, kept_z_diff = 0.0, fresh_p_diff = 0.0, fresh_z_diff = 0.0;
    std::unordered_set<std::size_t> keys;       ///< hashes of the sets of modes solved so far (all steps)
    std::unordered_set<std::size_t> step_keys;  ///< those solved in the current step
    static std::size_t hash(const std::vector<signed char>& key) {
        return std::hash<std::string>()(std::string(key.begin(), key.end()));
    }
    /// A new step's record (the solver's, at the start of each solve), made current.
    StepTrace& new_step() {
        steps.emplace_back();
        current = &steps.back();
        step_keys.clear();
        return *current;
    }
    /// Counts a new-set solve of the set `key` into the current step (docs/decisions/038:
    /// a set solved earlier in this step, else in an earlier one) and remembers it.
    void count_solve(const std::vector<signed char>& key) {
        const std::size_t h = hash(key);
        if (step_keys.count(h) > 0) ++current->recallable;
        else if (keys.count(h) > 0) ++current->seen_earlier;
        step_keys.insert(h);
        keys.insert(h);
    }
    // the open phase's start: the routes and the CPU time then
    RouteStats mark;
    double mark_s = 0.0;
    /// Starts a phase (after the previous one was closed).
    void open_phase() {
        mark = routes;
        mark_s = thread_cpu_s();
    }
    /// Adds what happened since open_phase() to the current step's phase `ph`, and opens the next.
    void close_phase(int ph) {
        const double now = thread_cpu_s();
        if (current) {
            current->phase[ph].add(routes);
            current->phase[ph].add(mark, -1.0);
            current->phase_s[ph] += now - mark_s;
        }
        mark = routes;
        mark_s = now;
    }
    // the Newton iterations' bookkeeping within the current step: the last modes and, per
    // pair, the modes visited (bit nmode * 5 + tmode) and its number of changes
    std::vector<signed char> last_n, last_t;
    std::vector<signed char> first_n, first_t;  ///< the semismooth method's first modes this step
    std::vector<unsigned short> visited;
    std::vector<int> changes;

    static unsigned short bit(signed char n, signed char t) { return static_cast<unsigned short>(1u << (n * 5 + t)); }
    /// Starts a step's bookkeeping from modes (n, t).
    void begin(const std::vector<signed char>& n, const std::vector<signed char>& t) {
        last_n = n;
        last_t = t;
        visited.assign(n.size(), 0);
        changes.assign(n.size(), 0);
        for (std::size_t k = 0; k < n.size(); ++k) visited[k] = bit(n[k], t[k]);
    }
    /// Records the modes (n, t) of a Newton iteration into `it` and the step's counts.
    void iterate(const std::vector<signed char>& n, const std::vector<signed char>& t, NewtonIterationTrace& it) {
        if (last_n.size() != n.size()) begin(n, t);
        for (std::size_t k = 0; k < n.size(); ++k) {
            const bool dn = n[k] != last_n[k], dt = t[k] != last_t[k];
            if (!dn && !dt) continue;
            it.n_changes += dn;
            it.t_changes += dt;
            if (visited[k] & bit(n[k], t[k])) ++it.returns;
            visited[k] |= bit(n[k], t[k]);
            ++changes[k];
        }
        last_n = n;
        last_t = t;
    }
    /// Pairs whose normal / tangential modes differ between (n0, t0) and (n1, t1).
    static void distance(const std::vector<signed char>& n0, const std::vector<signed char>& t0,
                         const std::vector<signed char>& n1, const std::vector<signed char>& t1, int& dn, int& dt) {
        dn = dt = 0;
        if (n0.size() != n1.size()) {
            dn = dt = -1;
            return;
        }
        for (std::size_t k = 0; k < n0.size(); ++k) {
            dn += n0[k] != n1[k];
            dt += t0[k] != t1[k];
        }
    }
};

}  // namespace stackbeam

namespace stackbeam::detail::sparse {
using TransitionTrace = ::stackbeam::SparsePathObserver;
}  // namespace stackbeam::detail::sparse
