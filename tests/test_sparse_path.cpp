// The sparse contact path (SparseContactProblem on the reduced stiffness) against
// the dense one (W = C' + (gamma/k) c c^T): both pose the same problem (simulation.hpp
// derives the rigid body's spring k_R = k (1 - gamma)/gamma), so runs must agree to
// round-off, step by step, on the paper example's three cases and on a graduated stack.
// The cases on the finer and ten-leaf stacks (each transition method on 1,000+ rows, 85 %
// of the program's time) carry the label "slow": they run in the Release build only
// (tests/CMakeLists.txt); each method keeps its case on the paper example in the tier the
// sanitizer build runs.
#define BOOST_TEST_MODULE sparse_path
#include <boost/test/unit_test.hpp>
#include <cmath>
#include <ostream>

#include "stackbeam/time/closed_form_stepper.hpp"
#include "stackbeam/errors.hpp"
#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/time/simulation.hpp"
#include "stackbeam/fe/system.hpp"
#include "contact/sparse/driver/switches.hpp"
#include "fe/system_internal.hpp"
#include "test_support.hpp"

namespace tt = boost::test_tools;
using namespace stackbeam;
using stackbeam::detail::sparse::TransitionMethod;

namespace stackbeam {
std::ostream& operator<<(std::ostream& os, ContactPath p) { return os << to_string(p); }
}  // namespace stackbeam

namespace {

// Agreement tolerance. Both paths solve the same linear system per set of modes, one
// by a dense LU of W_SS (cond(W) ~ 1e5 on the paper example), the other by a scaled,
// refined sparse LU of the saddle-point system, and they reach the same modes at every
// step, so the forces and w differ only by the round-off of the two solves, amplified
// by cond(W): about 1e-16 x 1e5 = 1e-11 relative per step; the recursion
// w -> w_free -> p is a (damped) oscillator, so it does not grow over the run. Observed:
// at most 6e-11 (forces, friction case) relative to the largest value over the run.
// 1e-9 keeps a margin of about 15 and still catches any real discrepancy (a wrong
// rigid-body spring k_R, or a different mode at one step, gives >= 1e-6).
constexpr double kRel = 1e-9;

struct Run {
    std::vector<StepRecord> records;
    std::vector<Eigen::VectorXd> forces;
    bool c_built = false;
};

Run run(const System& sys, ContactPath path, double dt, int steps, double tol, TauRule rule) {
    SimulationOptions so;
    so.tau_rule = rule;
    so.dt_s = dt;
    so.t_end_s = dt * steps;
    so.solver.tolerance_m = tol;
    so.contact_path = path;
    ClosedFormStepper st(sys, so);
    BOOST_TEST(st.contact_path() == path);
    Run r;
    r.records.push_back(st.current());
    r.forces.push_back(st.contact_forces());
    for (int i = 0; i < steps; ++i) {
        r.records.push_back(st.advance());
        r.forces.push_back(st.contact_forces());
    }
    return r;
}

double max_abs(const std::vector<StepRecord>& r, double StepRecord::*field) {
    double m = 0.0;
    for (const auto& x : r) m = std::max(m, std::abs(x.*field));
    return m;
}

/// Runs both paths on `spec` (a fresh System each, so that the sparse one provably
/// never builds the dense C') and compares them step by step.
void compare_paths(const ModelSpec& spec, double dt, int steps, double tol, bool compare_states = true,
                   TauRule rule = TauRule::current, double rel = kRel) {
    const System dense_sys(Model::build(spec));
    const System sparse_sys(Model::build(spec));
    const Run d = run(dense_sys, ContactPath::dense, dt, steps, tol, rule);
    const Run s = run(sparse_sys, ContactPath::sparse, dt, steps, tol, rule);
    BOOST_TEST(!detail::compliance_held_built(sparse_sys));  // the sparse path never forms C'
    BOOST_TEST_REQUIRE(d.records.size() == s.records.size());
    const double w_scale = max_abs(d.records, &StepRecord::w_m);
    const double v_scale = max_abs(d.records, &StepRecord::w_dot_m_per_s);
    const double e_scale = d.records.front().kinetic_energy_j + d.records.front().strain_energy_j;
    // force scale: the largest contact force, or the force on the body where the contact
    // forces are all ~0 (frictionless identical leaves bend alike and press on nothing)
    double p_scale = max_abs(d.records, &StepRecord::force_on_mass_n);
    for (const auto& p : d.forces) p_scale = std::max(p_scale, p.lpNorm<Eigen::Infinity>());
    double dw = 0.0, dv = 0.0, dp = 0.0, du = 0.0, dd = 0.0;
    int mode_mismatch = 0;
    for (std::size_t i = 0; i < d.records.size(); ++i) {
        const StepRecord &a = d.records[i], &b = s.records[i];
        dw = std::max(dw, std::abs(a.w_m - b.w_m));
        dv = std::max(dv, std::abs(a.w_dot_m_per_s - b.w_dot_m_per_s));
        dp = std::max(dp, (d.forces[i] - s.forces[i]).lpNorm<Eigen::Infinity>());
        du = std::max(du, std::abs(a.strain_energy_j - b.strain_energy_j));
        dd = std::max(dd, std::abs(a.dissipated_energy_j - b.dissipated_energy_j));
        if (a.n_stick != b.n_stick || a.n_slip != b.n_slip || a.n_open != b.n_open) ++mode_mismatch;
    }
    BOOST_TEST_MESSAGE("max differences: w " << dw / w_scale << ", w_dot " << dv / v_scale << ", p "
                                             << dp / p_scale << ", strain energy " << du / e_scale
                                             << ", dissipated " << dd / e_scale << " (relative)");
    BOOST_CHECK_SMALL(dw / w_scale, rel);
    BOOST_CHECK_SMALL(dv / v_scale, rel);
    BOOST_CHECK_SMALL(dp / p_scale, rel);
    BOOST_CHECK_SMALL(du / e_scale, rel);
    BOOST_CHECK_SMALL(dd / e_scale, rel);
    if (compare_states) BOOST_TEST(mode_mismatch == 0);  // the same pairs stick, slip and open at every step
    // the dissipation of the friction runs is not zero, so its comparison has teeth there
    BOOST_TEST_MESSAGE("dissipated at the end: " << d.records.back().dissipated_energy_j << " J");
}

// tolerance 1e-10 m: far below the physics (amplitudes ~ 2e-2 m), so the modes are
// settled well inside their thresholds and both paths see the same transitions.
constexpr double kTol = 1e-10;

}  // namespace

