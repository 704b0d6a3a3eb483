// The parametric (homotopy) active-set transition of the sparse path, behind
// SparsePathMethods::path_following (lib/contact/sparse/transitions/path_following.cpp, docs/decisions/040): it
// follows the solution from the previous step's problem to this step's along the straight
// line between their data, its modes confirmed by the active-set passes. Its answers must be
// the default method's: both are the exact solver's solution of the same problem (the passes
// accept a set of modes only when no mode is violated by more than 1e-3 x tolerance_m), so
// they agree to the solve's round-off, except where the problem has more than one solution
// (then each answer must be one: see below). Decision 042's repairs (a clamp taking friction
// again slips first, no per-pair switch limit, folds at degenerate vertices pivot on) must
// settle the runs that fell back before them, with answers of the same standard.
#define BOOST_TEST_MODULE path_following
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <vector>

#include "contact/sparse/driver/switches.hpp"
#include "contact/sparse/driver/trace.hpp"
#include "contact/sparse/transitions/transitions.hpp"
#include "test_support.hpp"

using namespace stackbeam;
namespace sp = stackbeam::detail::sparse;
using stackbeam::testing::graduated_stack;
using stackbeam::testing::sparse_step_problems;
using stackbeam::testing::with_elastic_interfaces;

namespace {

struct Replay {
    std::vector<Eigen::VectorXd> p;
    Eigen::VectorXd diag;  // W's diagonal [m/N]
    int unconverged = 0;
};

/// Solves `problems` in order with one solver constructed with the methods `sw` (and the
/// observer `trace`, if any), each warm-started from its own previous forces as in a run.
Replay replay(const std::vector<SparseContactProblem>& problems, const SolverOptions& options,
              const SparsePathMethods& sw, SparsePathObserver* trace = nullptr) {
    SparsePathTuning tuning;
    tuning.methods = sw;
    tuning.observer = trace;
    SparseContactSolver solver(options, tuning);
    Replay out;
    Eigen::VectorXd p = Eigen::VectorXd::Zero(problems.front().size()), z;
    for (const auto& pr : problems) {
        const SolveResult r = solver.solve(pr, p, z);
        out.unconverged += r.converged ? 0 : 1;
        out.p.push_back(p);
    }
    out.diag = solver.compliance_diagonal();
    return out;
}

/// The homotopy's runs in a trace: how many, how many settled (their end confirmed by the
/// passes), their breakpoints.
struct PathRuns {
    int runs = 0, settled = 0, breakpoints = 0;
    explicit PathRuns(const sp::TransitionTrace& trace) {
        for (const auto& t : trace.steps) {
            runs += t.path.end != 0;
            settled += t.path_confirmed;
            breakpoints += t.path.breakpoints;
        }
    }
};

/// Two replays of the same problems, step by step: the largest force difference where they
/// took the same solution (relative to the largest force), the steps where they took another,
/// and the dense problem's natural map of both answers at those steps.
///
/// At most steps both methods end with the same modes, and their answers agree to the
/// solve's round-off (direct solves with refinement: ~1e-12 relative measured, bound 1e-9
/// relative to the largest force as the sparse path's replays). The Coulomb problem with
/// the slip coupling need not have one solution, though: where a pair may be open or
/// closed, sticking or slipping with every law satisfied either way, the homotopy takes
/// the solution the path from the previous step reaches and the Newton method another.
/// There each answer must be a solution in its own right: the dense problem's natural
/// map (contact.hpp, in metres) at most the passes' acceptance, 1e-3 x tolerance_m, with
/// a margin of 10 for the round-off of W p + q on the dense W (cond ~1e5).
struct Agreement {
    double diff = 0.0, worst_map = 0.0;
    int worst = -1, other_solution = 0;
    Agreement(const std::vector<SparseContactProblem>& problems, const Replay& a, const Replay& b) {
        double scale = 0.0;
        for (const auto& p : a.p) scale = std::max(scale, p.lpNorm<Eigen::Infinity>());
        for (std::size_t i = 0; i < a.p.size(); ++i) {
            const double d = (b.p[i] - a.p[i]).lpNorm<Eigen::Infinity>() / scale;
            if (d <= 1e-9) {
                if (d > diff) {
                    diff = d;
                    worst = static_cast<int>(i);
                }
                continue;
            }
            ++other_solution;
            const ContactProblem dense = problems[i].to_dense();
            for (const Eigen::VectorXd* p : {&a.p[i], &b.p[i]}) {
                const Eigen::VectorXd s = dense.W * *p + dense.q;
                worst_map = std::max(worst_map, natural_map(dense, *p, s).lpNorm<Eigen::Infinity>());
            }
        }
    }
};

/// The switches of the homotopy before decision 042's repairs.
SparsePathMethods before_042() {
    SparsePathMethods sw;
    sw.path_clamp_slip = false;
    sw.path_max_pair_switches = 6;
    sw.path_fold_ends = true;
    return sw;
}

}  // namespace

