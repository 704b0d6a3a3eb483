#pragma once
// Shared by the tests of the sparse path's mode solver (test_incremental_solve,
// test_fixed_pattern_lu): the graduated 6-leaf stack's contact problems (rigid and elastic
// interfaces), a random walk over its sets of modes, and the comparison of two mode solvers
// on one set against the round-off bound of their solves.
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "contact/sparse/linear/mode_solver.hpp"
#include "contact/sparse/driver/sparse_path.hpp"
#include "stackbeam/time/closed_form_stepper.hpp"
#include "stackbeam/time/simulation.hpp"
#include "test_support.hpp"

namespace stackbeam::testing::mode_walk {

namespace sp = stackbeam::detail::sparse;


// Both sides solve the same linear system of a set of modes with the same Schur complement
// (up to the order of its sums) by dense LU with one step of refinement against the explicit
// M, one directly, one through the update of another set's LU (two steps of refinement). They
// differ by round-off amplified by cond(M) (<= 1e5 here, as W's on the paper example):
// ~1e-16 x 1e5 = 1e-11 relative; the bound 1e-10 keeps a margin of 10 and still
// catches a wrong entry of M or a wrong row of the update (>= 1e-6: one changed row of a
// held set moves the forces by the row's share, O(1)).
// Where M is worse conditioned (the random sets below hold rows next to the clamps'
// and slipping pairs: rcond(M) down to ~4e-9), the bound is the round-off of a backward-
// stable solve, eps / rcond(M) with eps = 1e-16: each comparison below is made against
// max(kRel, kEps / rcond) (measured: at most 0.37 of it; 7.8e-9 relative at rcond ~2e-9).
constexpr double kRel = 1e-10;
constexpr double kEps = 1e-16;

/// A contact problem of a graduated 6-leaf spring (50 elements per half leaf, two
/// 1000 N clamps) after a few closed-form steps, rigid interfaces, on the sparse path.
inline const SparseContactProblem& stack_problem() {
    static const SparseContactProblem pr = [] {
        const System sys(Model::build(graduated_stack(50, 6)));
        SimulationOptions so;
        so.contact_path = ContactPath::sparse;
        ClosedFormStepper st(sys, so);
        for (int i = 0; i < 5; ++i) st.advance();
        return st.contact_solver().last_sparse_problem();
    }();
    return pr;
}

inline double relative_difference(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    return (a - b).lpNorm<Eigen::Infinity>() / std::max(b.lpNorm<Eigen::Infinity>(), 1e-300);
}

/// Random mode changes: each picks `changes` pairs and moves one of them: a unilateral
/// pair opens or closes; a closed pair's tangential row sticks or slips either way; a
/// clamp's tangential row is released (free) or held again. Broad contact: 85 % of the
/// pairs closed at the start, a third of the closed ones slipping.
struct ModeWalk {
    ContactProblem laws;
    modes::ModeSet modes;
    std::mt19937 rng{20261125};

    explicit ModeWalk(const SparseContactProblem& pr) {
        laws.q = Eigen::VectorXd::Zero(pr.size());
        laws.pairs = pr.pairs;
        laws.tau_rule = TauRule::current;
        const int np = static_cast<int>(pr.pairs.size());
        modes.nmode.assign(static_cast<std::size_t>(np), modes::NONE);
        modes.tmode.assign(static_cast<std::size_t>(np), modes::NONE);
        std::uniform_real_distribution<double> u(0.0, 1.0);
        for (int k = 0; k < np; ++k) {
            const auto& c = laws.pairs[static_cast<std::size_t>(k)];
            if (c.row_n >= 0)
                modes.nmode[k] = !modes::ModeSet::unilateral(c) || u(rng) < 0.85 ? modes::CLOSED : modes::OPEN;
            if (c.row_t >= 0 && c.kind != PairKind::bonded)
                modes.tmode[k] = u(rng) < 0.33 ? (u(rng) < 0.5 ? modes::SLIP_POS : modes::SLIP_NEG) : modes::STICK;
            modes.make_consistent(laws, k);
        }
    }