BOOST_AUTO_TEST_CASE(sparse_equals_dense_on_the_paper_example_bonded) {
    compare_paths(paper_example(PaperCase::bonded), 1e-3, 300, kTol);
}

BOOST_AUTO_TEST_CASE(sparse_equals_dense_on_the_paper_example_friction) {
    // 300 steps = 0.3 s: more than one period with stick-slip transitions at the clamps
    compare_paths(paper_example(PaperCase::friction), 1e-3, 300, kTol);
}

BOOST_AUTO_TEST_CASE(sparse_equals_dense_with_the_previous_step_friction_limit) {
    // the paper's fallback rule: the slip forces come from the previous step's tau, so the
    // sparse path's cached constant solve changes every step
    compare_paths(paper_example(PaperCase::friction), 1e-3, 200, kTol, true, TauRule::previous_step);
}

BOOST_AUTO_TEST_CASE(sparse_equals_dense_on_the_paper_example_frictionless) {
    // The identical frictionless leaves bend alike: every contact force is zero up to
    // round-off (~1e-12 N), so whether a pair counts as open or closed is the sign of
    // round-off on either path; the states are not compared, the forces are (to the
    // force on the body as scale).
    compare_paths(paper_example(PaperCase::frictionless), 1e-3, 300, kTol, false);
}

BOOST_AUTO_TEST_CASE(sparse_equals_dense_on_the_full_model) {
    // full model: the seat rotates (theta_R) and ties the leaves axially; 200 steps
    PaperExampleOptions o;
    o.symmetry = Symmetry::full;
    compare_paths(paper_example(PaperCase::friction, o), 1e-3, 200, kTol);
}

BOOST_AUTO_TEST_CASE(sparse_equals_dense_on_a_graduated_stack) {
    // As in test_graduated.cpp: a long pinned leaf over a shorter free one, mu = 0.3,
    // two clamps with 200 N; plus an initial displacement so that the held initial
    // contact state (R held at w(0)) is exercised on both paths.
    constexpr double L = 0.5, b = 0.05, h = 0.005, E = 2e10, short_len = 0.25;
    ModelSpec s;
    s.leaves.push_back({L, 0.0, h, b, E, 0.0, SupportKind::pinned, SupportKind::pinned});
    s.leaves.push_back({short_len, 0.5 * (L - short_len), h, b, E, 0.0, SupportKind::free, SupportKind::free});
    s.interfaces.push_back({InterfaceLaw::coulomb, 0.3, 0.0});
    s.clamps = {{0.15, 200.0}, {0.35, 200.0}};
    s.rigid_body.mass_kg = 20.0;
    s.rigid_body.x_m = 0.5 * L;
    s.rigid_body.initial_velocity_m_per_s = 1.0;
    s.rigid_body.initial_displacement_m = -2e-3;
    s.mesh.element_length_m = 0.5 * L / 20;
    s.symmetry = Symmetry::half;
    compare_paths(s, 5e-4, 400, kTol);
}

BOOST_AUTO_TEST_CASE(sparse_problem_is_the_dense_problem) {
    // The stepper's sparse problem, condensed (to_dense), is the dense path's W and q:
    // the k_R derivation in simulation.hpp, checked on one step. W ~ 1e-5 m/N; the two
    // are computed by different sequences of solves: 1e-9 relative.
    const System sys(Model::build(paper_example(PaperCase::friction)));
    SimulationOptions so;
    so.solver.tolerance_m = kTol;
    so.contact_path = ContactPath::sparse;
    ClosedFormStepper sp(sys, so);
    so.contact_path = ContactPath::dense;
    ClosedFormStepper de(sys, so);
    for (int i = 0; i < 5; ++i) {
        sp.advance();
        de.advance();
    }
    const ContactProblem c = sp.contact_solver().last_sparse_problem().to_dense();
    const ContactProblem& ref = de.contact_solver().last_dense_problem();
    BOOST_TEST((c.W - ref.W).norm() / ref.W.norm() < 1e-9);
    BOOST_TEST((c.q - ref.q).norm() / ref.q.norm() < 1e-9);
    BOOST_TEST(sp.contact_solver().last_dense_problem().W.size() == 0);  // the sparse stepper holds no dense W
}