BOOST_AUTO_TEST_CASE(homotopy_transitions_give_the_default_answers) {
    // 60 steps (60 ms): the first steps from rest, the stack's first loading, many transition
    // steps with pairs opening, closing, sticking and slipping.
    // graduated 6-leaf spring (50 elements per half leaf, two 1000 N clamps, mu = 0.5,
    // elastic interfaces with the derived layer, 2 m/s from rest)
    const auto problems = sparse_step_problems(with_elastic_interfaces(graduated_stack(50, 6)), 60);
    const SolverOptions options;
    SparsePathMethods newton;  // the Newton methods after the pass from the previous modes, without the homotopy
    newton.path_following = 0;
    const Replay def = replay(problems, options, newton);
    sp::TransitionTrace trace;
    SparsePathMethods sw;  // the default: the homotopy after the pass, then (where it fails) the Newton methods
    const Replay hom = replay(problems, options, sw, &trace);
    BOOST_TEST(def.unconverged == 0);
    BOOST_TEST(hom.unconverged == 0);
    const PathRuns path(trace);
    // another solution at few steps (measured: 4 of 60 against the default method of decision
    // 037, 2 of 60 against the one before; bound 6, a tenth of the steps): Agreement above
    const double accept_m = 1e-3 * options.tolerance_m;
    const Agreement ag(problems, def, hom);
    BOOST_TEST_MESSAGE("homotopy: " << path.runs << " runs, " << path.settled << " settled, " << path.breakpoints
                                    << " breakpoints; same solution: max force difference " << ag.diff
                                    << " relative (step " << ag.worst + 1 << "); another solution at "
                                    << ag.other_solution << " steps, natural map of both at most " << ag.worst_map << " m");
    BOOST_TEST(path.settled > 0);  // the homotopy's breakpoints were used, not only the fallbacks
    BOOST_TEST(path.breakpoints > path.settled);
    BOOST_CHECK_SMALL(ag.diff, 1e-9);
    BOOST_TEST(ag.other_solution <= 6);
    BOOST_TEST(ag.worst_map <= 10.0 * accept_m);
}

BOOST_AUTO_TEST_CASE(repaired_homotopy_settles_where_it_fell_back) {
    // Decision 042's repairs of the homotopy (SparsePathMethods::path_clamp_slip, path_max_pair_switches,
    // path_fold_ends), on two problem sequences where the homotopy of decision 040 fell back to
    // the Newton methods (measured: graduated 10 x 50, 100 steps: 5 of 62 runs, 4 ends not
    // confirmed after a clamp stuck at once on taking friction again, 1 pair switching 7 times;
    // graduated 6 x 50, 100 steps: 1 of 61, a fold at a degenerate vertex of three pairs).
    // With them every run settles, and the answers are the exact solver's: the same as the
    // Newton methods' (path_following 0) to round-off, or (few steps) another solution, each
    // one by the natural map (Agreement).
    const SolverOptions options;
    const double accept_m = 1e-3 * options.tolerance_m;
    for (const int leaves : {10, 6}) {
        const auto problems = sparse_step_problems(with_elastic_interfaces(graduated_stack(50, leaves)), 100);
        SparsePathMethods newton;
        newton.path_following = 0;
        const Replay def = replay(problems, options, newton);
        sp::TransitionTrace before_trace, trace;
        SparsePathMethods before = before_042(), sw;
        const Replay old = replay(problems, options, before, &before_trace);
        const Replay hom = replay(problems, options, sw, &trace);
        const PathRuns path_before(before_trace), path(trace);
        const Agreement ag(problems, def, hom), ag_before(problems, def, old);
        BOOST_TEST_MESSAGE(leaves << " leaves: before 042 " << path_before.settled << " of " << path_before.runs
                                  << " runs settled (another solution than the Newton methods' at "
                                  << ag_before.other_solution << " steps); with the repairs " << path.settled << " of "
                                  << path.runs << " (" << path.breakpoints
                                  << " breakpoints); same solution as the Newton methods: max force difference "
                                  << ag.diff << " relative; another solution at " << ag.other_solution
                                  << " steps, natural map of both at most " << ag.worst_map << " m");
        BOOST_TEST(def.unconverged == 0);
        BOOST_TEST(old.unconverged == 0);
        BOOST_TEST(hom.unconverged == 0);
        BOOST_TEST(path_before.settled < path_before.runs);  // the sequences do exercise the repairs
        BOOST_TEST(path.runs > 50);
        BOOST_TEST(path.settled == path.runs);
        BOOST_CHECK_SMALL(ag.diff, 1e-9);
        // the homotopy keeps to the branch the previous step's answer is on, so another solution
        // than the Newton methods' lasts for a few steps once taken (measured on 10 leaves: 19 of
        // 100 steps before 042, 22 with the repairs; on 6 leaves 10 and 10): bound a quarter of
        // the steps; each is a solution by the natural map
        BOOST_TEST(ag.other_solution <= 25);
        BOOST_TEST(ag.worst_map <= 10.0 * accept_m);
    }
}

