// The contact solvers on hand-built problems with known answers (stick, slip,
// open, clamp), the paper iteration's stability bound on alpha, and agreement
// of all solvers on problems recorded from the paper example.
#define BOOST_TEST_MODULE contact_solvers
#include <boost/test/unit_test.hpp>
#include <cmath>

#include "stackbeam/time/closed_form_stepper.hpp"
#include "stackbeam/contact/contact.hpp"
#include "stackbeam/errors.hpp"
#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/time/simulation.hpp"

namespace tt = boost::test_tools;
using namespace stackbeam;

namespace {

// A compliance of two pairs (rows n0, t0, n1, t1) [m/N]: symmetric, diagonally
// dominant, hence positive definite.
Eigen::MatrixXd two_pair_W() {
    Eigen::MatrixXd W(4, 4);
    W << 2.0, 0.3, 0.5, 0.1,
         0.3, 1.5, 0.2, 0.4,
         0.5, 0.2, 2.5, 0.3,
         0.1, 0.4, 0.3, 1.8;
    return 1e-6 * W;
}

// Builds q so that (p_known, s_known) solves the problem: q = s - W p.
ContactProblem problem_with_answer(const Eigen::VectorXd& p, const Eigen::VectorXd& s, std::vector<ContactPair> pairs) {
    ContactProblem pr;
    pr.W = two_pair_W();
    pr.q = s - pr.W * p;
    pr.pairs = std::move(pairs);
    return pr;
}

ContactPair coulomb(int rn, int rt, double mu) { return {PairKind::coulomb, mu, 0.0, rn, rt}; }

SolverOptions tight(SolverKind kind) {
    SolverOptions o;
    o.kind = kind;
    o.tolerance_m = 1e-13;
    o.max_iterations = 1000000;
    return o;
}

const SolverKind kAll[] = {SolverKind::paper, SolverKind::block_jacobi, SolverKind::accelerated, SolverKind::exact};

// Forces from a solve with ||v|| < 1e-13 m: the force error is at most
// ||W^-1|| * 1e-13 m ~ 1e6 N/m * 1e-13 m = 1e-7 N, so 1e-5 N absolute is safe.
constexpr double kForceTol = 1e-5;

}  // namespace

BOOST_AUTO_TEST_CASE(one_pair_sticks_one_pair_slips) {
    // Pair 0 sticks: p = (-10, 3) N, |3| < 0.5*10. Pair 1 slips: p = (-8, -4) N at the
    // limit 0.5*8, sliding in +t (s_t = +2 um) against its force (eq. 8: s_t = -beta p_t).
    Eigen::VectorXd p(4), s(4);
    p << -10, 3, -8, -4;
    s << 0, 0, 0, 2e-6;
    const ContactProblem pr = problem_with_answer(p, s, {coulomb(0, 1, 0.5), coulomb(2, 3, 0.5)});
    for (SolverKind k : kAll) {
        BOOST_TEST_CONTEXT("solver " << to_string(k)) {
            Eigen::VectorXd x = Eigen::VectorXd::Zero(4);
            const SolveResult r = make_solver(tight(k))->solve(pr, x);
            BOOST_TEST(r.converged);
            BOOST_TEST(r.residual_m < 1e-13);
            // the solver-independent natural map agrees: its entries are W_kk-scaled
            // force or gap errors, of the order of v's at these forces (x 10 margin)
            BOOST_TEST(r.natural_residual_m < 1e-12);
            for (int i = 0; i < 4; ++i) BOOST_CHECK_SMALL(x[i] - p[i], kForceTol);
            BOOST_TEST(to_string(pair_state(pr, 0, x)) == std::string("stick"));
            BOOST_TEST(to_string(pair_state(pr, 1, x)) == std::string("slip"));
        }
    }
}

BOOST_AUTO_TEST_CASE(open_pair_and_clamp_pair) {
    // Pair 0 is open: p = 0 with a 1 um gap (s_n = -1 um). Pair 1 is a clamp with
    // preload 50 N pulled apart by a reaction of 20 N (p_n = +20 N, allowed: bilateral),
    // so its friction limit is 0.4 * (50 - 20) = 12 N, reached: p_t = +12 N, slipping in -t.
    Eigen::VectorXd p(4), s(4);
    p << 0, 0, 20, 12;
    s << -1e-6, 3e-7, 0, -5e-7;
    const ContactProblem pr =
        problem_with_answer(p, s, {coulomb(0, 1, 0.3), ContactPair{PairKind::clamp, 0.4, 50.0, 2, 3}});
    for (SolverKind k : kAll) {
        BOOST_TEST_CONTEXT("solver " << to_string(k)) {
            Eigen::VectorXd x = Eigen::VectorXd::Zero(4);
            const SolveResult r = make_solver(tight(k))->solve(pr, x);
            BOOST_TEST(r.converged);
            for (int i = 0; i < 4; ++i) BOOST_CHECK_SMALL(x[i] - p[i], kForceTol);
            BOOST_TEST(to_string(pair_state(pr, 0, x)) == std::string("open"));
            BOOST_TEST(to_string(pair_state(pr, 1, x)) == std::string("slip"));
        }
    }
}