BOOST_AUTO_TEST_CASE(automatic_choice_and_bad_input) {
    const System small(Model::build(paper_example(PaperCase::friction)));
    SimulationOptions so;
    BOOST_TEST(so.contact_path == ContactPath::automatic);
    BOOST_TEST(small.num_components() < kSparsePathMinComponents);
    BOOST_TEST(choose_contact_path(small, so) == ContactPath::dense);
    // decision 050: the paper example (76 rows) and the graduated 10 x 12 (144) dense, the
    // graduated 10 x 14 (234) and 10 x 50 (540) sparse, where each path is the faster
    const System g12(Model::build(testing::graduated_stack(12, 10)));
    const System g14(Model::build(testing::graduated_stack(14, 10)));
    const System g50(Model::build(testing::graduated_stack(50, 10)));
    BOOST_TEST(g12.num_components() == 144);
    BOOST_TEST(g14.num_components() == 234);
    BOOST_TEST(g50.num_components() == 540);
    BOOST_TEST(choose_contact_path(g12, so) == ContactPath::dense);
    BOOST_TEST(choose_contact_path(g14, so) == ContactPath::sparse);
    BOOST_TEST(choose_contact_path(g50, so) == ContactPath::sparse);
    PaperExampleOptions o;
    o.elements_per_half_leaf = 300;  // 3 leaves: 2 interfaces x ~300 nodes x 2 rows > 1000
    const System large(Model::build(paper_example(PaperCase::friction, o)));
    BOOST_TEST(large.num_components() >= kSparsePathMinComponents);
    BOOST_TEST(choose_contact_path(large, so) == ContactPath::sparse);
    BOOST_TEST(!detail::compliance_held_built(large));  // the constructor no longer builds C'
    so.solver.kind = SolverKind::accelerated;    // only the exact solver has a sparse form
    BOOST_TEST(choose_contact_path(large, so) == ContactPath::dense);
    so.contact_path = ContactPath::sparse;
    BOOST_CHECK_THROW(so.validate(), InputError);
    BOOST_CHECK_THROW(SparseContactSolver(so.solver), InputError);

    BOOST_TEST(parse_contact_path("auto", "--contact-path") == ContactPath::automatic);
    BOOST_TEST(parse_contact_path("sparse", "--contact-path") == ContactPath::sparse);
    try {
        parse_contact_path("banded", "--contact-path");
        BOOST_FAIL("no error for an unknown contact path");
    } catch (const InputError& e) {
        const std::string msg = e.what();
        BOOST_TEST(e.field() == "--contact-path");
        BOOST_TEST(msg.find("'banded'") != std::string::npos);
        BOOST_TEST(msg.find("auto, dense, sparse") != std::string::npos);
    }
}

BOOST_AUTO_TEST_CASE(sparse_compliance_diagonal_is_exact) {
    // The sparse path's diagonal of W = G K^-1 G^T (selected inverse of K without the
    // rigid body's DOFs plus a rank-h correction for them, contact/sparse/driver/sparse_solver.cpp) against the
    // dense W of to_dense() (m full solves). Both are exact up to round-off: the entries
    // are sums of a few products of O(1) coefficients with entries of K^-1 whose relative
    // error is about cond(K) x 1e-16 (cond ~ 1e8-1e10 here: EA/L against EI/L^3 and the
    // mesh), so 1e-7 relative to the largest W_ii; observed at most 2e-13.
    auto check = [](const ModelSpec& spec) {
        const System sys(Model::build(spec));
        SimulationOptions so;
        so.solver.tolerance_m = kTol;
        so.contact_path = ContactPath::sparse;
        ClosedFormStepper st(sys, so);
        st.advance();
        const SparseContactProblem& pr = st.contact_solver().last_sparse_problem();
        SparseContactSolver solver(so.solver);
        Eigen::VectorXd p = Eigen::VectorXd::Zero(pr.size()), z;
        const SolveResult r = solver.solve(pr, p, z);
        const ContactProblem dense = pr.to_dense();
        const Eigen::VectorXd ref = dense.W.diagonal();
        const double err = (solver.compliance_diagonal() - ref).lpNorm<Eigen::Infinity>() / ref.lpNorm<Eigen::Infinity>();
        BOOST_TEST_MESSAGE("compliance diagonal: max relative difference " << err);
        BOOST_TEST(err < 1e-7);
        // the residuals reported (one fused pass over the pairs) are those of the public
        // functions at the same p and s (summation order only: 1e-12 relative)
        const Eigen::VectorXd& sp = solver.relative_positions();
        const double v = error_vector(dense, p, sp).norm(), nat = natural_map(dense, p, sp).norm();
        BOOST_TEST(std::abs(r.residual_m - v) <= 1e-12 * v + 1e-300);
        BOOST_TEST(std::abs(r.natural_residual_m - nat) <= 1e-7 * nat + 1e-300);  // W_ii: see above
    };
    check(paper_example(PaperCase::friction));
    check(paper_example(PaperCase::bonded));
    PaperExampleOptions full;
    full.symmetry = Symmetry::full;  // two hubs: w and the seat rotation
    check(paper_example(PaperCase::friction, full));
    PaperExampleOptions fine;
    fine.elements_per_half_leaf = 60;
    ModelSpec five = paper_example(PaperCase::friction, fine);
    while (five.leaves.size() < 5) {
        five.leaves.push_back(five.leaves.back());
        five.interfaces.push_back(five.interfaces.back());
    }
    check(five);
}

