#pragma once
// Internal: the active-set algorithms on the modes (stackbeam/contact/modes.hpp) shared by the
// dense `exact` solver (contact/exact.cpp) and the sparse path (contact/sparse/driver/sparse_solver.cpp):
// the passes (block principal pivoting, Murty's rule), Anderson mixing and the Tresca fixed
// point. What is path-specific is only how a set of modes' linear problem is solved and how
// s = W p + q is evaluated: this file needs s and the diagonal of W, never W itself.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "stackbeam/contact/contact.hpp"
#include "stackbeam/contact/modes.hpp"

namespace stackbeam::detail {

/// Active-set passes from the current modes; true when no mode is violated.
/// Block principal pivoting (Judice & Pires): switch every violated mode while the
/// number of violations falls; when it has not fallen for `budget_passes` passes,
/// switch only the first violated one (Murty's least-index rule, finite for P-matrices).
/// `solve_modes(p)` solves the linear problem of the modes into p and returns the
/// number of factorisations it made; `violations(p)` returns modes.count_violations(...).
template <class SolveModes, class Violations>
bool active_set_passes(modes::ModeSet& modes, const ContactProblem& pr, Eigen::VectorXd& p, int max_passes,
                       int budget_passes, SolveResult& r, SolveModes solve_modes, Violations violations) {
    int best = std::numeric_limits<int>::max(), budget = budget_passes;
    bool single = false;
    for (int pass = 1; pass <= max_passes; ++pass) {
        ++r.iterations;
        r.factorizations += solve_modes(p);
        const int v = violations(p);
        if (v == 0) return true;
        if (v < best) {
            best = v;
            budget = budget_passes;
            single = false;
        } else if (budget > 0) {
            --budget;
        } else {
            single = true;
        }
        modes.apply_switches(pr, single);
    }
    return false;
}

/// Anderson acceleration (type II) of a fixed point x = g(x) on the friction limits,
/// in the scaled variables y = scale * x [m] (entries with scale 0 take x = g, unmixed).
/// next(scale, g, x): given g(x) at the current x, replaces x by the next iterate,
///     y+ = g_y - dG gamma,  gamma = argmin || f - dF gamma ||_2,  f = g_y - y,
/// over the last `depth` differences dF, dG, then projects on x >= 0 (limits are forces).
class AndersonMixer {
public:
    AndersonMixer(int n, int depth) : depth_(depth), dF_(n, depth), dG_(n, depth) {}

