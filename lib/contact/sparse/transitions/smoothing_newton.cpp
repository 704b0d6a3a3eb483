// The smoothing Newton method of the sparse path on the natural map (transitions.hpp).
#include <algorithm>
#include <cmath>
#include <vector>

#include "contact/sparse/transitions/transitions.hpp"

namespace stackbeam::detail::sparse {

namespace {
// iteration limit, first smoothing as a fraction of the natural residual, the smoothing
// kept at most this fraction of the natural residual, Armijo's constant and the number of
// halvings of the step length tried; iterations without a 10 % fall of the natural residual
constexpr int kSmoothIterations = 80;
constexpr double kSmoothStart = 0.1;
constexpr double kSmoothTrack = 0.2;
constexpr double kArmijo = 1e-4;
constexpr int kSmoothHalvings = 40;
constexpr int kSmoothStall = 15;

// Chen-Harker-Kanzow-Smale smoothing of max(0, y): smax(y, e) = (y + sqrt(y^2 + 4 e^2)) / 2,
// smooth for e > 0, within e of max(0, y), and equal to it for e = 0.
double smax(double y, double e) { return 0.5 * (y + std::sqrt(y * y + 4.0 * e * e)); }
double dsmax(double y, double e) {
    const double r = std::sqrt(y * y + 4.0 * e * e);
    return r > 0.0 ? 0.5 * (1.0 + y / r) : 0.5;
}
/// One row of the smoothed map's Jacobian: dF_i = alpha dp_i + beta ds_i + gamma dp_ncol.
struct SmoothRow {
    double alpha = 0.0, beta = 1.0, gamma = 0.0;
    int ncol = -1;  // the pair's normal row (tangential rows of friction pairs), else -1
};

/// The natural map of natural_residual with every max(0, .) (and so every min and clamp,
/// and the friction limit's tau) smoothed by smax with e = eps_m / w (w = W_ii of the
/// row, so eps_m is in metres like F): F_eps is smooth for eps_m > 0, within about
/// eps_m of F per component, and F_0 is the natural map (natural_residual). Per component:
///   unilateral normal  F = w (p_n + smax(s_n / w - p_n, e))         (= w (p_n - min(0, a)))
///   tangential         F = w (p_t - clip(a)),  a = p_t - s_t / w,
///                      clip(a) = -L + smax(a + L, e) - smax(a - L, e),  L = mu tau_eps(p_n)
///                      (tau_eps = smax(-p_n) for Coulomb, smax(F_c - p_n) for clamps)
///   bilateral, bonded  F = s.
/// With `jac`, the coefficients of its Jacobian per row. The previous step's tau rule
/// has a constant limit (gamma = 0).
void smoothed_residual(const SparsePath& path, const Eigen::VectorXd& p, const Eigen::VectorXd& s, double eps_m,
                       Eigen::VectorXd& F, std::vector<SmoothRow>* jac) {
    const SparseStiffness& st = path.stiffness();
    F = s;
    if (jac) jac->assign(static_cast<std::size_t>(s.size()), SmoothRow{});
    const bool prev = path.laws.tau_rule == TauRule::previous_step;
    for (int k = 0; k < static_cast<int>(path.laws.pairs.size()); ++k) {
        const auto& c = path.laws.pairs[k];
        if (c.row_n >= 0 && c.kind == PairKind::coulomb) {
            const double w = st.diag[c.row_n], pn = p[c.row_n], y = s[c.row_n] / w - pn, e = eps_m / w;
            F[c.row_n] = w * (pn + smax(y, e));
            if (jac) {
                const double D = dsmax(y, e);  // dF = w (1 - D) dp_n + D ds_n
                (*jac)[c.row_n] = SmoothRow{w * (1.0 - D), D, 0.0, -1};
            }
        }
        if (c.row_t < 0 || c.kind == PairKind::bonded) continue;
        const double w = st.diag[c.row_t], pt = p[c.row_t], e = eps_m / w, a = pt - s[c.row_t] / w;
        double tau = 0.0, dtau = 0.0;  // tau and d tau / d p_n
        if (prev) {
            tau = friction_normal_force(path.laws, k, p);
        } else if (c.row_n >= 0) {
            const double en = eps_m / st.diag[c.row_n];
            const double y = (c.kind == PairKind::clamp ? c.preload_n : 0.0) - p[c.row_n];
            tau = smax(y, en);
            dtau = -dsmax(y, en);
        } else {
            tau = c.kind == PairKind::clamp ? c.preload_n : 0.0;
        }
        const double mu = c.friction_coefficient, L = mu * tau;
        const double hi = smax(a + L, e), lo = smax(a - L, e);
        F[c.row_t] = w * (pt - (-L + hi - lo));
        if (jac) {
            const double dh = dsmax(a + L, e), dl = dsmax(a - L, e);
            const double Ca = dh - dl, CL = -1.0 + dh + dl;  // d clip / da, d clip / dL
            (*jac)[c.row_t] = SmoothRow{w * (1.0 - Ca), Ca, -w * CL * mu * dtau, prev ? -1 : c.row_n};
        }
    }
}

/// The Newton step of the smoothed map, J dp = -F with J = A + B W (A: alpha on the
/// diagonal and gamma at (t, n); B = diag(beta)), without W: with dz = K^-1 G^T dp,
///     [ K      -G^T ] [dz]   [ 0]
///     [ B G     A   ] [dp] = [-F],
/// scaled like solve_modes (dz = Dz y, dp_i = pi_i / h_i and contact row i divided by
/// h_i, h_i = ||G_i Dz||). Its pattern does not depend on the iterate, so the LU's
/// ordering is made once per (K, G) and every iteration is one numeric factorisation.
/// A row whose component is held (beta = 1, alpha = 0), open (alpha = w, beta = 0) or
/// in between (a component near its kink: both ~ 1/2) is regular, which is what the
/// natural map's generalised Jacobian lacks near a degenerate solution.
bool smoothing_direction(SparsePath& path, const std::vector<SmoothRow>& J, const Eigen::VectorXd& F,
                         Eigen::VectorXd& dp, Eigen::VectorXd& dzv) {
    const SparseStiffness& st = path.stiffness();
    const int n = static_cast<int>(st.K.rows()), m = static_cast<int>(F.size());
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(static_cast<std::size_t>(st.K.nonZeros() + 2 * st.G.nonZeros() + 2 * m));
    st.append_scaled_K(t);
    for (int i = 0; i < m; ++i) {
        const double hi = st.row_h[i];
        for (SpMat::InnerIterator it(st.Gt_scaled, i); it; ++it) {
            t.emplace_back(it.row(), n + i, -it.value() / hi);
            t.emplace_back(n + i, it.row(), J[i].beta * it.value() / hi);
        }
        t.emplace_back(n + i, n + i, J[i].alpha / (hi * hi));
        if (J[i].ncol >= 0) t.emplace_back(n + i, n + J[i].ncol, J[i].gamma / (hi * st.row_h[J[i].ncol]));
    }
    path.Js.resize(n + m, n + m);
    path.Js.setFromTriplets(t.begin(), t.end());
    path.Js.makeCompressed();
    if (!path.js_analysed) {
        path.js_lu->analyze(path.Js);
        path.js_analysed = true;
    }
    if (!path.js_lu->factorize(path.Js)) return false;
    Eigen::VectorXd rhs_s = Eigen::VectorXd::Zero(n + m);
    for (int i = 0; i < m; ++i) rhs_s[n + i] = -F[i] / st.row_h[i];
    Eigen::VectorXd y = rhs_s;  // one step of iterative refinement
    if (!path.js_lu->refined_solve(path.Js, y) || !y.allFinite()) return false;
    dzv = st.dz.cwiseProduct(y.head(n));
    dp = y.tail(m).cwiseQuotient(st.row_h);
    return true;
}

}  // namespace

/// Smoothing Newton method (Chen, Qi and Sun's Jacobian smoothing with a continuation on
/// the smoothing, here on the natural map of eq. 8): for transitions where the semismooth
/// Newton method stalls, i.e. near a degenerate solution (identical leaves: many
/// components with force and gap both ~0). There the natural map has kinks next to the
/// iterate, so ||F||^2 has no descent along the semismooth step and that method's
/// generalised Jacobians (every component either held or free) become near-singular.
/// F_eps (smoothed_residual) has neither problem: ||F_eps||^2 is differentiable, the
/// Newton step of F_eps is a descent direction for it, so Armijo's backtracking always
/// finds a step, and a component at its kink enters its row half held, half free.
/// Each iteration: one sparse LU of the Jacobian's saddle-point system
/// (smoothing_direction), an Armijo search on ||F_eps||^2 (s is affine in p: O(m) per
/// trial), then eps_m = min(eps_m, kSmoothTrack ||F_0||_inf), so the smoothing falls
/// with the natural residual (geometrically once F_eps is solved: ||F_0|| <= ||F_eps||
/// + ~2 eps_m). Stops when every component of the natural map is within `accept` (as the
/// semismooth method) and leaves the modes at p for the passes that follow; false
/// after kSmoothIterations or when no step length lowers the merit. On entry z must be
/// K^-1 (b + G^T p).
bool smoothing_newton(SparsePath& path, const Step& step, Eigen::VectorXd& p, Eigen::VectorXd& z, SolveResult& r) {
    const SparseStiffness& st = path.stiffness();
    const Eigen::VectorXd& d = step.d;
    const int m = static_cast<int>(d.size());
    if (m == 0) return true;
    Eigen::VectorXd sk = st.Grow * z - d, F, Fn, Ft, dp, dzv, ds, pa, sa;
    std::vector<SmoothRow> J;
    path.natural_residual(p, sk, Fn, false);
    double nat = Fn.lpNorm<Eigen::Infinity>();
    double eps = kSmoothStart * nat, best = nat;
    int since_best = 0;
    for (int it = 0; it <= kSmoothIterations; ++it) {
        const double roundoff = st.roundoff(d, z);
        const double accept = std::max(0.5 * kAccept * path.options.tolerance_m, roundoff);
        if (nat <= accept) {
            path.s = sk;
            path.natural_residual(p, sk, F, true);  // the modes at p, for the passes that follow
            return true;
        }
        if (it == kSmoothIterations || since_best >= kSmoothStall) break;
        ++r.iterations;
        ++r.smoothing_iterations;
        eps = std::max(eps, 0.1 * accept);
        smoothed_residual(path, p, sk, eps, F, &J);
        const double theta = F.squaredNorm();
        ++r.factorizations;
        if (!smoothing_direction(path, J, F, dp, dzv)) return false;
        ds = st.Grow * dzv;
        // Armijo's backtracking on theta = ||F_eps||^2 (the exact Newton step of a smooth map is
        // a descent direction: d theta / da = -2 theta at a = 0)
        double a = 1.0;
        bool found = false;
        for (int j = 0; j < kSmoothHalvings && !found; ++j) {
            if (j > 0) a *= 0.5;
            pa = p + a * dp;
            sa = sk + a * ds;
            smoothed_residual(path, pa, sa, eps, Ft, nullptr);
            found = Ft.squaredNorm() <= (1.0 - 2.0 * kArmijo * a) * theta;
        }
        if (!found) return false;
        p = pa;
        sk = sa;
        z += a * dzv;
        path.natural_residual(p, sk, Fn, false);
        nat = Fn.lpNorm<Eigen::Infinity>();
        eps = std::min(eps, kSmoothTrack * nat);
        // a stall (measured at 10 leaves x 400 elements: a local minimum of ||F_eps|| where
        // its Jacobian is near-singular, the slip coupling's doing) is given up early
        if (nat < 0.9 * best) {
            best = nat;
            since_best = 0;
        } else {
            ++since_best;
        }
    }
    return false;
}

}  // namespace stackbeam::detail::sparse