/// The answers of one SparseContactSolver (made with `tuning` and the methods `methods`) to
/// `problems` in order, each solve from the last answer (as the stepper does), with its counts;
/// checks that every solve converged (error vector below the tolerance: the exact solver's answer).
struct Replay {
    std::vector<Eigen::VectorXd> p;  ///< the forces [N] per problem
    int newton = 0, updates = 0, factorizations = 0;
    Eigen::VectorXd w;               ///< W's diagonal [m/N] at the end
};
Replay replay_sparse(const std::vector<SparseContactProblem>& problems, const SolverOptions& options,
                     SparsePathTuning tuning = {}, const SparsePathMethods& methods = {}) {
    tuning.methods = methods;
    SparseContactSolver solver(options, tuning);
    Replay out;
    Eigen::VectorXd p = Eigen::VectorXd::Zero(problems.front().size()), z;
    for (const auto& pr : problems) {
        const SolveResult r = solver.solve(pr, p, z);
        BOOST_TEST(r.converged);
        out.newton += r.newton_iterations;
        out.updates += r.updates;
        out.factorizations += r.factorizations;
        out.p.push_back(p);
    }
    out.w = solver.compliance_diagonal();
    return out;
}

BOOST_AUTO_TEST_CASE(sparse_ways_agree_on_replayed_problems) {
    // The three ways of SparseContactSolver to solve a set of modes (SparsePathTuning):
    // the sparse LU of the saddle-point system alone (schur_max_rows = 0, max_border_rows
    // = 0: the reference, a fresh factorisation per set of modes), the same with low-rank
    // bordered updates of the last LU (max_border_rows = 150), and the default (the dense
    // Schur complement of the held rows on K's factor for up to 400 held rows). They
    // replay the sparse problems of 300 steps of the paper's friction case in order, each
    // warm-started from its own previous forces as in a run, and must give the same forces
    // at every step. All are direct solves with one step of iterative refinement, so they
    // differ by round-off amplified by cond(W) ~ 1e5 (1e-11 relative) and, for the
    // updates, by the capacitance matrix's conditioning over up to 150 changed rows;
    // observed: see the message. 1e-9 relative to the largest force, as the sparse ==
    // dense runs above; a different mode at one step would give >= 1e-6.
    const System sys(Model::build(paper_example(PaperCase::friction)));
    SimulationOptions so;
    so.solver.tolerance_m = kTol;
    so.contact_path = ContactPath::sparse;
    ClosedFormStepper st(sys, so);
    std::vector<SparseContactProblem> problems;
    for (int i = 0; i < 300; ++i) {
        st.advance();
        problems.push_back(st.contact_solver().last_sparse_problem());
    }
    const Replay rl = replay_sparse(problems, so.solver, SparsePathTuning{0, 0});
    const Replay rb = replay_sparse(problems, so.solver, SparsePathTuning{0, 150});
    const Replay rd = replay_sparse(problems, so.solver, SparsePathTuning{});
    const auto &lu = rl.p, &border = rb.p, &def = rd.p;
    const int u_lu = rl.updates, f_lu = rl.factorizations, u_border = rb.updates, f_border = rb.factorizations,
              u_default = rd.updates, f_default = rd.factorizations;
    double scale = 0.0, d_border = 0.0, d_default = 0.0;
    for (std::size_t i = 0; i < lu.size(); ++i) {
        scale = std::max(scale, lu[i].lpNorm<Eigen::Infinity>());
        d_border = std::max(d_border, (border[i] - lu[i]).lpNorm<Eigen::Infinity>());
        d_default = std::max(d_default, (def[i] - lu[i]).lpNorm<Eigen::Infinity>());
    }
    BOOST_TEST_MESSAGE("replayed: LU " << f_lu << " factorisations; with updates " << f_border << " + " << u_border
                                       << " updates, max difference " << d_border / scale << "; default " << f_default
                                       << " + " << u_default << " updates, max difference " << d_default / scale);
    BOOST_TEST(u_lu == 0);
    BOOST_TEST(u_border > 0);  // the updates were used
    BOOST_CHECK_SMALL(d_border / scale, kRel);
    BOOST_CHECK_SMALL(d_default / scale, kRel);
    BOOST_CHECK_THROW(SparseContactSolver(so.solver, SparsePathTuning{-1, 0}), InputError);
}

