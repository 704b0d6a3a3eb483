// Units of the sparse contact path (lib/contact/sparse/), each alone on small problems
// against an independent dense computation:
//  - the selected inverse: diag(G K^-1 G^T) formed densely;
//  - the mode solver: a dense solve of the same linear problem of a set of modes, by its
//    three ways (sparse LU, Schur complement, bordered update);
//  - the box-QP methods: against each other, the dense primal method (box_qp.hpp) and the
//    QP's optimality conditions checked on the dense W, q;
//  - the transition methods: each from the previous step's answer, against the dense exact
//    solver's answer of the step.
// The problems: a hand-made K and G, and the paper's friction example (76 contact rows)
// recorded from a sparse run.
#define BOOST_TEST_MODULE sparse_units
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "contact/box_qp.hpp"
#include "contact/sparse/qp/box_qp_methods.hpp"
#include "contact/sparse/linear/selected_inverse.hpp"
#include "contact/sparse/driver/trace.hpp"
#include "contact/sparse/transitions/transitions.hpp"
#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/time/closed_form_stepper.hpp"
#include "stackbeam/time/simulation.hpp"

using namespace stackbeam;
namespace sp = stackbeam::detail::sparse;

namespace {

constexpr double kTol = 2e-6;  // the paper's tolerance on ||v|| [m]
// Both sides of every comparison below solve the same linear system (a set of modes or a
// working set), one densely (LU of W_SS, cond(W) ~ 1e5 on the paper example) and one on
// the sparse stiffness (scaled, refined), so they differ by round-off amplified by
// cond(W): ~1e-16 x 1e5 = 1e-11 relative. 1e-9 keeps a margin of 100 and still catches a
// different mode or working set (>= 1e-6 on these problems, test_sparse_path).
constexpr double kRel = 1e-9;

/// `steps` sparse problems of the paper's friction case (closed-form mode, default dt),
/// and the dense exact solver's answers to them, each warm-started from the one before.
struct Recorded {
    std::vector<SparseContactProblem> problems;
    std::vector<Eigen::VectorXd> exact;
    /// the dense solver settled the step by its active-set passes alone (no Tresca fixed
    /// point: no pair near-degenerate within its threshold)
    std::vector<bool> by_passes;
};

const Recorded& friction_steps() {
    static const Recorded rec = [] {
        Recorded r;
        const System sys(Model::build(paper_example(PaperCase::friction)));
        SimulationOptions so;
        so.solver.tolerance_m = kTol;
        so.contact_path = ContactPath::sparse;
        ClosedFormStepper st(sys, so);
        const auto dense = make_solver(so.solver);
        for (int i = 0; i < 300; ++i) {
            st.advance();
            r.problems.push_back(st.contact_solver().last_sparse_problem());
            Eigen::VectorXd p = r.exact.empty() ? Eigen::VectorXd::Zero(r.problems.back().size()) : r.exact.back();
            const SolveResult rd = dense->solve(r.problems.back().to_dense(), p);
            BOOST_TEST_REQUIRE(rd.converged);
            r.by_passes.push_back(rd.tresca_iterations == 0 && !rd.fell_back);
            r.exact.push_back(p);
        }
        return r;
    }();
    return rec;
}

SolverOptions options() {
    SolverOptions o;
    o.tolerance_m = kTol;
    return o;
}

/// A path on `pr`'s structure with the problem's tau rule.
void prepare(sp::SparsePath& path, const SparseContactProblem& pr) {
    path.reset(pr);
    path.laws.tau_rule = pr.tau_rule;
    path.laws.tau_previous_n = pr.tau_previous_n;
}

double relative_difference(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    return (a - b).lpNorm<Eigen::Infinity>() / std::max(b.lpNorm<Eigen::Infinity>(), 1e-300);
}

/// The linear problem of `lin` solved densely on W, q: p = e + E p_S (held rows p_S, slip
/// rows coupled to their normal row) with (W p + q)_S = 0.
Eigen::VectorXd dense_mode_solution(const ContactProblem& dense, const modes::ModeLinearization& lin) {
    const int m = dense.size(), ms = static_cast<int>(lin.S.size());
    Eigen::MatrixXd E = Eigen::MatrixXd::Zero(m, ms);
    std::vector<int> col(m, -1);
    for (int i = 0; i < ms; ++i) {
        E(lin.S[i], i) = 1.0;
        col[lin.S[i]] = i;
    }
    Eigen::VectorXd e = lin.e;
    for (std::size_t a = 0; a < lin.coupled.size(); ++a) {
        const int t = lin.coupled[a].first, n = lin.coupled[a].second;
        if (col[n] >= 0) E(t, col[n]) += lin.coef[a];
        else e[t] += lin.coef[a] * e[n];
    }
    Eigen::MatrixXd M(ms, ms);
    Eigen::VectorXd rhs(ms);
    const Eigen::MatrixXd WE = dense.W * E;
    const Eigen::VectorXd we = dense.W * e + dense.q;
    for (int r = 0; r < ms; ++r) {
        M.row(r) = WE.row(lin.S[r]);
        rhs[r] = -we[lin.S[r]];
    }
    return e + E * Eigen::VectorXd(M.partialPivLu().solve(rhs));
}

}  // namespace

