// The sparse path's step from rest by the homotopy from a covering start
// (SparsePathMethods::rest_path_violations, lib/contact/sparse/transitions/covering_start.cpp and
// SparseContactSolver::Impl::rest_transition; docs/decisions/041): the semismooth Newton method
// from rest hands its iterate over once few laws are violated; that iterate's modes M0 are made
// valid by moving the step's data (b, d) -> (b0, d0), and path_following takes the solution from
// (b0, d0) to (b, d); its end modes are confirmed by the active-set passes.
#define BOOST_TEST_MODULE rest_path
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <random>
#include <vector>

#include "contact/sparse/driver/common.hpp"
#include "contact/sparse/driver/switches.hpp"
#include "contact/sparse/driver/trace.hpp"
#include "contact/sparse/transitions/transitions.hpp"
#include "test_support.hpp"

using namespace stackbeam;
namespace sp = stackbeam::detail::sparse;
using stackbeam::testing::graduated_stack;
using stackbeam::testing::sparse_step_problems;
using stackbeam::testing::with_elastic_interfaces;

BOOST_AUTO_TEST_CASE(covering_start_makes_any_modes_a_solution_of_the_moved_data) {
    // The construction's claim, checked on the solver's own linear algebra: for a set of modes
    // M0 (here random: closed / open, stick / slip +- / free, on every pair of a graduated 6 x 50
    // elastic spring's first step) and M0's linear solution at the step's data, M0 solved again
    // at (b0, d0) violates none of its laws (the passes' test, threshold kAccept x tolerance_m or
    // the round-off of s): the path's start is valid. Its forces and gaps are the projections of
    // the first solution's, so the held rows' gaps and the zero-force rows' forces are unchanged
    // (to the solves' round-off, ~1e-12 relative; bound 1e-9 relative).
    const auto problems = sparse_step_problems(with_elastic_interfaces(graduated_stack(50, 6)), 1);
    SparseContactProblem layered = problems.front();
    BOOST_REQUIRE(sp::layer_structure(problems.front(), layered));
    layered.b.head(problems.front().b.size()) = problems.front().b;
    layered.d = problems.front().d;
    layered.pairs = problems.front().pairs;
    const SolverOptions options;
    sp::SparsePath path(options, sp::ModeSolverTuning{}, SparsePathMethods{});
    path.reset(layered);
    const int np = static_cast<int>(layered.pairs.size());
    const int m = layered.size();
    const sp::Step step{layered.b, layered.d};
    std::mt19937 rng(41);
    int trials = 0, moved = 0;
    for (int trial = 0; trial < 8; ++trial) {
        path.modes.nmode.assign(np, modes::NONE);
        path.modes.tmode.assign(np, modes::NONE);
        for (int k = 0; k < np; ++k) {
            const auto& c = layered.pairs[k];
            if (c.row_n >= 0) path.modes.nmode[k] = !modes::ModeSet::unilateral(c) || rng() % 2 ? modes::CLOSED : modes::OPEN;
            if (c.row_t >= 0) {
                const unsigned pick = rng() % 4;
                path.modes.tmode[k] = c.kind == PairKind::bonded ? modes::STICK
                                      : pick == 0                ? modes::SLIP_POS
                                      : pick == 1                ? modes::SLIP_NEG
                                      : pick == 2 && c.kind == PairKind::clamp ? modes::FREE
                                                                               : modes::STICK;
            }
            path.modes.make_consistent(path.laws, k);
        }
        const modes::ModeSet m0 = path.modes;
        Eigen::VectorXd p = Eigen::VectorXd::Zero(m), z;
        try {
            path.solve_modes(step, p, z);
        } catch (const sp::SingularModes&) {
            continue;  // dependent held rows in this draw
        }
        const Eigen::VectorXd s = path.stiffness().Grow * z - step.d;
        moved += path.count_violations(step.d, p, z) > 0;
        Eigen::VectorXd b0, d0;
        sp::covering_start(path, step, p, z, b0, d0);
        const sp::Step start{b0, d0};
        Eigen::VectorXd p0 = p, z0;
        path.solve_modes(start, p0, z0);
        BOOST_TEST((path.modes.nmode == m0.nmode && path.modes.tmode == m0.tmode));
        BOOST_TEST(path.count_violations(d0, p0, z0) == 0);
        const Eigen::VectorXd s0 = path.stiffness().Grow * z0 - d0;
        const double pscale = std::max(1.0, p.lpNorm<Eigen::Infinity>());
        const double sscale = std::max(1e-9, s.lpNorm<Eigen::Infinity>());
        modes::ModeLinearization lin;
        m0.linearize(path.laws, lin);
        std::vector<char> held(m, 0);
        for (const int r : lin.S) held[r] = 1;
        for (int r = 0; r < m; ++r) {
            if (held[r]) BOOST_CHECK_SMALL(s0[r] - s[r], 1e-9 * sscale);
            else if (lin.e[r] == 0.0 && p[r] == 0.0) BOOST_CHECK_SMALL(p0[r], 1e-9 * pscale);
        }
        ++trials;
    }
    BOOST_TEST(trials >= 6);
    BOOST_TEST(moved == trials);  // random modes violate laws at the step's data: the start moved
}