BOOST_AUTO_TEST_CASE(low_rank_updates_agree_with_fresh_factorisations) {
    // Frictionless graduated stack (as sparse_equals_dense_on_a_graduated_stack, mu = 0):
    // no slip coupling, so every set of modes near the last sparse LU's held set is
    // solved by a bordered update of it, and the forces returned come from those updates
    // (the contact opens and closes pair by pair as the short leaf lifts off and lands).
    // Replayed with updates (max_border_rows = 150) and with a fresh sparse LU per set of
    // modes (0): the same forces at every step to round-off. Tolerance as above (1e-9
    // relative to the largest force: cond(W) ~ 1e5 and the capacitance matrix of at most
    // 150 rows; a different mode at one step gives >= 1e-6); observed: see the message.
    constexpr double L = 0.5, b = 0.05, h = 0.005, E = 2e10, short_len = 0.25;
    ModelSpec s;
    s.leaves.push_back({L, 0.0, h, b, E, 0.0, SupportKind::pinned, SupportKind::pinned});
    s.leaves.push_back({short_len, 0.5 * (L - short_len), h, b, E, 0.0, SupportKind::free, SupportKind::free});
    s.interfaces.push_back({InterfaceLaw::coulomb, 0.0, 0.0});
    s.clamps = {{0.15, 200.0}, {0.35, 200.0}};
    s.rigid_body.mass_kg = 20.0;
    s.rigid_body.x_m = 0.5 * L;
    s.rigid_body.initial_velocity_m_per_s = 1.0;
    s.mesh.element_length_m = 0.5 * L / 40;
    s.symmetry = Symmetry::half;
    const System sys(Model::build(s));
    SimulationOptions so;
    so.solver.tolerance_m = kTol;
    so.dt_s = 5e-4;
    so.contact_path = ContactPath::sparse;
    ClosedFormStepper st(sys, so);
    std::vector<SparseContactProblem> problems;
    for (int i = 0; i < 400; ++i) {
        st.advance();
        problems.push_back(st.contact_solver().last_sparse_problem());
    }
    const Replay rf = replay_sparse(problems, so.solver, SparsePathTuning{0, 0});
    const Replay rb = replay_sparse(problems, so.solver, SparsePathTuning{0, 150});
    const auto &fresh = rf.p, &border = rb.p;
    const int u_fresh = rf.updates, u_border = rb.updates;
    double scale = 0.0, diff = 0.0;
    for (std::size_t i = 0; i < fresh.size(); ++i) {
        scale = std::max(scale, fresh[i].lpNorm<Eigen::Infinity>());
        diff = std::max(diff, (border[i] - fresh[i]).lpNorm<Eigen::Infinity>());
    }
    BOOST_TEST_MESSAGE("updates: " << u_border << ", max difference to fresh factorisations " << diff / scale);
    BOOST_TEST(u_fresh == 0);
    BOOST_TEST(u_border > 20);
    BOOST_CHECK_SMALL(diff / scale, kRel);
}

BOOST_AUTO_TEST_CASE(sparse_equals_dense_on_a_finer_stack) {
    // 3 leaves x 160 elements per half leaf (636 contact rows), friction: the first passes
    // hold more than 400 rows (sparse LU, low-rank updates), the later ones fewer (Schur
    // complement on K's factor), so the default tuning's ways meet in one run; 20 steps.
    // Tolerance: cond(W) grows with the mesh (the leaves' bending compliance against the
    // contact rows' local stiffness, ~ elements^2: 64x that of the 20-element example),
    // so round-off differences do too. Observed with the sparse LU alone (the path before
    // the Schur and update ways): 1.0e-8 (forces) and 3.2e-8 (strain energy); with the
    // default ways 1.0e-8 and 1.4e-9. 1e-7 keeps a margin of 3 and still catches a
    // different mode at one step (>= 1e-6).
    PaperExampleOptions o;
    o.elements_per_half_leaf = 160;
    compare_paths(paper_example(PaperCase::friction, o), 1e-3, 20, kTol, true, TauRule::current, 1e-7);
}