BOOST_AUTO_TEST_CASE(selected_inverse_is_the_dense_diagonal_on_a_hand_made_stiffness) {
    // Two chains of 8 DOFs (two "leaves": springs of 1e6 N/m to the ground, 2e6 N/m between
    // neighbours) and one hub DOF tied to all 16 (degree 17 > 12: eliminated by the rank
    // correction, as the rigid body's w). Contact rows: differences across the chains (on
    // the selected pattern), one with the hub, and one between the two ends of one chain
    // (an entry of A^-1 off the Cholesky pattern: computed directly). W's diagonal is then
    // exact to round-off on both sides: K's condition number here is ~1e2, so 1e-12.
    const int nc = 8, n = 2 * nc + 1, hub = n - 1;
    std::vector<Eigen::Triplet<double>> t;
    auto spring = [&](int a, int b, double k) {
        t.emplace_back(a, a, k);
        if (b < 0) return;
        t.emplace_back(b, b, k);
        t.emplace_back(a, b, -k);
        t.emplace_back(b, a, -k);
    };
    for (int c = 0; c < 2; ++c)
        for (int i = 0; i < nc; ++i) {
            spring(c * nc + i, -1, 1e6);
            if (i + 1 < nc) spring(c * nc + i, c * nc + i + 1, 2e6);
            spring(c * nc + i, hub, 1e5);
        }
    sp::SpMat K(n, n);
    K.setFromTriplets(t.begin(), t.end());
    K.makeCompressed();
    std::vector<Eigen::Triplet<double>> g;
    int rows = 0;
    for (int i = 0; i < nc; i += 2, ++rows) {
        g.emplace_back(rows, i, 1.0);
        g.emplace_back(rows, nc + i, -1.0);
    }
    g.emplace_back(rows, 3, 0.5);
    g.emplace_back(rows++, hub, -1.0);
    g.emplace_back(rows, 0, 1.0);
    g.emplace_back(rows++, nc - 1, -1.0);
    sp::SpMat G(rows, n);
    G.setFromTriplets(g.begin(), g.end());
    G.makeCompressed();
    sp::KCholesky llt(K);
    const Eigen::VectorXd diag = sp::selected_compliance_diagonal(K, G, llt);
    const Eigen::MatrixXd Kd(K), Gd(G);
    const Eigen::VectorXd ref = (Gd * Kd.llt().solve(Gd.transpose())).diagonal();
    BOOST_TEST(relative_difference(diag, ref) < 1e-12);
}

BOOST_AUTO_TEST_CASE(selected_inverse_is_the_dense_diagonal_on_the_paper_example) {
    // The paper example's sparse problem (hub: the rigid body's w): exact to round-off,
    // cond(K) ~ 1e8 here, so 1e-10 relative (measured ~1e-15).
    const SparseContactProblem& pr = friction_steps().problems.front();
    sp::KCholesky llt(pr.K);
    const Eigen::VectorXd diag = sp::selected_compliance_diagonal(pr.K, pr.G, llt);
    BOOST_TEST(relative_difference(diag, pr.to_dense().W.diagonal()) < 1e-10);
}

