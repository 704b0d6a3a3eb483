#pragma once
// Internal, a study aid (docs/decisions/036): what the sparse path's transition steps do,
// recorded per step when Switches::trace points at a TransitionTrace (the benchmark's
// `trace` argument). Off (nullptr) by default: nothing is recorded and nothing costs.
#include <algorithm>
#include <vector>

namespace stackbeam::detail::sparse {

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
    /// 3 no decrease (nonmonotone limit), 4 singular modes
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
};

struct TransitionTrace {
    std::vector<StepTrace> steps;
    StepTrace* current = nullptr;  ///< the step being recorded (the solver's)
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

}  // namespace stackbeam::detail::sparse