namespace {

/// Replays the sparse problems of `steps` closed-form steps of `spec` (recorded from a
/// sparse run) with the semismooth Newton method alone (SparsePathMethods::newton_first:
/// every solve starts with it from the previous forces, the passes only confirm its
/// modes) and with the dense exact solver on to_dense(), each warm-started from its own
/// previous forces, and compares the forces step by step. Also checks the contact
/// conditions independently: the natural map (contact.hpp) of the Newton answer on the
/// dense W, q.
void newton_equals_dense(const ModelSpec& spec, int steps, double rel,
                         TransitionMethod method = TransitionMethod::newton) {
    const bool smoothing = method == TransitionMethod::smoothing;
    const bool tresca = method == TransitionMethod::tresca;  // with the interior-point method on every box QP
    SimulationOptions so;
    so.solver.tolerance_m = kTol;
    const std::vector<SparseContactProblem> problems = testing::sparse_step_problems(spec, steps, so);
    SparsePathTuning tuning;
    tuning.methods.newton_first = true;
    tuning.methods.transition = method;
    if (tresca) tuning.methods.box_qp = SparseBoxQpMethod::interior_point;
    SparseContactSolver newton(so.solver, tuning);
    const auto dense_solver = make_solver(so.solver);
    Eigen::VectorXd pn = Eigen::VectorXd::Zero(problems.front().size()), pd = pn, z;
    double scale = 0.0, diff = 0.0, worst_natural = 0.0;
    int newton_iterations = 0, factorizations = 0, transitions = 0;
    for (const auto& pr : problems) {
        const SolveResult rn = newton.solve(pr, pn, z);
        BOOST_TEST(rn.converged);
        BOOST_TEST(!rn.fell_back);  // the Newton method's answer, not the Tresca fixed point's or the dense one's
        const int its = smoothing ? rn.smoothing_iterations
                        : tresca  ? rn.iterations  // interior-point iterations and passes
                                  : rn.newton_iterations;
        newton_iterations += its;
        factorizations += rn.factorizations;
        if (its > 0) ++transitions;
        const ContactProblem dense = pr.to_dense();
        const SolveResult rd = dense_solver->solve(dense, pd);
        BOOST_TEST(rd.converged);
        scale = std::max(scale, pd.lpNorm<Eigen::Infinity>());
        diff = std::max(diff, (pn - pd).lpNorm<Eigen::Infinity>());
        const Eigen::VectorXd s = dense.W * pn + dense.q;
        worst_natural = std::max(worst_natural, natural_map(dense, pn, s).norm());
        BOOST_TEST(error_vector(dense, pn, s).norm() < kTol);  // eq. 10: v = 0 to the tolerance
    }
    BOOST_TEST_MESSAGE((smoothing ? "smoothing Newton: " : tresca ? "interior-point Tresca: " : "semismooth Newton: ")
                       << newton_iterations << " iterations in " << transitions
                                             << " solves that needed it, " << factorizations
                                             << " factorisations; max force difference to the dense exact solver "
                                             << diff / scale << " (relative), worst natural-map residual "
                                             << worst_natural << " m");
    BOOST_TEST(transitions > 0);  // the method was exercised (the warm start was not already a solution)
    BOOST_CHECK_SMALL(diff / scale, rel);
    // the Newton method stops at |F_i| <= kAccept x tolerance / 2 per component and the
    // passes then solve its modes exactly, so the natural map is round-off: below kTol
    BOOST_CHECK_SMALL(worst_natural, kTol);
}

}  // namespace

BOOST_AUTO_TEST_CASE(newton_equals_dense_exact_on_the_paper_friction_case) {
    // 300 steps of the paper's friction case (76 rows): stick-slip transitions at the
    // clamps every few steps. Both answers are the linear solution of the same set of
    // modes (a dense LU of W_SS against the Schur complement on K's factor), so they differ
    // by round-off amplified by cond(W) ~ 1e5: 1e-9 relative, as kRel above; a different
    // mode at one step gives >= 1e-6.
    newton_equals_dense(paper_example(PaperCase::friction), 300, kRel);
}

BOOST_AUTO_TEST_CASE(newton_equals_dense_exact_on_a_finer_friction_stack, *boost::unit_test::label("slow")) {
    // 3 leaves x 160 elements (636 rows), 20 steps from rest: the first steps are the
    // degenerate transition (most pairs open at once). Tolerance 1e-7 relative, as
    // sparse_equals_dense_on_a_finer_stack: cond(W) grows ~ elements^2 (64x the
    // example's), observed round-off differences up to 1e-8.
    PaperExampleOptions o;
    o.elements_per_half_leaf = 160;
    newton_equals_dense(paper_example(PaperCase::friction, o), 20, 1e-7);
}

BOOST_AUTO_TEST_CASE(smoothing_equals_dense_exact_on_the_paper_friction_case) {
    // The smoothing Newton method alone (TransitionMethod::smoothing, from the warm start
    // at every step) on the 300 replayed steps of newton_equals_dense_exact_on_the_paper_
    // friction_case: it stops at |F_i| <= kAccept x tolerance / 2 of the natural map and the
    // passes then solve its modes exactly, so the answer is again the linear solution of
    // the dense solver's modes: the same round-off bound, 1e-9 relative (kRel).
    newton_equals_dense(paper_example(PaperCase::friction), 300, kRel, TransitionMethod::smoothing);
}

BOOST_AUTO_TEST_CASE(smoothing_equals_dense_exact_on_a_finer_friction_stack, *boost::unit_test::label("slow")) {
    // 3 x 160 from rest, 20 steps (the degenerate transition), smoothing method alone;
    // tolerance as for the semismooth method on this stack (cond(W) ~ 64x the example's).
    PaperExampleOptions o;
    o.elements_per_half_leaf = 160;
    newton_equals_dense(paper_example(PaperCase::friction, o), 20, 1e-7, TransitionMethod::smoothing);
}

BOOST_AUTO_TEST_CASE(interior_point_tresca_equals_dense_exact_on_the_paper_friction_case) {
    // The Tresca fixed point alone (TransitionMethod::tresca, from the warm start at every
    // step) with every box QP solved by the interior-point method (BoxQpMethod::interior_point): its
    // working set, read from the iterate, gives the modes, and the passes then solve those
    // modes exactly, so the answer is again the linear solution of the dense solver's modes
    // (a wrong working set would show as a different mode: >= 1e-6): the round-off bound of
    // the Newton methods' tests, 1e-9 relative (kRel).
    newton_equals_dense(paper_example(PaperCase::friction), 300, kRel, TransitionMethod::tresca);
}