BOOST_AUTO_TEST_CASE(mode_solver_ways_equal_the_dense_solve) {
    // A set of modes of the paper friction example with every kind of row: every third
    // pair open, the others closed; of the closed ones every other sticks, the rest slip
    // (coupled to their normal force; clamps against their preload). The same linear
    // problem solved densely on W = G K^-1 G^T (dense_mode_solution) is the reference.
    const Recorded& rec = friction_steps();
    const SparseContactProblem& pr = rec.problems[10];
    const ContactProblem dense = pr.to_dense();
    modes::ModeSet modes;
    modes.init(dense, rec.exact[10], dense.W * rec.exact[10] + dense.q);
    for (int k = 0; k < static_cast<int>(dense.pairs.size()); ++k) {
        const auto& c = dense.pairs[k];
        if (c.row_n >= 0 && modes::ModeSet::unilateral(c)) modes.nmode[k] = k % 3 == 0 ? modes::OPEN : modes::CLOSED;
        if (c.row_t >= 0 && c.kind != PairKind::bonded) modes.tmode[k] = k % 2 == 0 ? modes::STICK : modes::SLIP_POS;
        modes.make_consistent(dense, k);
    }
    modes::ModeLinearization lin;
    modes.linearize(dense, lin);
    BOOST_TEST_REQUIRE(!lin.coupled.empty());  // slip coupling exercised
    const Eigen::VectorXd ref = dense_mode_solution(dense, lin);
    auto key = modes.key();
    for (const sp::ModeSolverTuning tuning : {sp::ModeSolverTuning{0, 0}, sp::ModeSolverTuning{400, 0}}) {
        sp::ModeSolver solver(tuning);
        solver.reset(pr.K, pr.G);
        Eigen::VectorXd p, z;
        BOOST_TEST(solver.solve(lin, key, pr.b, pr.d, p, z) == 1);  // one factorisation
        BOOST_TEST(relative_difference(p, ref) < kRel);
        // z is K^-1 (b + G^T p): s = G z - d vanishes on the held rows
        const Eigen::VectorXd s = pr.G * z - pr.d;
        for (int i : lin.S) BOOST_TEST(std::abs(s[i]) < 1e-12 * pr.d.lpNorm<Eigen::Infinity>() + 1e-15);
        // the same key again, then with another single-entry load: the cached affine map
        BOOST_TEST(solver.is_current(key));
        Eigen::VectorXd p2, z2;
        BOOST_TEST(solver.solve(lin, key, pr.b, pr.d, p2, z2) == 0);
        BOOST_TEST(relative_difference(p2, ref) < kRel);
        const Eigen::VectorXd b3 = 1.7 * pr.b;
        BOOST_TEST(solver.solve(lin, key, b3, pr.d, p2, z2) == 0);
        const Eigen::VectorXd b3_only = b3;
        ContactProblem dense3 = dense;
        dense3.q = pr.G * Eigen::MatrixXd(pr.K).llt().solve(b3_only) - pr.d;
        BOOST_TEST(relative_difference(p2, dense_mode_solution(dense3, lin)) < kRel);
    }
}

BOOST_AUTO_TEST_CASE(mode_solver_bordered_update_equals_the_dense_solve) {
    // The bordered way: a base sparse LU (no slip coupling, every closed row held), then a
    // held set that frees two base rows and adds one: solved by a low-rank update (no new
    // factorisation, updates() = 1), equal to the dense solve of that set.
    const Recorded& rec = friction_steps();
    const SparseContactProblem& pr = rec.problems[10];
    const ContactProblem dense = pr.to_dense();
    modes::ModeLinearization base, near;
    base.e = Eigen::VectorXd::Zero(pr.size());
    for (int i = 0; i < pr.size(); ++i)
        if (i % 4 != 1) base.S.push_back(i);
    near = base;
    near.S.erase(near.S.begin() + 3);  // freed rows: their forces fixed at e
    near.S.erase(near.S.begin() + 7);
    near.e[base.S[3]] = -50.0;
    near.S.push_back(1);               // a row not held in the base
    std::sort(near.S.begin(), near.S.end());
    sp::ModeSolver solver(sp::ModeSolverTuning{0, 150});
    solver.reset(pr.K, pr.G);
    Eigen::VectorXd p, z;
    const std::vector<signed char> key_base{1}, key_near{2};
    BOOST_TEST(solver.solve(base, key_base, pr.b, pr.d, p, z) == 1);
    BOOST_TEST(relative_difference(p, dense_mode_solution(dense, base)) < kRel);
    BOOST_TEST(solver.solve(near, key_near, pr.b, pr.d, p, z) == 0);
    BOOST_TEST(solver.updates() == 1);
    BOOST_TEST(relative_difference(p, dense_mode_solution(dense, near)) < kRel);
}