BOOST_AUTO_TEST_CASE(a_step_from_rest_gives_the_answer_of_the_way_before) {
    // The first step of a graduated 10 x 100 elastic spring (2 m/s from rest): the step whose
    // semismooth method ran its 60 iterations and the smoothing method's before (docs/decisions/
    // 041). With the homotopy from rest the semismooth method hands over (end 5) and the path
    // settles it; both ways end with the passes' confirmation, so each answer is the exact
    // solver's. They agree to the solve's round-off (bound 1e-9 of the largest force, as
    // test_path_following) where they end with the same modes; where the problem has two
    // solutions (pairs at zero force and zero gap, decision 040) each must be one: the dense
    // problem's natural map at most 10 x the passes' acceptance (the round-off of W p + q on the
    // dense W, as test_path_following).
    const auto problems = sparse_step_problems(with_elastic_interfaces(graduated_stack(100, 10)), 1);
    const SparseContactProblem& pr = problems.front();
    const SolverOptions options;
    auto solve = [&](int violations, sp::TransitionTrace* trace, SolveResult& r) {
        SparsePathTuning tuning;
        tuning.methods.rest_path_violations = violations;
        tuning.observer = trace;
        SparseContactSolver solver(options, tuning);
        Eigen::VectorXd p = Eigen::VectorXd::Zero(pr.size()), z;
        r = solver.solve(pr, p, z);
        return p;
    };
    SolveResult before, after;
    const Eigen::VectorXd p_before = solve(0, nullptr, before);
    sp::TransitionTrace trace;
    const Eigen::VectorXd p_after = solve(SparsePathMethods{}.rest_path_violations, &trace, after);
    BOOST_TEST(before.converged);
    BOOST_TEST(after.converged);
    BOOST_REQUIRE(trace.steps.size() == 1u);
    const sp::StepTrace& t = trace.steps.front();
    BOOST_TEST(t.newton_end == 5);  // handed over
    BOOST_TEST(t.path.end == sp::PathStats::reached);
    BOOST_TEST(t.path_confirmed);
    BOOST_TEST(t.path.breakpoints > 0);
    BOOST_TEST(after.smoothing_iterations == 0);
    BOOST_TEST(before.smoothing_iterations > 0);  // the way before needed the smoothing method here
    BOOST_TEST_MESSAGE("from rest: semismooth " << after.newton_iterations << " iterations, then the path: "
                                                << t.path.start_hits << " start hits, " << t.path.breakpoints
                                                << " breakpoints; the way before " << before.newton_iterations
                                                << " + " << before.smoothing_iterations << " smoothing iterations");
    const double scale = p_before.lpNorm<Eigen::Infinity>();
    const double diff = (p_after - p_before).lpNorm<Eigen::Infinity>();
    BOOST_TEST_MESSAGE("force difference " << diff / scale << " relative");
    if (diff > 1e-9 * scale) {
        const ContactProblem dense = pr.to_dense();
        for (const Eigen::VectorXd* p : {&p_before, &p_after}) {
            const Eigen::VectorXd s = dense.W * *p + dense.q;
            BOOST_CHECK_SMALL(natural_map(dense, *p, s).lpNorm<Eigen::Infinity>(), 10.0 * sp::kAccept * options.tolerance_m);
        }
    }
}