BOOST_AUTO_TEST_CASE(error_vector_is_zero_exactly_at_a_solution) {
    // eq. 10: v = 0 at a solution; a force off the solution gives v != 0.
    Eigen::VectorXd p(4), s(4);
    p << -10, 3, -8, -4;
    s << 0, 0, 0, 2e-6;
    const ContactProblem pr = problem_with_answer(p, s, {coulomb(0, 1, 0.5), coulomb(2, 3, 0.5)});
    BOOST_CHECK_SMALL(error_vector(pr, p, pr.W * p + pr.q).norm(), 1e-18);
    Eigen::VectorXd q = p;
    q[1] = 2.0;  // pair 0 still sticks but now s_t != 0
    BOOST_TEST(error_vector(pr, q, pr.W * q + pr.q).norm() > 1e-7);
}

BOOST_AUTO_TEST_CASE(natural_map_sees_inadmissible_forces_that_v_does_not) {
    // A tensile force in an open pair: eq. 9 gives v_n = 0 (p_n >= 0 and s_n <= 0), the
    // natural map gives W_nn p_n. A friction force above the limit: v_t = 0 if it
    // opposes the slip, the natural map gives W_tt (|p_t| - limit).
    Eigen::VectorXd p(4), s(4);
    p << 0, 0, -8, -4;
    s << -1e-6, 0, 0, 2e-6;
    const ContactProblem pr = problem_with_answer(p, s, {coulomb(0, 1, 0.5), coulomb(2, 3, 0.5)});
    BOOST_CHECK_SMALL(natural_map(pr, p, pr.W * p + pr.q).norm(), 1e-18);
    Eigen::VectorXd bad = p;
    bad[0] = 0.1;  // tension in the open pair 0 (s_n stays negative: 0.1 N * 2e-6 m/N < 1e-6 m)
    const Eigen::VectorXd sb = pr.W * bad + pr.q;
    BOOST_TEST(sb[0] < 0.0);
    BOOST_CHECK_SMALL(error_vector(pr, bad, sb)[0], 1e-18);
    BOOST_TEST(natural_map(pr, bad, sb)[0] == pr.W(0, 0) * 0.1, tt::tolerance(1e-9));
}

BOOST_AUTO_TEST_CASE(paper_iteration_converges_below_two_over_lambda_max_and_not_above) {
    // For bonded pairs eq. 17 is Richardson's iteration p <- p - alpha (W p + q): it
    // converges iff alpha < 2 / lambda_max(W). At 0.95 of the bound it converges; at
    // 1.05 the error grows along the top eigenvector and the solver must say so.
    Eigen::VectorXd p(4), s = Eigen::VectorXd::Zero(4);
    p << -10, 3, -8, -4;
    const ContactPair bond{PairKind::bonded, 0.0, 0.0, 0, 1};
    const ContactPair bond2{PairKind::bonded, 0.0, 0.0, 2, 3};
    const ContactProblem pr = problem_with_answer(p, s, {bond, bond2});
    const double bound = 2.0 / largest_eigenvalue(pr.W);
    SolverOptions o = tight(SolverKind::paper);
    o.max_iterations = 20000;
    o.alpha = 0.95 * bound;
    Eigen::VectorXd x = Eigen::VectorXd::Zero(4);
    SolveResult r = make_solver(o)->solve(pr, x);
    BOOST_TEST(r.converged);
    for (int i = 0; i < 4; ++i) BOOST_CHECK_SMALL(x[i] - p[i], kForceTol);

    o.alpha = 1.05 * bound;
    x.setZero();
    r = make_solver(o)->solve(pr, x);
    BOOST_TEST(!r.converged);
    BOOST_TEST(r.message.find("did not reach") != std::string::npos);
    BOOST_TEST(r.residual_m > 1e-6);

    // The same holds with friction, where eq. 17 projects: 0.9 of the bound converges.
    Eigen::VectorXd sf(4);
    sf << 0, 0, 0, 2e-6;
    const ContactProblem pf = problem_with_answer(p, sf, {coulomb(0, 1, 0.5), coulomb(2, 3, 0.5)});
    o.alpha = 0.9 * 2.0 / largest_eigenvalue(pf.W);
    x.setZero();
    BOOST_TEST(make_solver(o)->solve(pf, x).converged);
}