BOOST_AUTO_TEST_CASE(box_qp_methods_agree_with_the_dense_method_and_the_kkt_conditions) {
    // The box QP of the Tresca fixed point with the friction limits of the exact answer,
    // mu |p_n*|: its solution is the Coulomb solution p* itself (the fixed point), and
    // (W SPD) it is unique. Each method from zero with an empty working set: x within
    // its box, the KKT conditions on the dense W, q to the tolerance (tolerance [m] as
    // the methods' own test; the final solve holds its working set exactly), and x equal
    // to the dense primal method's answer and to p* to round-off (kRel).
    const Recorded& rec = friction_steps();
    int exercised = 0;
    for (int step : {5, 20, 40}) {
        const SparseContactProblem& pr = rec.problems[step];
        const Eigen::VectorXd& pstar = rec.exact[step];
        const ContactProblem dense = pr.to_dense();
        const double inf = std::numeric_limits<double>::infinity();
        Eigen::VectorXd lower = Eigen::VectorXd::Constant(pr.size(), -inf), upper = -lower;
        for (int k = 0; k < static_cast<int>(pr.pairs.size()); ++k) {
            const auto& c = pr.pairs[k];
            if (c.row_n >= 0 && modes::ModeSet::unilateral(c)) upper[c.row_n] = 0.0;
            if (c.row_t >= 0 && c.kind != PairKind::bonded) {
                const double limit = c.friction_coefficient * friction_normal_force(dense, k, pstar);
                lower[c.row_t] = -limit;
                upper[c.row_t] = limit;
            }
        }
        const double tolerance = sp::kAccept * kTol;
        Eigen::VectorXd xd = Eigen::VectorXd::Zero(pr.size());
        std::vector<signed char> wd;
        BOOST_TEST_REQUIRE(
            detail::solve_box_qp(dense.W, dense.q, lower, upper, xd, wd, tolerance, 50 * (pr.size() + 1)).converged);
        for (const sp::BoxQpFn method : {sp::box_qp_pivoting, sp::box_qp_interior_point, sp::box_qp_primal}) {
            sp::SparsePath path(options(), {}, {});
            prepare(path, pr);
            const sp::Step st{pr.b, pr.d};
            Eigen::VectorXd x = Eigen::VectorXd::Zero(pr.size()), z;
            std::vector<signed char> at_bound(pr.size(), 0);
            SolveResult r;
            BOOST_TEST_REQUIRE(method(path, sp::BoxQp{st, lower, upper, tolerance}, x, z, at_bound, r));
            if (r.iterations > 1) ++exercised;
            const Eigen::VectorXd s = dense.W * x + dense.q;
            for (int i = 0; i < pr.size(); ++i) {
                const double w = dense.W(i, i);
                // within the box: bound rows exactly, held rows to the tolerance (their test)
                BOOST_TEST((lower[i] - x[i]) * w < tolerance);
                BOOST_TEST((x[i] - upper[i]) * w < tolerance);
                // natural map of the box QP per row [m]: w (x - clamp(x - s / w, lower, upper))
                BOOST_TEST(std::abs(w * (x[i] - std::clamp(x[i] - s[i] / w, lower[i], upper[i]))) < tolerance);
            }
            BOOST_TEST(relative_difference(x, xd) < kRel);
            BOOST_TEST(relative_difference(x, pstar) < kRel);
        }
    }
    BOOST_TEST_MESSAGE("box QPs that needed more than one iteration: " << exercised << " of 9");
    BOOST_TEST(exercised > 0);
}

namespace {

/// Runs `method` alone on the recorded steps: each from the previous step's exact answer
/// and the modes read there, its modes then confirmed by the active-set passes where
/// `confirm` (the Newton methods stop near the solution). Checked against the step's
/// dense answer:
///  - the contact conditions on the dense W, q: natural map (contact.hpp) below the
///    tolerance, an independent check of the answer;
///  - where the dense solver settled the step by its passes (a unique set of modes within
///    the threshold), the same forces to round-off (kRel). Where it needed its Tresca fixed
///    point (steps 67 and 190 here), a pair is near-degenerate and the threshold admits a
///    second set of modes: measured 4e-5 relative apart (the dense answer with ||v|| below
///    the tolerance, this one with its natural map below it), so only the conditions are
///    checked there.
/// Counts the steps where the start was not a solution (`worked`) and where the method
/// settled (`settled`).
void transition_equals_dense(sp::TransitionFn method, bool confirm, int& worked, int& settled) {
    const Recorded& rec = friction_steps();
    sp::SparsePath path(options(), {}, {});
    prepare(path, rec.problems.front());
    worked = settled = 0;
    for (std::size_t i = 1; i < rec.problems.size(); ++i) {
        const SparseContactProblem& pr = rec.problems[i];
        path.laws.tau_rule = pr.tau_rule;
        const sp::Step step{pr.b, pr.d};
        Eigen::VectorXd p = rec.exact[i - 1], z;
        path.s = path.stiffness().positions(pr.b, pr.d, p, z);
        path.modes.init(path.laws, p, path.s);
        // the start is not a solution: the method has work to do (else skip the step)
        Eigen::VectorXd ps = p, zs = z;
        SolveResult probe;
        const bool start_solves = path.passes(step, ps, zs, 1, probe);
        path.modes.init(path.laws, p, path.stiffness().positions(pr.b, pr.d, p, z));
        if (start_solves) continue;
        ++worked;
        SolveResult r;
        bool ok = method(path, step, p, z, r);
        if (ok && confirm) ok = sp::passes_from_modes(path, step, p, z, r);
        if (!ok) continue;
        ++settled;
        const ContactProblem dense = pr.to_dense();
        BOOST_TEST(natural_map(dense, p, dense.W * p + dense.q).norm() < kTol, "step " << i);
        if (rec.by_passes[i]) BOOST_TEST(relative_difference(p, rec.exact[i]) < kRel, "step " << i);
    }
}

}  // namespace