BOOST_AUTO_TEST_CASE(the_first_solve_from_rest_takes_no_pass_from_the_rest_modes) {
    // SparsePathMethods::rest_first_pass (docs/decisions/046): the run's first solve from rest goes to the
    // Newton methods without the active-set pass from the rest modes (every pair closed and
    // sticking, every contact row held: the run's largest factorisation), whose solution no
    // Newton method starts from (from rest the semismooth method starts from the open modes'
    // solution). On the first step of a graduated 10 x 100 elastic spring: the same answer as
    // with the pass, one mode-set solve fewer, both confirmed by the passes (converged: every law
    // within the passes' acceptance). The same sequence of mode sets is solved either way, by
    // factorisations of those sets alone (the skipped pass's factorisation is reused by no later
    // set), so the answers agree to the solves' round-off: bound 1e-12 of the largest force
    // (measured: equal to the last digit, as the graduated and identical 10 x 100 to 10 x 400
    // runs' answer lines). A later solve from p = 0 on the same solver (a converged solve
    // before it) still takes the pass.
    const auto problems = sparse_step_problems(with_elastic_interfaces(graduated_stack(100, 10)), 1);
    const SparseContactProblem& pr = problems.front();
    const SolverOptions options;
    auto solve = [&](bool first_pass, sp::TransitionTrace& trace, SolveResult& r, SolveResult* again) {
        SparsePathTuning tuning;
        tuning.methods.rest_first_pass = first_pass;
        tuning.observer = &trace;
        SparseContactSolver solver(options, tuning);
        Eigen::VectorXd p = Eigen::VectorXd::Zero(pr.size()), z;
        r = solver.solve(pr, p, z);
        if (again) {
            Eigen::VectorXd p2 = Eigen::VectorXd::Zero(pr.size()), z2;
            *again = solver.solve(pr, p2, z2);
        }
        return p;
    };
    sp::TransitionTrace with_trace, without_trace;
    SolveResult with, without, again;
    const Eigen::VectorXd p_with = solve(true, with_trace, with, nullptr);
    const Eigen::VectorXd p_without = solve(false, without_trace, without, &again);
    BOOST_TEST(with.converged);
    BOOST_TEST(without.converged);
    BOOST_TEST(again.converged);
    BOOST_REQUIRE(with_trace.steps.size() == 1u);
    BOOST_REQUIRE(without_trace.steps.size() == 2u);
    BOOST_TEST(with_trace.steps[0].pass_solves == 1);
    BOOST_TEST(without_trace.steps[0].pass_solves == 0);
    BOOST_TEST(without_trace.steps[1].pass_solves >= 1);  // not the run's first solve: the pass
    BOOST_TEST(with.iterations - without.iterations == 1);
    BOOST_TEST(with.factorizations - without.factorizations == 1);
    BOOST_TEST(with.newton_iterations == without.newton_iterations);
    BOOST_TEST(without_trace.steps[0].newton_end == with_trace.steps[0].newton_end);
    const double scale = p_with.lpNorm<Eigen::Infinity>();
    BOOST_TEST(scale > 0.0);
    BOOST_CHECK_SMALL((p_without - p_with).lpNorm<Eigen::Infinity>(), 1e-12 * scale);
}
