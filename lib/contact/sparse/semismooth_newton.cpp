// The semismooth Newton method of the sparse path on the natural map (transitions.hpp).
#include <algorithm>
#include <cmath>
#include <limits>

#include "contact/sparse/transitions.hpp"

namespace stackbeam::detail::sparse {

namespace {
// iteration limit, line-search grid (octaves of a), full steps taken although they raise
// the merit function
constexpr int kNewtonIterations = 60;
constexpr int kLineSearchOctaves = 12;
constexpr int kNewtonNonmonotone = 5;

/// The modes of a start from rest: every unilateral pair open, only the bilateral rows
/// held (clamps sticking, bonds). On identical leaves most pairs open in the first steps
/// (measured: 850 of 891 pairs at 10 leaves x 100 elements), where "all closed" (the
/// stepper's modes at rest) is the worst start.
void set_open_modes(SparsePath& path) {
    for (int k = 0; k < static_cast<int>(path.laws.pairs.size()); ++k) {
        const auto& c = path.laws.pairs[k];
        if (c.row_n >= 0) path.modes.nmode[k] = detail::ModeSet::unilateral(c) ? detail::OPEN : detail::CLOSED;
        if (c.row_t >= 0) path.modes.tmode[k] = detail::STICK;
        path.modes.make_consistent(path.laws, k);
    }
}
}  // namespace

/// Semismooth Newton method on the natural map (Alart-Curnier / Pang's natural-map
/// Newton, planar: the tangential direction is a scalar), for transitions where nearly
/// every pair changes mode (identical leaves starting from rest: forces and gaps ~0).
/// Each iteration:
///  1. the modes of the generalised Jacobian of F at the iterate (natural_residual): which
///     part of each min / clamp is active there;
///  2. the Newton step: the linear problem of those modes, s_S = 0, fixed and slip forces
///     (solve_modes: the sparse saddle-point system, its low-rank update or the Schur
///     complement, as for the active-set passes), giving (p1, z1); F is piecewise linear
///     in p, so this is the full Newton step p1 - p;
///  3. a line search on theta = ||F||^2 along it: s is affine in p, so
///     s(p + a (p1 - p)) = s + a (s1 - s) and a trial costs O(m), no solve. Where no trial
///     decreases theta the full step is taken (a non-monotone step; at most
///     kNewtonNonmonotone of them) rather than stalling.
/// From rest (p = 0) it starts from the open modes' solution (set_open_modes).
/// Unlike block principal pivoting, the modes come from p - s / w (forces and gaps
/// together), and a damped step moves every component part of the way, so many pairs
/// change per iteration without the ping-pong of full switches. Stops when every
/// component of F is within `accept` [m] (half the active-set threshold, so the passes
/// that follow see no violated mode); returns false after kNewtonIterations or on a
/// singular set of modes (p and z are then the last iterate). On entry z must be
/// K^-1 (b + G^T p).
bool semismooth_newton(SparsePath& path, const Step& step, Eigen::VectorXd& p, Eigen::VectorXd& z, SolveResult& r) {
    const SparseStiffness& st = path.stiffness();
    const Eigen::VectorXd& d = step.d;
    const int m = static_cast<int>(d.size());
    path.best_p.resize(0);
    if (m > 0 && p.isZero(0.0)) {
        // a start from rest (no force anywhere, the first step of a run): the linear problem
        // of the open modes (set_open_modes) instead of the natural map's modes at p = 0, where
        // every closed pair sits on the kink of its friction limit (tau = 0)
        set_open_modes(path);
        ++r.iterations;
        ++r.newton_iterations;
        try {
            r.factorizations += path.solve_modes(step, p, z);
        } catch (const SingularModes&) {
            path.solver.forget();
            return false;
        }
    }
    Eigen::VectorXd sk = st.Grow * z - d, F, F1, pa, sa, p1, z1, s1;
    path.natural_residual(p, sk, F, false);
    double theta = F.squaredNorm();
    int nonmonotone = 0;
    // the iterate of smallest ||F|| (where the smoothing method starts when this one fails)
    path.best_p = p;
    double best_theta = theta;
    bool full_step = false;  // p is the linear solution of the current modes
    for (int it = 0; it < kNewtonIterations; ++it) {
        const double roundoff = st.roundoff(d, z);
        const double accept = std::max(0.5 * kAccept * path.options.tolerance_m, roundoff);
        if (m == 0 || F.lpNorm<Eigen::Infinity>() <= accept) {
            // the modes for the passes that follow: those of the last full step (its linear
            // problem gave p, so the passes reuse its factorisation), else those at p
            if (!full_step) path.natural_residual(p, sk, F, true);
            return true;
        }
        ++r.iterations;
        ++r.newton_iterations;
        path.natural_residual(p, sk, F, true);
        p1 = p;
        try {
            r.factorizations += path.solve_modes(step, p1, z1);
        } catch (const SingularModes&) {
            path.solver.forget();
            return false;
        }
        s1 = st.Grow * z1 - d;
        // line search: the smallest theta on the grid a = 2^(-j/4), j = 0 .. 4 kLineSearchOctaves
        // (each trial O(m)); theta is piecewise quadratic along the step with many kinks
        // (every component that changes branch), so the grid's best point is taken rather
        // than the first that passes Armijo's test (measured: 26 instead of 48 iterations
        // on the first step of 10 leaves x 100 elements). Where no trial lowers theta, the
        // full step is taken (non-monotone; at most kNewtonNonmonotone times).
        double a = 1.0, grid_theta = std::numeric_limits<double>::infinity();
        for (int j = 0; j <= 4 * kLineSearchOctaves; ++j) {
            const double aj = std::pow(2.0, -0.25 * j);
            pa = p + aj * (p1 - p);
            sa = sk + aj * (s1 - sk);
            path.natural_residual(pa, sa, F1, false);
            const double tj = F1.squaredNorm();
            if (tj < grid_theta) {
                grid_theta = tj;
                a = aj;
            }
        }
        if (!(grid_theta < theta)) {
            if (++nonmonotone > kNewtonNonmonotone) break;
            a = 1.0;
        }
        full_step = a == 1.0;
        if (full_step) {
            p = p1;
            z = z1;
            sk = s1;
        } else {
            p += a * (p1 - p);
            z += a * (z1 - z);
            sk += a * (s1 - sk);
        }
        path.natural_residual(p, sk, F, false);
        theta = F.squaredNorm();
        if (theta < best_theta) {
            best_theta = theta;
            path.best_p = p;
        }
    }
    return false;
}

}  // namespace stackbeam::detail::sparse
