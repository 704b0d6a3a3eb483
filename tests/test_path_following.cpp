// The parametric (homotopy) active-set transition of the sparse path, behind
// Switches::path_following (lib/contact/sparse/path_following.cpp, docs/decisions/040): it
// follows the solution from the previous step's problem to this step's along the straight
// line between their data, its modes confirmed by the active-set passes. Its answers must be
// the default method's: both are the exact solver's solution of the same problem (the passes
// accept a set of modes only when no mode is violated by more than 1e-3 x tolerance_m), so
// they agree to the solve's round-off, except where the problem has more than one solution
// (then each answer must be one: see below).
#define BOOST_TEST_MODULE path_following
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <vector>

#include "contact/sparse/switches.hpp"
#include "contact/sparse/trace.hpp"
#include "contact/sparse/transitions.hpp"
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

/// Solves `problems` in order with one solver constructed under `sw`, each warm-started
/// from its own previous forces as in a run.
Replay replay(const std::vector<SparseContactProblem>& problems, const SolverOptions& options, const sp::Switches& sw) {
    const sp::ScopedSwitches scoped(sw);
    SparseContactSolver solver(options);
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

}  // namespace

BOOST_AUTO_TEST_CASE(homotopy_transitions_give_the_default_answers) {
    // 60 steps (60 ms): the first steps from rest, the stack's first loading, many transition
    // steps with pairs opening, closing, sticking and slipping.
    // graduated 6-leaf spring (50 elements per half leaf, two 1000 N clamps, mu = 0.5,
    // elastic interfaces with the derived layer, 2 m/s from rest)
    const auto problems = sparse_step_problems(with_elastic_interfaces(graduated_stack(50, 6)), 60);
    const SolverOptions options;
    sp::Switches newton;  // the Newton methods after the pass from the previous modes, without the homotopy
    newton.path_following = 0;
    const Replay def = replay(problems, options, newton);
    sp::TransitionTrace trace;
    sp::Switches sw;  // the default: the homotopy after the pass, then (where it fails) the Newton methods
    sw.trace = &trace;
    const Replay hom = replay(problems, options, sw);
    BOOST_TEST(def.unconverged == 0);
    BOOST_TEST(hom.unconverged == 0);
    int runs = 0, settled = 0, breakpoints = 0;
    for (const auto& t : trace.steps) {
        runs += t.path.end != 0;
        settled += t.path_confirmed;
        breakpoints += t.path.breakpoints;
    }
    // At most steps both methods end with the same modes, and their answers agree to the
    // solve's round-off (direct solves with refinement: ~1e-12 relative measured, bound 1e-9
    // relative to the largest force as the sparse path's replays). The Coulomb problem with
    // the slip coupling need not have one solution, though: where a pair may be open or
    // closed, sticking or slipping with every law satisfied either way, the homotopy takes
    // the solution the path from the previous step reaches and the Newton method another.
    // There each answer must be a solution in its own right: the dense problem's natural
    // map (contact.hpp, in metres) at most the passes' acceptance, 1e-3 x tolerance_m, with
    // a margin of 10 for the round-off of W p + q on the dense W (cond ~1e5); and such steps
    // stay few (measured: 4 of 60 against the default method of decision 037, 2 of 60
    // against the one before; bound 6, a tenth of the steps).
    const double accept_m = 1e-3 * options.tolerance_m;
    double scale = 0.0, diff = 0.0, worst_map = 0.0;
    int worst = -1, other_solution = 0;
    for (std::size_t i = 0; i < def.p.size(); ++i) scale = std::max(scale, def.p[i].lpNorm<Eigen::Infinity>());
    for (std::size_t i = 0; i < def.p.size(); ++i) {
        const double d = (hom.p[i] - def.p[i]).lpNorm<Eigen::Infinity>();
        if (d <= 1e-9 * scale) {
            if (d > diff) {
                diff = d;
                worst = static_cast<int>(i);
            }
            continue;
        }
        ++other_solution;
        const ContactProblem dense = problems[i].to_dense();
        for (const Eigen::VectorXd* p : {&def.p[i], &hom.p[i]}) {
            const Eigen::VectorXd s = dense.W * *p + dense.q;
            worst_map = std::max(worst_map, natural_map(dense, *p, s).lpNorm<Eigen::Infinity>());
        }
    }
    BOOST_TEST_MESSAGE("homotopy: " << runs << " runs, " << settled << " settled, " << breakpoints
                                    << " breakpoints; same solution: max force difference " << diff / scale
                                    << " relative (step " << worst + 1 << "); another solution at " << other_solution
                                    << " steps, natural map of both at most " << worst_map << " m");
    BOOST_TEST(settled > 0);          // the homotopy's breakpoints were used, not only the fallbacks
    BOOST_TEST(breakpoints > settled);
    BOOST_CHECK_SMALL(diff / scale, 1e-9);
    BOOST_TEST(other_solution <= 6);
    BOOST_TEST(worst_map <= 10.0 * accept_m);
}