BOOST_AUTO_TEST_CASE(each_transition_method_alone_equals_the_dense_exact_solver) {
    // Each transition method of the sparse path alone (not in the solver's chain) on the
    // steps of the paper friction case whose start (the previous answer and its modes) is
    // not a solution: the same answer as the dense exact solver (the same set of modes,
    // solved on the sparse stiffness: kRel). The Tresca fixed point's answer is confirmed
    // too (its slip forces are at the limit of the final tau to kAccept x tolerance).
    // The active-set passes alone (200 of them) settle only part of the transitions: with
    // the slip coupling the problem is not symmetric and block pivoting may cycle, which is
    // why the solver turns to the other methods.
    const sp::TransitionFn many_passes = [](sp::SparsePath& path, const sp::Step& step, Eigen::VectorXd& p,
                                            Eigen::VectorXd& z, SolveResult& r) {
        return path.passes(step, p, z, 200, r);
    };
    int worked = 0, settled = 0;
    transition_equals_dense(many_passes, false, worked, settled);
    BOOST_TEST_MESSAGE("transitions among the recorded steps: " << worked << ", settled by the passes alone: " << settled);
    BOOST_TEST(worked > 0);
    BOOST_TEST(settled > 0);
    // every other method settles every one of them
    const std::pair<sp::TransitionFn, bool> methods[] = {
        {sp::semismooth_newton, true}, {sp::smoothing_newton, true}, {sp::tresca_fixed_point, true}};
    for (const auto& [method, confirm] : methods) {
        int w = 0, s = 0;
        transition_equals_dense(method, confirm, w, s);
        BOOST_TEST(w == worked);
        BOOST_TEST(s == worked);
    }
}

BOOST_AUTO_TEST_CASE(methods_are_per_solver) {
    // The methods are a solver's own (SparsePathTuning::methods, taken at its construction): two
    // solvers made one after the other on one thread keep theirs, and the observer goes with them.
    // A bad field is an InputError naming it.
    const SolverOptions options;
    SparsePathMethods tresca;
    tresca.transition = sp::TransitionMethod::tresca;
    tresca.newton_first = true;
    SparsePathObserver trace;
    const sp::SparsePath a(options, sp::ModeSolverTuning{}, tresca, &trace);
    const sp::SparsePath b(options, sp::ModeSolverTuning{}, SparsePathMethods{});
    BOOST_TEST(static_cast<int>(a.switches.transition) == static_cast<int>(sp::TransitionMethod::tresca));
    BOOST_TEST(a.switches.newton_first);
    BOOST_TEST(a.observer == &trace);
    BOOST_TEST(static_cast<int>(b.switches.transition) == static_cast<int>(sp::TransitionMethod::newton));
    BOOST_TEST(!b.switches.newton_first);
    BOOST_TEST(b.observer == nullptr);
    for (const int fixed : {-1, 5}) {
        SparsePathTuning bad;
        bad.methods.fixed_pattern = fixed;
        try {
            SparseContactSolver solver(options, bad);
            BOOST_TEST(false, "fixed_pattern " << fixed << " accepted");
        } catch (const InputError& e) {
            BOOST_TEST(std::string(e.what()).find("tuning.methods.fixed_pattern") != std::string::npos);
        }
    }
    SparsePathTuning bad;
    bad.methods.newton_passes = -1;
    BOOST_CHECK_THROW(SparseContactSolver(options, bad), InputError);
}