BOOST_AUTO_TEST_CASE(kept_base_solves_are_the_from_scratch_solves) {
    // Decision 045 (SparsePathMethods::path_keep_base): the confirming passes of the homotopy's end modes
    // and the next step's first pass solve a set of modes near the path's base on the base's
    // factorisation and its columns (the bordered form, refined against the set's own system)
    // instead of factorising it. Over a run's real steps (graduated 6 x 50, 60 steps), every such
    // solve is checked against the same modes solved from scratch by a mode solver of its own
    // (TransitionTrace::check_kept: Eigen's SparseLU of the whole saddle-point system, refined).
    // Both are backward-stable solves of the same linear system, the kept one refined until its held
    // rows' residual is at a direct solve's (1e-16 of s's terms), so they differ by round-off times the
    // system's conditioning, as two direct solvers do: the trace also solves each set by KLU (the
    // default route's) and measures KLU against Eigen. Bound: 1e-10 relative to the largest force and
    // displacement, or 10 x the two direct solvers' difference where that is larger (measured on this
    // run below; on the graduated 10 x 400 run the direct solvers differ by up to 2e-7 and the kept
    // solves by up to 1.2e-6 from Eigen's: h^-4 conditioning, decision 045). The run's answers must be
    // the Newton methods' as for the homotopy without it (Agreement), and the kept base must be used.
    const auto problems = sparse_step_problems(with_elastic_interfaces(graduated_stack(50, 6)), 60);
    const SolverOptions options;
    SparsePathMethods newton;
    newton.path_following = 0;
    const Replay def = replay(problems, options, newton);
    sp::TransitionTrace trace;
    trace.check_kept = true;
    SparsePathMethods sw;
    sw.path_keep_base = 1;  // (the default keeps it from 10,000 unknowns on: this stack has fewer)
    const Replay kept = replay(problems, options, sw, &trace);
    SparsePathMethods off;
    off.path_keep_base = 0;
    const Replay before = replay(problems, options, off);
    const Agreement ag(problems, def, kept), ag_off(problems, before, kept);
    int kept_runs = 0;
    for (const auto& t : trace.steps) kept_runs += t.path.kept_base ? 1 : 0;
    BOOST_TEST_MESSAGE("kept base: " << trace.kept_checked << " solves on it, " << kept_runs
                                     << " path runs started on it; against from scratch: p " << trace.kept_p_diff
                                     << ", z " << trace.kept_z_diff << " relative (KLU against Eigen: p "
                                     << trace.fresh_p_diff << ", z " << trace.fresh_z_diff << "); against the Newton methods: max force difference " << ag.diff
                                     << ", another solution at " << ag.other_solution
                                     << " steps; against path_keep_base off: " << ag_off.diff << ", another solution at "
                                     << ag_off.other_solution << " steps");
    BOOST_TEST(kept.unconverged == 0);
    BOOST_TEST(trace.kept_checked > 20);
    BOOST_TEST(kept_runs > 10);
    BOOST_CHECK_SMALL(trace.kept_p_diff, std::max(1e-10, 10.0 * trace.fresh_p_diff));
    BOOST_CHECK_SMALL(trace.kept_z_diff, std::max(1e-10, 10.0 * trace.fresh_z_diff));
    BOOST_CHECK_SMALL(ag.diff, 1e-9);
    BOOST_TEST(ag.other_solution <= 6);  // as the homotopy without it (the first test)
    BOOST_TEST(ag.worst_map <= 10.0 * 1e-3 * options.tolerance_m);
}