BOOST_AUTO_TEST_CASE(interior_point_tresca_equals_dense_exact_on_a_finer_friction_stack, *boost::unit_test::label("slow")) {
    // 3 x 160 from rest, 20 steps (the degenerate transition: pairs with force and gap both
    // ~0, where pivoting changes few rows per factorisation), interior-point box QPs;
    // tolerance as for the Newton methods on this stack (cond(W) ~ 64x the example's).
    PaperExampleOptions o;
    o.elements_per_half_leaf = 160;
    newton_equals_dense(paper_example(PaperCase::friction, o), 20, 1e-7, TransitionMethod::tresca);
}

BOOST_AUTO_TEST_CASE(accelerated_tresca_settles_a_graduated_ten_leaf_stack, *boost::unit_test::label("slow")) {
    // 10 graduated leaves x 100 elements per half leaf (1,080 rows; leaf k shorter by
    // 8 % of L per leaf, free ends, clamps at 0.2 and 0.3 m: the benchmark's graduated
    // stack), 25 steps from rest recorded from a default sparse run (semismooth Newton at
    // the transitions), replayed with the Tresca fixed point alone (TransitionMethod::tresca)
    // at the default Anderson depth. Without the acceleration (depth 0) its 100 passes do
    // not settle on steps 19-24 of this replay, and the dense fallback's Gauss-Seidel ends
    // them just under the tolerance, 2.4 minutes for the 25 steps (measured; too slow for a
    // test). Checked here:
    // - every step settles (at most kMaxPasses passes; 13 measured, 10 on step 19, where the
    //   plain fixed point first stalls; steps 20-24 then settle by the passes alone) and
    //   satisfies the contact conditions on the dense problem: natural map below the
    //   tolerance, an independent check of the solver's own report;
    // - from step 6 on, the forces are the default transition's to round-off (both are the
    //   linear solution of the same modes; cond(W) ~ elements^2, 1e-7 relative as the finer
    //   stacks above; a different mode gives >= 1e-6). Steps 0-5 are the transition from
    //   rest, where this stack's incremental problem has more than one solution: on steps 1
    //   and 5 both methods end with natural maps ~1e-17 m yet forces 0.7 and 1.9 N apart
    //   (measured), so there only the contact conditions are checked.
    constexpr int kMaxPasses = 30;
    const System sys(Model::build(testing::graduated_stack(100, 10)));
    SimulationOptions so;
    so.contact_path = ContactPath::sparse;
    ClosedFormStepper st(sys, so);
    std::vector<SparseContactProblem> problems;
    std::vector<Eigen::VectorXd> reference;
    for (int i = 0; i < 25; ++i) {
        st.advance();
        problems.push_back(st.contact_solver().last_sparse_problem());
        reference.push_back(st.contact_forces());
    }
    SparsePathTuning tresca;
    tresca.methods.transition = TransitionMethod::tresca;
    SparseContactSolver solver(so.solver, tresca);
    BOOST_TEST(so.solver.tresca_anderson_depth > 0);
    Eigen::VectorXd p = Eigen::VectorXd::Zero(problems.front().size()), z;
    double scale = 0.0, diff = 0.0, worst_natural = 0.0;
    int passes = 0, most = 0, late = 0;
    for (std::size_t i = 0; i < problems.size(); ++i) {
        const SolveResult r = solver.solve(problems[i], p, z);
        BOOST_TEST(r.converged);
        passes += r.tresca_iterations;
        most = std::max(most, r.tresca_iterations);
        if (r.tresca_iterations == 0) continue;  // the passes from the previous modes settled it
        const ContactProblem dense = problems[i].to_dense();
        const Eigen::VectorXd s = dense.W * p + dense.q;
        worst_natural = std::max(worst_natural, natural_map(dense, p, s).norm());
        if (i < 6) continue;
        ++late;
        BOOST_TEST(!r.fell_back);  // the passes confirmed the fixed point's modes
        scale = std::max(scale, reference[i].lpNorm<Eigen::Infinity>());
        diff = std::max(diff, (p - reference[i]).lpNorm<Eigen::Infinity>());
    }
    BOOST_TEST_MESSAGE("accelerated Tresca fixed point, graduated 10 x 100: " << passes << " passes in 25 steps (most "
                                                                             << most << "), worst natural map " << worst_natural
                                                                             << " m; from step 6 (" << late << " steps) max "
                                                                             << "force difference to the default transition "
                                                                             << diff / scale);
    BOOST_TEST(late > 0);  // the hard steps did reach the fixed point
    BOOST_TEST(most <= kMaxPasses);
    BOOST_CHECK_SMALL(worst_natural, so.solver.tolerance_m);
    BOOST_CHECK_SMALL(diff / scale, 1e-7);
    SolverOptions bad;
    bad.tresca_anderson_depth = -1;
    BOOST_CHECK_THROW(SparseContactSolver{bad}, InputError);
    bad.tresca_anderson_depth = 51;
    BOOST_CHECK_THROW(make_solver(bad), InputError);
}