    void change(int changes) {
        const int np = static_cast<int>(laws.pairs.size());
        std::uniform_int_distribution<int> pick(0, np - 1), what(0, 3);
        for (int j = 0; j < changes; ++j) {
            const int k = pick(rng);
            const auto& c = laws.pairs[static_cast<std::size_t>(k)];
            const int w = what(rng);
            if (c.kind == PairKind::coulomb && c.row_n >= 0 && w == 0) {
                modes.nmode[k] = modes.nmode[k] == modes::CLOSED ? modes::OPEN : modes::CLOSED;
            } else if (c.row_t >= 0 && c.kind != PairKind::bonded) {
                const signed char next[] = {modes::STICK, modes::SLIP_POS, modes::SLIP_NEG,
                                            c.kind == PairKind::clamp ? modes::FREE : modes::STICK};
                modes.tmode[k] = next[w];
            }
            modes.make_consistent(laws, k);
        }
    }
};

struct Counts {
    int solves = 0, slip_coupled = 0;
    double largest = 0.0;  // the largest relative difference
};

/// One step of the walk: both solvers solve the walk's current set of modes (first use:
/// the whole load; then a second load on the same key: the cached affine maps), and the
/// answers are compared.
/// `bound`: the round-off bound of the comparison (default: that of the Schur way, below).
template <class Bound>
void compare(sp::ModeSolver& inc, sp::ModeSolver& ref, const ModeWalk& walk, const SparseContactProblem& pr,
             Counts& counts, double& worst, Bound bound_of) {
    modes::ModeLinearization lin;
    walk.modes.linearize(walk.laws, lin);
    const std::vector<signed char> key = walk.modes.key();
    Eigen::VectorXd pi, zi, pr_, zr;
    bool singular_i = false, singular_r = false;
    try {
        inc.solve(lin, key, pr.b, pr.d, pi, zi);
    } catch (const sp::SingularModes&) {
        singular_i = true;
        inc.forget();
    }
    try {
        ref.solve(lin, key, pr.b, pr.d, pr_, zr);
    } catch (const sp::SingularModes&) {
        singular_r = true;
        ref.forget();
    }
    BOOST_TEST_REQUIRE(singular_i == singular_r);
    if (singular_r) return;
    ++counts.solves;
    if (!lin.coupled.empty()) ++counts.slip_coupled;
    // the difference against the round-off bound of the two solves: eps / rcond(M) (M the
    // held set's Schur complement, rcond from the solve from scratch's LU)
    const double bound = bound_of(ref);
    const double d1 = std::max(relative_difference(pi, pr_), relative_difference(zi, zr));
    worst = std::max(worst, d1 / bound);
    counts.largest = std::max(counts.largest, d1);
    const Eigen::VectorXd b2 = 0.7 * pr.b;  // the same key, another load
    inc.solve(lin, key, b2, pr.d, pi, zi);
    ref.solve(lin, key, b2, pr.d, pr_, zr);
    const double d2 = std::max(relative_difference(pi, pr_), relative_difference(zi, zr));
    worst = std::max(worst, d2 / bound);
    counts.largest = std::max(counts.largest, d2);
}

inline void compare(sp::ModeSolver& inc, sp::ModeSolver& ref, const ModeWalk& walk, const SparseContactProblem& pr,
                    Counts& counts, double& worst) {
    compare(inc, ref, walk, pr, counts, worst,
            [](const sp::ModeSolver& r) { return std::max(kRel, kEps / r.schur_rcond()); });
}


/// The graduated 6-leaf spring of stack_problem() with elastic interfaces (the layer derived
/// from the leaves; the clamps stay rigid point ties), its contact problem after a few
/// closed-form steps in the layered form the mode solver takes (sp::layer_structure).
inline const SparseContactProblem& elastic_problem() {
    static const SparseContactProblem pr = [] {
        ModelSpec spec = graduated_stack(50, 6);
        for (auto& f : spec.interfaces) f.contact = InterfaceContact::elastic;
        const System sys(Model::build(spec));
        SimulationOptions so;
        so.contact_path = ContactPath::sparse;
        ClosedFormStepper st(sys, so);
        for (int i = 0; i < 5; ++i) st.advance();
        const SparseContactProblem& flat = st.contact_solver().last_sparse_problem();
        SparseContactProblem layered = flat;
        if (!sp::layer_structure(flat, layered)) throw std::logic_error("no layer rows");
        layered.b.head(flat.b.size()) = flat.b;
        return layered;
    }();
    return pr;
}

}  // namespace stackbeam::testing::mode_walk