    void next(const Eigen::VectorXd& scale, const Eigen::VectorXd& g, Eigen::VectorXd& x) {
        const Eigen::Index n = x.size();
        Eigen::VectorXd gy(n), f(n);
        for (Eigen::Index k = 0; k < n; ++k) {
            gy[k] = scale[k] != 0.0 ? scale[k] * g[k] : 0.0;
            f[k] = scale[k] != 0.0 ? gy[k] - scale[k] * x[k] : 0.0;
        }
        Eigen::VectorXd y = gy;
        if (depth_ > 0 && f_.size() == n) {
            const int slot = count_ % depth_;  // ring buffer of the last `depth` differences
            dF_.col(slot) = f - f_;
            dG_.col(slot) = gy - g_;
            ++count_;
            const int m = std::min(count_, depth_);
            const Eigen::VectorXd gamma = dF_.leftCols(m).colPivHouseholderQr().solve(f);
            if (gamma.allFinite()) y -= dG_.leftCols(m) * gamma;
        }
        const bool mixed = count_ > 0;
        f_ = f;
        g_ = gy;
        for (Eigen::Index k = 0; k < n; ++k)
            x[k] = mixed && scale[k] != 0.0 ? std::max(0.0, y[k] / scale[k]) : g[k];
    }

private:
    int depth_;
    int count_ = 0;
    Eigen::MatrixXd dF_, dG_;  // differences of f and of g_y [m], one column per iteration
    Eigen::VectorXd f_, g_;    // the last f and g_y
};

/// The Tresca fixed point of the exact solvers (dense and sparse): each pass solves
/// the problem with the friction limits frozen, a box-constrained convex QP (unilateral
/// normals in (-inf, 0], held at 0 when open; tangential rows in [-mu tau, mu tau],
/// held at their bound while slipping); the limits are updated from its normal forces
/// until they settle to `accept` (in metres: the change of mu tau times W's diagonal);
/// its final working set then gives the modes, and slip forces are put at the limit of
/// the final tau. Returns true when the limits settled within `max_iterations` passes.
///
/// The limits are updated by Anderson acceleration of depth `anderson_depth` (0: the plain
/// fixed point tau <- tau(p)). The map from limits to normal forces is piecewise affine
/// (affine while the box QP's working set stays); on fine meshes its contraction factor
/// nears 1 (neighbouring pairs' normal forces are nearly interchangeable), and the plain
/// update creeps or oscillates there: graduated 10 leaves x 100 elements, steps that ran all
/// 100 passes unsettled now settle in 10-13 (docs/decisions/007-anderson-acceleration.md). The mixing works on the
/// limits in metres, y = mu tau W_tt (the measure `accept` uses), and is projected on tau >= 0.
///   Anderson, J. ACM 12 (1965); Walker & Ni, SIAM J. Numer. Anal. 49 (2011), type II.
///   box_solve(lower, upper, at_bound) -> bool   solves the box QP into p (the path's
///                                                own start, factorisations, counters)
///   diagonal(row) -> W_row,row [m/N]
///   tangential_s(row) -> s_row at the final p   (only where a box of zero width, tau = 0
///                                                in the last QP, held a force without a sign)
template <class BoxSolve, class Diagonal, class TangentialS>
bool tresca_fixed_point(modes::ModeSet& modes, const ContactProblem& pr, int n, Eigen::VectorXd& p, double accept,
                        int max_iterations, int anderson_depth, BoxSolve box_solve, Diagonal diagonal,
                        TangentialS tangential_s) {
    const int np = static_cast<int>(pr.pairs.size());
    const double inf = std::numeric_limits<double>::infinity();
    Eigen::VectorXd lower = Eigen::VectorXd::Constant(n, -inf), upper = Eigen::VectorXd::Constant(n, inf);
    std::vector<signed char> at_bound(n, 0);
    for (int k = 0; k < np; ++k) {
        const auto& c = pr.pairs[k];
        if (c.row_n >= 0 && modes::ModeSet::unilateral(c)) {
            upper[c.row_n] = 0.0;
            if (modes.nmode[k] == modes::OPEN) at_bound[c.row_n] = +1;
        }
        if (c.row_t >= 0 && (modes.tmode[k] == modes::SLIP_POS || modes.tmode[k] == modes::SLIP_NEG))
            at_bound[c.row_t] = modes.tmode[k] == modes::SLIP_POS ? +1 : -1;
    }
    Eigen::VectorXd tau(np), scale_m = Eigen::VectorXd::Zero(np);  // scale_m = mu W_tt [m/N]
    std::vector<char> limited(np, 0);  // pairs with a friction limit (a tangential row, not bonded)
    for (int k = 0; k < np; ++k) {
        const auto& c = pr.pairs[k];
        tau[k] = friction_normal_force(pr, k, p);
        limited[k] = c.row_t >= 0 && c.kind != PairKind::bonded;
        if (limited[k]) scale_m[k] = c.friction_coefficient * diagonal(c.row_t);
    }
    AndersonMixer mixer(np, anderson_depth);
    Eigen::VectorXd g = tau;
    for (int it = 0; it < max_iterations; ++it) {
        for (int k = 0; k < np; ++k) {
            if (!limited[k]) continue;
            const auto& c = pr.pairs[k];
            const double limit = c.friction_coefficient * tau[k];
            lower[c.row_t] = -limit;
            upper[c.row_t] = limit;
        }
        if (!box_solve(lower, upper, at_bound)) return false;
        double change_m = 0.0;
        for (int k = 0; k < np; ++k) {
            if (!limited[k]) continue;
            g[k] = friction_normal_force(pr, k, p);
            change_m = std::max(change_m, scale_m[k] * std::abs(g[k] - tau[k]));
        }
        if (change_m > accept) {
            mixer.next(scale_m, g, tau);
            continue;
        }
        // modes from the working set; slip forces put at the limit of the final tau, g
        // (the normal forces of the last box QP; setting p's tangential rows leaves them)
        for (int k = 0; k < np; ++k) {
            const auto& c = pr.pairs[k];
            if (c.row_n >= 0 && modes::ModeSet::unilateral(c))
                modes.nmode[k] = at_bound[c.row_n] == +1 ? modes::OPEN : modes::CLOSED;
            if (!limited[k]) continue;
            const double limit = c.friction_coefficient * g[k];
            if (limit <= 0.0) {
                modes.tmode[k] = modes::FREE;
                p[c.row_t] = 0.0;
            } else if (at_bound[c.row_t] != 0) {
                // slip against the motion; a box that had zero width (tau was 0 in the
                // last QP) held the force without a sign: take it from s_t.
                const signed char sigma = lower[c.row_t] < upper[c.row_t] ? at_bound[c.row_t]
                                                                          : (tangential_s(c.row_t) > 0.0 ? -1 : +1);
                modes.tmode[k] = sigma > 0 ? modes::SLIP_POS : modes::SLIP_NEG;
                p[c.row_t] = sigma * limit;
            } else {
                modes.tmode[k] = modes::STICK;
            }
            modes.make_consistent(pr, k);
        }
        return true;
    }
    return false;
}

}  // namespace stackbeam::detail