BOOST_AUTO_TEST_CASE(sparse_equals_dense_on_a_ten_leaf_friction_stack) {
    // 10 identical leaves x 20 elements (342 rows), friction, 20 steps from rest: the
    // degenerate transition the semismooth Newton method is for (the default sparse
    // path: passes from the previous modes, then Newton). Tolerance as the finer stack.
    compare_paths(testing::paper_stack(PaperCase::friction, 20, 10), 1e-3, 20, kTol, true, TauRule::current, 1e-7);
}

BOOST_AUTO_TEST_CASE(newton_and_tresca_transitions_agree) {
    // The same 20 replayed problems of 3 leaves x 160 elements from rest (636 rows, the
    // first steps a transition of most pairs), solved with the default transition method
    // (passes, then the semismooth Newton method) and with the Tresca fixed point alone
    // (TransitionMethod::tresca, the method before): both end in an exact solve of the
    // same modes, so the forces agree to round-off (1e-7 relative, as the finer-stack
    // comparison above), and the Newton method is used by the default only.
    PaperExampleOptions o;
    o.elements_per_half_leaf = 160;
    const System sys(Model::build(paper_example(PaperCase::friction, o)));
    SimulationOptions so;
    so.solver.tolerance_m = kTol;
    so.contact_path = ContactPath::sparse;
    ClosedFormStepper st(sys, so);
    std::vector<SparseContactProblem> problems;
    for (int i = 0; i < 20; ++i) {
        st.advance();
        problems.push_back(st.contact_solver().last_sparse_problem());
    }
    SparsePathMethods tresca;
    tresca.transition = TransitionMethod::tresca;
    const Replay ra = replay_sparse(problems, so.solver);
    const Replay rt = replay_sparse(problems, so.solver, {}, tresca);
    const auto &a = ra.p, &b = rt.p;
    const int n_default = ra.newton, n_tresca = rt.newton;
    double scale = 0.0, diff = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        scale = std::max(scale, b[i].lpNorm<Eigen::Infinity>());
        diff = std::max(diff, (a[i] - b[i]).lpNorm<Eigen::Infinity>());
    }
    BOOST_TEST_MESSAGE("Newton iterations: default " << n_default << ", Tresca only " << n_tresca
                                                     << "; max force difference " << diff / scale);
    BOOST_TEST(n_default > 0);
    BOOST_TEST(n_tresca == 0);
    BOOST_CHECK_SMALL(diff / scale, 1e-7);
    SparsePathTuning bad;
    bad.newton_min_rows = -1;
    BOOST_CHECK_THROW(SparseContactSolver(so.solver, bad), InputError);
}

BOOST_AUTO_TEST_CASE(transition_method_of_decision_037_keeps_the_answers) {
    // The transition steps' method of decision 037 (one active-set pass before the semismooth
    // Newton method, the first pass's start without an extrapolation, the creep limit, the
    // nonmonotone line search; SparsePathMethods' defaults) against the way before
    // (SparsePathMethods::before_037) on the same problems: a graduated 10-leaf spring, 100 elements per
    // half leaf, elastic interfaces, the first 30 steps from rest at 2 m/s (the first step a
    // transition of most pairs, later ones of tens). Both confirm their final modes by the
    // active-set passes, so both answers are the exact solver's: error vector below the
    // tolerance at every step. They are not always the same answer: near pairs with force and
    // gap both ~0 this problem has several solutions to the passes' acceptance (measured: at 4
    // of the 30 steps the two end on answers with error vectors of 1e-15 to 1.2e-9 m that
    // differ at 6-57 rows, by at most 0.37 N where the largest force is 1,400 N; the other
    // steps agree to 1e-11 relative). So the forces are compared where the laws measure them,
    // in metres (|dp_i| W_ii, the motion the difference moves its own row by): within the
    // tolerance to which each is a solution (measured at most 1.8e-6 m of 2e-6 m).
    // (Every replayed solve converged: replay_sparse.)
    ModelSpec spec = testing::graduated_stack(100, 10);
    for (auto& f : spec.interfaces) f.contact = InterfaceContact::elastic;
    const System sys(Model::build(spec));
    SimulationOptions so;
    so.contact_path = ContactPath::sparse;
    ClosedFormStepper st(sys, so);
    std::vector<SparseContactProblem> problems;
    for (int i = 0; i < 30; ++i) {
        st.advance();
        problems.push_back(st.contact_solver().last_sparse_problem());
    }
    const Replay ra = replay_sparse(problems, so.solver);
    const Replay rb = replay_sparse(problems, so.solver, {}, SparsePathMethods::before_037());
    const auto &a = ra.p, &b = rb.p;
    const Eigen::VectorXd& w = ra.w;  // W's diagonal [m/N] (the same for every problem: one K and G)
    const int n_now = ra.newton, n_before = rb.newton;
    BOOST_TEST_REQUIRE(w.size() == a.front().size());
    double metres = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i)
        metres = std::max(metres, (a[i] - b[i]).cwiseAbs().cwiseProduct(w).maxCoeff());
    BOOST_TEST_MESSAGE("Newton iterations: now " << n_now << ", before " << n_before
                                                 << "; largest force difference in metres " << metres);
    BOOST_TEST(n_now > 0);
    BOOST_TEST(metres < so.solver.tolerance_m);
}