BOOST_AUTO_TEST_CASE(iteration_limit_is_reported_not_hidden) {
    Eigen::VectorXd p(4), s(4);
    p << -10, 3, -8, -4;
    s << 0, 0, 0, 2e-6;
    const ContactProblem pr = problem_with_answer(p, s, {coulomb(0, 1, 0.5), coulomb(2, 3, 0.5)});
    SolverOptions o = tight(SolverKind::paper);
    o.max_iterations = 3;
    Eigen::VectorXd x = Eigen::VectorXd::Zero(4);
    const SolveResult r = make_solver(o)->solve(pr, x);
    BOOST_TEST(!r.converged);
    BOOST_TEST(r.iterations == 3);
    BOOST_TEST(!r.message.empty());
}

BOOST_AUTO_TEST_CASE(bad_problems_and_options_are_rejected_by_name) {
    ContactProblem pr;
    pr.W = two_pair_W();
    pr.q = Eigen::VectorXd::Zero(3);
    pr.pairs = {coulomb(0, 1, 0.5)};
    Eigen::VectorXd x;
    auto field_of = [&](const ContactProblem& bad) {
        try {
            make_solver(SolverOptions{})->solve(bad, x);
        } catch (const InputError& e) {
            return e.field();
        }
        return std::string("none");
    };
    BOOST_TEST(field_of(pr) == "problem.W");
    pr.q = Eigen::VectorXd::Zero(4);
    BOOST_TEST(field_of(pr) == "problem.pairs");  // rows 2, 3 belong to no pair
    pr.pairs = {coulomb(0, 1, -0.1), coulomb(2, 3, 0.5)};
    BOOST_TEST(field_of(pr) == "problem.pairs[0].friction_coefficient");
    SolverOptions o;
    o.tolerance_m = 0.0;
    BOOST_CHECK_THROW(make_solver(o), InputError);
    BOOST_CHECK_THROW(parse_solver_kind("lemke", "--solver"), InputError);
}

BOOST_AUTO_TEST_CASE(solvers_agree_on_recorded_steps_of_the_paper_example) {
    // Replay problems recorded along the friction and bonded cases (including
    // stick-slip reversals) with every solver at 1e-11 m; answers must agree to the
    // force error this tolerance allows, ||W^-1|| * 1e-11 m (||W^-1|| ~ 1/lambda_min).
    for (PaperCase c : {PaperCase::friction, PaperCase::bonded}) {
        const System sys(Model::build(paper_example(c)));
        SimulationOptions so;
        so.solver.tolerance_m = 1e-11;
        ClosedFormStepper st(sys, so);
        const int record_at[] = {1, 2, 45, 90, 180};
        int k = 0;
        for (int step = 1; step <= 180; ++step) {
            const Eigen::VectorXd p_start = st.contact_forces();
            st.advance();
            if (step != record_at[k]) continue;
            ++k;
            const ContactProblem pr = st.contact_solver().last_dense_problem();
            Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(pr.W);
            const double force_tol = 1e-11 / es.eigenvalues().minCoeff();
            for (SolverKind kind : {SolverKind::block_jacobi, SolverKind::accelerated, SolverKind::exact}) {
                // Block-Jacobi moves every pair at once and stalls near 1e-6 m on the first
                // friction steps (many pairs open and close together): bonded steps only.
                if (kind == SolverKind::block_jacobi && c == PaperCase::friction) continue;
                BOOST_TEST_CONTEXT(to_string(c) << " step " << step << " solver " << to_string(kind)) {
                    SolverOptions o = tight(kind);
                    o.tolerance_m = 1e-11;
                    Eigen::VectorXd x = p_start;
                    const SolveResult r = make_solver(o)->solve(pr, x);
                    BOOST_TEST(r.converged);
                    BOOST_TEST(r.natural_residual_m < 1e-9);  // contact laws hold (eq. 8/10) to ~1e-11 m x sqrt(n) x margin
                    BOOST_TEST((x - st.contact_forces()).lpNorm<Eigen::Infinity>() < 2.0 * force_tol);
                }
            }
        }
    }
}
