#pragma once
/// @file sparse_methods.hpp
/// The sparse contact path's methods as a typed configuration (SparsePathTuning::methods), and
/// the observer a caller may attach to record what its transition steps do
/// (SparsePathTuning::observer). The defaults are the production method; the other values
/// are the ways before a decision, kept to check or measure it (tests, benchmarks/), each
/// named with its decision note (docs/decisions/). A solver takes them at its construction:
/// nothing of it is global or per-thread state.

namespace stackbeam {

/// The observer of a SparseContactSolver's transition steps: counters per route and phase,
/// per-step traces (defined in lib/contact/sparse/driver/trace.hpp, a study aid: tests and
/// benchmarks include it). The caller owns it and reads it.
struct SparsePathObserver;

/// How the sparse path solves a transition that the active-set passes from the previous
/// modes do not settle (SparseContactSolver::solve, step 2).
enum class SparseTransitionMethod {
    newton = 0,  ///< semismooth Newton on the natural map with a line search; if it fails, the smoothing
                 ///< Newton method; then the Tresca fixed point (default)
    // 1: semismooth, the semismooth method then the Tresca fixed point (the default before
    // decision 004), removed by decision 053; the values stay those the benchmark passes
    smoothing = 2,  ///< the smoothing Newton method alone, then the Tresca fixed point (tests)
    tresca = 3,     ///< the Tresca fixed point on a box QP only (the method before the Newton ones)
};

/// How the sparse path solves the box-constrained QP of the Tresca fixed point (friction
/// limits frozen): min 1/2 p^T W p + q^T p over lower <= p <= upper, with W = G K^-1 G^T
/// never formed. All end at the same working-set test, so their answers agree to round-off.
enum class SparseBoxQpMethod {
    pivoting,        ///< block principal pivoting (a few sparse solves where it settles); where it does not
                     ///< settle in 50 passes, a primal-dual interior-point method (Mehrotra's predictor-
                     ///< corrector, one sparse LDL^T of K + G^T Sigma^-1 G per iteration, its working set
                     ///< read from the iterate); then the monotone primal active-set method (default)
    interior_point,  ///< the interior-point method first, then as `pivoting` (tests)
    // (2: pivoting_only, the way before decision 006, removed by decision 053)
};

/// The methods of one SparseContactSolver (SparsePathTuning::methods, fixed at its
/// construction): the defaults are the production method; tests and the benchmark set a field
/// to check or measure one way alone, or the way before a decision (the field's note says which).
struct SparsePathMethods {
    SparseTransitionMethod transition = SparseTransitionMethod::newton;
    SparseBoxQpMethod box_qp = SparseBoxQpMethod::pivoting;
    /// Every solve starts with the transition method from the warm start (no active-set
    /// passes from the previous modes first, and whatever the problem's size), so its
    /// answers can be checked alone.
    bool newton_first = false;
    /// The incremental solve (docs/decisions/020): the Schur way's update of the base's
    /// dense LU (ModeSolverTuning::schur_updates) and the semismooth Newton method's exact
    /// breakpoint line search. false: every held set's Schur complement from scratch and the
    /// 49-point line search, the way before (kept for comparison in the benchmark and tests).
    bool incremental = true;
    /// The sparse LU of the mode solver's held sets above the Schur way's limit and of the
    /// smoothing Newton method's Jacobian (docs/decisions/031): 4 (default, docs/decisions/038)
    /// KLU on each held set's own system (the held rows only), ordered by AMD per set, the
    /// smoothing method's Jacobian on KLU's fixed pattern as with 2; 2 KLU on the fixed
    /// pattern of every contact row, ordered once per (K, G), refactorised on the last pivot
    /// sequence where it fits (the way before 038); 3 as 4 under the fixed pattern's ordering
    /// restricted to the set (measured no faster than 2); 1 Eigen's SparseLU on the fixed
    /// pattern (measured slower than 0); 0 each held set's own saddle-point system ordered
    /// and factorised from scratch by Eigen's SparseLU, and Eigen's SparseLU for the smoothing
    /// method. 2-4 need KLU (builds without it: as 0).
    int fixed_pattern = 4;
    /// KLU's refactorisation on the last pivot sequence kept by its solves' backward error
    /// (PatternLu::refined_solve; a rejected one pivots afresh) instead of its pivot growth
    /// (klu_rgrowth per factorisation): docs/decisions/035. false: the way before.
    bool residual_refactor_check = true;
    /// The bordered update of the sparse LU solves its new columns A0^-1 U together (one
    /// multi-column solve, refined together) instead of one refined solve per changed row
    /// (docs/decisions/035). false: the way before.
    bool block_border_solves = true;
    /// The bordered update's limit (changed rows) when the base LU is KLU's on the fixed
    /// pattern, whose refactorisation is cheap: at most this many (docs/decisions/035);
    /// -1: SparsePathTuning::max_border_rows alone, the way before.
    int fixed_border_rows = 8;
    /// The transition steps' method (docs/decisions/037; each measured on the graduated
    /// 10 x 400 spring; before_037() below sets the way before):
    /// active-set passes from the previous modes before a Newton method (0:
    /// SolverOptions::max_active_set_iterations, 3): one, the previous modes' solution; more
    /// switch every violated row and move away from the step's answer
    int newton_passes = 1;
    /// a start from rest (p = 0) takes the smoothing Newton method first, then (where it
    /// fails) the semismooth method. Off (the way before: the semismooth method first): on the
    /// graduated 10 x 400 it saves 40 mode-set solves but no CPU time (a smoothing iteration
    /// factorises the whole Jacobian), on identical leaves it fails first (25 iterations)
    bool smoothing_from_rest = false;
    /// without an extrapolation (one solve before), the semismooth method starts from the
    /// first pass's solution (false: from the warm start, the last step's answer)
    bool first_pass_start = true;
    /// the semismooth method gives way to the smoothing method after this many line-search
    /// steps below 0.01 in a row (0: never; it ran its 60 iterations)
    int creep_limit = 5;
    /// the semismooth method's line search takes the full step wherever it lowers ||F||^2
    /// below the largest of the last this many iterates' (nonmonotone; 0: the exact
    /// minimiser along the step, monotone)
    int nonmonotone_memory = 10;
    /// All of the above the way before decision 037 (the benchmark's before).
    static SparsePathMethods before_037() {
        SparsePathMethods s;
        s.newton_passes = 0;
        s.smoothing_from_rest = false;
        s.first_pass_start = false;
        s.creep_limit = 0;
        s.nonmonotone_memory = 0;
        return s;
    }
    /// The Schur way's fresh dense LU (a held set no low-rank update of the base reaches) only
    /// up to this many held rows; larger sets take the sparse LU (ModeSolverTuning::
    /// schur_fresh_max_rows; docs/decisions/038). -1: no limit, the way before.
    int schur_fresh_max_rows = 200;
    /// The parametric (homotopy) active-set transition (path_following.cpp, docs/decisions/040):
    /// where the passes from the previous modes do not settle a step, the solution is followed
    /// from the last converged solve's data and modes to this step's along the straight line
    /// between them, one mode switch per breakpoint, its end modes confirmed by the passes;
    /// where it does not reach its end (no progress, too many breakpoints or changed rows, a
    /// singular system; a fold or a cycle where path_fold_ends / path_max_pair_switches say so)
    /// or the passes do not confirm it, the Newton methods
    /// follow as without it. 1: on (default; graduated 10 x 400 about 0.9x CPU, identical
    /// 0.76-0.85x, docs/decisions/040); 0: off, the way before.
    int path_following = 1;
    /// Its new base: when more than this many contact rows' equations differ from the base
    /// modes' (the modes whose factorisation the path's sets are low-rank changes of), the
    /// current modes are factorised and become the base (0: never; up to 400 changed rows).
    int path_rebase_rows = 48;
    /// It is not followed (the Newton methods instead) where more than this many conditions of
    /// the start modes fail before its end (its first ratio test's hits: a broad change,
    /// hundreds of breakpoints and columns; docs/decisions/040). 0: no limit.
    int path_max_start_hits = 500;
    /// A solve from rest (p = 0: the first step of a run, where every pair touches at zero
    /// force): the semismooth method hands over to the homotopy from a covering start
    /// (covering_start: its iterate's modes made valid by moving this step's data) once a full
    /// Newton step leaves at most this many components of the natural map above its acceptance
    /// (its tail there: tens of iterations flipping the same pairs), and wherever it fails from
    /// rest; the path's end modes confirmed by the passes. Where the path fails, the semismooth
    /// method goes on from the iterate, then the smoothing method, as before (docs/decisions/
    /// 041: graduated 10 x 400 the first step 1.15 -> 0.4-0.5 CPU s). 0: off, the way before.
    int rest_path_violations = 25;
    /// A solve from rest (p = 0) that is the first of its run (no converged solve before it on
    /// the same structure) and that a Newton method follows: false (default, docs/decisions/
    /// 046) no active-set pass from the rest modes first: from rest the Newton methods start from
    /// p = 0 (the semismooth method from the open modes' solution), so that pass's solution (every
    /// pair closed and sticking, all contact rows held: the run's largest factorisation) was used
    /// only where it settled the step, which no measured run's did (graduated and identical 10 x
    /// 100 to 10 x 400: one solve fewer, the same answers to the last digit). true: the pass, the
    /// way before.
    bool rest_first_pass = false;
    /// Its continuity where a clamp takes friction again (its normal force back below the
    /// preload: free -> carrying friction; docs/decisions/042): true (default) the clamp enters
    /// slip against its tangential motion s_t (its friction force 0 there, continuous) and sticks
    /// only where s_t is at its anchor, as a closing pair does; false: it sticks at once, the way
    /// before (s_t jumps to the anchor: the path is not continuous there, other pairs' modes go
    /// wrong without a breakpoint; graduated 10 x 400, 100 ms: 4 of the 5 runs that fell back to
    /// the Newton methods, 3 ends not confirmed and 1 fold).
    bool path_clamp_slip = true;
    /// Its limit on one pair's mode switches in one run (a cycle, then the Newton methods): 0 none
    /// (default, docs/decisions/042: a pair may open and close again as t advances, graduated 10 x
    /// 400 one run of 82 with 7 switches of one pair; a cycle at one t still ends at the limit of
    /// 20 breakpoints without progress, or as a fold, and every run at 400 breakpoints); 6 the way
    /// before.
    int path_max_pair_switches = 0;
    /// Its end at a fold, a pair switching back to the mode it left at the same t: false
    /// (default, docs/decisions/042) it goes on: where several pairs reach their kinks at one t (a
    /// degenerate vertex) a pair switching back is how the pivots resolve it (graduated 10 x 50 and
    /// 10 x 100, 6 x 50 and 6 x 100, 100 ms: the 3 runs of 263 that ended at a fold settle with it),
    /// and a real fold or cycle at one t ends at the limit of 20 breakpoints without progress; true:
    /// the Newton methods at once, the way before.
    bool path_fold_ends = false;
    /// Its base kept (docs/decisions/045): at the path's end its modes are the base's plus the
    /// changed rows C (at most path_rebase_rows), whose columns it holds; the confirming passes
    /// solve such a set of modes on the base's factorisation and those columns (the bordered,
    /// Woodbury form, refined against the set's own system until its held rows' residual is a
    /// direct solve's; a singular or ill-conditioned bordered system, a refinement that does not
    /// reach that, or more changed rows: a fresh factorisation as before), and so does the next
    /// step's first pass; the next path starts on the same base with its columns. > 0: on where the
    /// stiffness has at least this many unknowns (K's rows, the elastic layer's included), where a
    /// factorisation costs more than the kept base's solves (10,000, the default: graduated 10 x 400
    /// (12,340) 0.89x CPU, identical 0.93x; 10 x 200 and 10 x 100 1.0-1.1x, so off there); 1 always;
    /// 0 off, the way before (the confirming passes factorise the end modes, the next path's base).
    int path_keep_base = 10000;
};

}  // namespace stackbeam
