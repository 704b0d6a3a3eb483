// The box QP of the Tresca fixed point by a primal-dual interior-point method
// (box_qp_methods.hpp).
#include <algorithm>
#include <cmath>

#include "contact/sparse/qp/box_qp_methods.hpp"

namespace stackbeam::detail::sparse {

namespace {
// iteration limit; proximal Sigma of rows without bounds and floor of every Sigma, as a
// fraction of W_ii (the Newton systems stay within ~1e8 of K's conditioning; s is
// recomputed exactly, so this only slows convergence)
constexpr int kIpmIterations = 100;
constexpr double kIpmRegularisation = 1e-8;

/// Row i's bound kind: 0 free, 1 lower only, 2 upper only, 3 both, 4 fixed (lower == upper).
bool has_bound(const std::vector<signed char>& kind, int i, bool up) {
    return up ? (kind[i] == 2 || kind[i] == 3) : (kind[i] == 1 || kind[i] == 3);
}

/// The rows' bound kinds (has_bound), and x moved strictly inside its box (the start).
std::vector<signed char> interior_start(const Eigen::VectorXd& lower, const Eigen::VectorXd& upper, Eigen::VectorXd& x) {
    const int m = static_cast<int>(x.size());
    std::vector<signed char> kind(m);  // 0 free, 1 lower only, 2 upper only, 3 both, 4 fixed
    double fscale = 0.0;               // force scale [N]
    for (int i = 0; i < m; ++i) {
        const bool hl = std::isfinite(lower[i]), hu = std::isfinite(upper[i]);
        kind[i] = hl && hu ? (lower[i] == upper[i] ? 4 : 3) : hl ? 1 : hu ? 2 : 0;
        if (hl) fscale = std::max(fscale, std::abs(lower[i]));
        if (hu) fscale = std::max(fscale, std::abs(upper[i]));
        fscale = std::max(fscale, std::abs(x[i]));
    }
    if (!(fscale > 0.0)) fscale = 1.0;
    // start: x strictly inside its box, multipliers from s at that x (at least a floor)
    for (int i = 0; i < m; ++i) {
        switch (kind[i]) {
            case 4: x[i] = lower[i]; break;
            case 3: {
                const double w = upper[i] - lower[i];
                x[i] = std::clamp(x[i], lower[i] + 0.1 * w, upper[i] - 0.1 * w);
                break;
            }
            case 1: x[i] = std::max(x[i], lower[i] + 1e-2 * fscale); break;
            case 2: x[i] = std::min(x[i], upper[i] - 1e-2 * fscale); break;
            default: break;
        }
    }
    return kind;
}

/// The working set the iterate (x; yl, gl, yu, gu) points at (at a bound where the multiplier
/// exceeds the gap, both in metres), its bounded variables put on their bounds: true (x, z set)
/// where the box QP's natural residual is then within `tolerance` in every row.
bool try_working_set(const SparseStiffness& st, const BoxQp& box, const std::vector<signed char>& kind,
                     const Eigen::VectorXd& yl, const Eigen::VectorXd& gl, const Eigen::VectorXd& yu,
                     const Eigen::VectorXd& gu, Eigen::VectorXd& x, Eigen::VectorXd& z, Eigen::VectorXd& zc,
                     std::vector<signed char>& at_bound) {
    const Eigen::VectorXd &lower = box.lower, &upper = box.upper;
    const int m = static_cast<int>(x.size());
    at_bound.assign(m, 0);
    Eigen::VectorXd xs = x;
    for (int i = 0; i < m; ++i) {
        if (kind[i] == 4) at_bound[i] = +1;
        else if (has_bound(kind, i, false) && yl[i] > st.diag[i] * gl[i]) at_bound[i] = -1;
        else if (has_bound(kind, i, true) && yu[i] > st.diag[i] * gu[i]) at_bound[i] = +1;
        if (at_bound[i] != 0) xs[i] = at_bound[i] < 0 ? lower[i] : upper[i];
    }
    const Eigen::VectorXd ss = st.positions(box.step.b, box.step.d, xs, zc);
    double worst = 0.0;
    for (int i = 0; i < m; ++i) {
        const double v = box_row_violation(i, at_bound, xs, ss, lower, upper, st.diag);
        worst = std::max(worst, at_bound[i] == 0 ? std::max(std::abs(ss[i]), v) : v);
    }
    if (worst <= box.tolerance && xs.allFinite()) {
        x = xs;
        z = zc;
        return true;
    }
    return false;
}

/// The Newton system's matrix K + G^T Sigma^-1 G (winv = Sigma^-1) factorised into
/// path.ipm_ldlt (its pattern analysed once while it stays). False where it fails.
bool factor_newton_system(SparsePath& path, const Eigen::VectorXd& winv) {
    const SparseStiffness& st = path.stiffness();
    SpMat M = st.K + SpMat(st.Gt * winv.asDiagonal() * st.Grow);
    if (!path.ipm_analysed || M.nonZeros() != path.ipm_nnz) {
        path.ipm_ldlt.analyzePattern(M);
        path.ipm_analysed = true;
        path.ipm_nnz = M.nonZeros();
    }
    path.ipm_ldlt.factorize(M);
    return path.ipm_ldlt.info() == Eigen::Success;
}
}  // namespace

/// The box QP by a primal-dual interior-point method (Mehrotra's
/// predictor-corrector): its iteration count hardly depends on how many bounds change
/// or how degenerate they are (pairs with force and gap both ~0), where block principal
/// pivoting and the primal method may need one factorisation per working-set change.
///   min 1/2 x^T W x + q^T x,  lower <= x <= upper,  W = G K^-1 G^T, q = G K^-1 b - d;
/// the gradient is s = W x + q = G z - d [m], z = K^-1 (b + G^T x). KKT conditions with
/// multipliers yl, yu >= 0 [m] and gaps gl = x - lower, gu = upper - x [N]:
///   s - yl + yu = 0,   gl yl = 0,   gu yu = 0.
/// Each iteration solves the Newton system (W + Sigma) dx = h, Sigma = yl / gl + yu / gu
/// [m/N], without W:  (K + G^T Sigma^-1 G) dz = G^T Sigma^-1 h,  dx = Sigma^-1 (h - G dz)
/// (one sparse LDL^T of the same pattern each iteration; the predictor and corrector
/// share it). s is recomputed exactly from z at every iterate, so the Newton systems'
/// round-off (Sigma spans many decades near the end) only slows it, never biases it.
/// Rows without bounds (bilateral) carry a proximal Sigma = kIpmRegularisation x W_ii.
/// End: the working set read from the iterate (at a bound where the multiplier exceeds
/// the gap, both in metres), the bounded variables put exactly on their bounds, z and s
/// recomputed, and the box QP's natural residual (in metres, as box_qp_pivoting's test) below
/// `tolerance` in every row: the answer is then the QP's to the same test as the
/// pivoting methods'. Returns false after kIpmIterations or on a failed factorisation.
bool box_qp_interior_point(SparsePath& path, const BoxQp& box, Eigen::VectorXd& x, Eigen::VectorXd& z,
                           std::vector<signed char>& at_bound, SolveResult& r) {
    const SparseStiffness& st = path.stiffness();
    const Eigen::VectorXd &b = box.step.b, &d = box.step.d, &lower = box.lower, &upper = box.upper;
    const double tolerance = box.tolerance;
    const int m = static_cast<int>(x.size());
    const std::vector<signed char> kind = interior_start(lower, upper, x);
    auto bounded = [&](int i, bool up) { return has_bound(kind, i, up); };
    Eigen::VectorXd sx = st.positions(b, d, x, z);
    const double yfloor = std::max(1e-2 * sx.lpNorm<Eigen::Infinity>(), tolerance);
    // multipliers yl, yu and gaps gl, gu; the gaps are iterated themselves (not x - bound:
    // that cancels to 0 or below near a bound)
    Eigen::VectorXd yl = Eigen::VectorXd::Zero(m), yu = Eigen::VectorXd::Zero(m);
    Eigen::VectorXd gl = Eigen::VectorXd::Zero(m), gu = Eigen::VectorXd::Zero(m);
    for (int i = 0; i < m; ++i) {
        if (bounded(i, false)) {
            yl[i] = std::max(sx[i], yfloor);
            gl[i] = x[i] - lower[i];
        }
        if (bounded(i, true)) {
            yu[i] = std::max(-sx[i], yfloor);
            gu[i] = upper[i] - x[i];
        }
    }
    Eigen::VectorXd rd(m), winv(m), h(m), dx(m), dyl(m), dyu(m), dxa(m), dyla(m), dyua(m), zc;
    // the Newton system on the stiffness's pattern plus G^T G (every row, so the pattern
    // stays and its ordering is made once per call)
    auto newton = [&](const Eigen::VectorXd& hh, Eigen::VectorXd& ddx) {
        ddx = winv.cwiseProduct(hh - st.Grow * path.ipm_ldlt.solve(st.Gt * winv.cwiseProduct(hh)));
    };
    // largest step keeping the gaps and multipliers positive (fraction to the boundary)
    auto max_step = [&](const Eigen::VectorXd& ddx, const Eigen::VectorXd& ddl, const Eigen::VectorXd& ddu) {
        double a = 1.0;
        for (int i = 0; i < m; ++i) {
            if (bounded(i, false)) {
                if (ddx[i] < 0.0) a = std::min(a, -gl[i] / ddx[i]);
                if (ddl[i] < 0.0) a = std::min(a, -yl[i] / ddl[i]);
            }
            if (bounded(i, true)) {
                if (ddx[i] > 0.0) a = std::min(a, gu[i] / ddx[i]);
                if (ddu[i] < 0.0) a = std::min(a, -yu[i] / ddu[i]);
            }
        }
        return a;
    };
    // the multipliers' changes for a given dx and complementarity targets rl, ru
    auto multipliers = [&](const Eigen::VectorXd& ddx, const Eigen::VectorXd& rl, const Eigen::VectorXd& ru,
                           Eigen::VectorXd& ddl, Eigen::VectorXd& ddu) {
        ddl.setZero(m);
        ddu.setZero(m);
        for (int i = 0; i < m; ++i) {
            if (bounded(i, false)) ddl[i] = (rl[i] - yl[i] * ddx[i]) / gl[i];
            if (bounded(i, true)) ddu[i] = (ru[i] + yu[i] * ddx[i]) / gu[i];
        }
    };
    Eigen::VectorXd rl(m), ru(m);
    // the Newton system's right-hand side h = -rd + rl / gl - ru / gu for complementarity targets rl, ru
    auto newton_rhs = [&] {
        for (int i = 0; i < m; ++i)
            h[i] = kind[i] == 4 ? 0.0 : -rd[i] + (bounded(i, false) ? rl[i] / gl[i] : 0.0) -
                                            (bounded(i, true) ? ru[i] / gu[i] : 0.0);
    };
    for (int it = 0; it < kIpmIterations; ++it) {
        // residuals: stationarity [m], complementarity [m^2] (gap x W_ii x multiplier)
        rd = sx - yl + yu;
        double comp = 0.0, comp_max = 0.0, rd_max = 0.0;
        int nb = 0;
        for (int i = 0; i < m; ++i) {
            if (kind[i] == 4) {
                rd[i] = 0.0;
                continue;
            }
            rd_max = std::max(rd_max, std::abs(rd[i]));
            if (bounded(i, false)) {
                comp += gl[i] * yl[i];
                comp_max = std::max(comp_max, gl[i] * yl[i] * st.diag[i]);
                ++nb;
            }
            if (bounded(i, true)) {
                comp += gu[i] * yu[i];
                comp_max = std::max(comp_max, gu[i] * yu[i] * st.diag[i]);
                ++nb;
            }
        }
        // close enough to try the working set it points at (each row's error ~ sqrt(gap W y))
        if (rd_max < 0.1 * tolerance && comp_max < 1e-2 * tolerance * tolerance &&
            try_working_set(st, box, kind, yl, gl, yu, gu, x, z, zc, at_bound))
            return true;
        ++r.iterations;
        ++r.factorizations;
        const double mu = nb > 0 ? comp / nb : 0.0;
        for (int i = 0; i < m; ++i) {
            double si = 0.0;
            if (bounded(i, false)) si += yl[i] / gl[i];
            if (bounded(i, true)) si += yu[i] / gu[i];  // free rows: 0, raised to the proximal floor
            winv[i] = kind[i] == 4 ? 0.0 : 1.0 / std::max(si, kIpmRegularisation * st.diag[i]);
        }
        if (!factor_newton_system(path, winv)) return false;
        // predictor (affine scaling: complementarity targets 0)
        for (int i = 0; i < m; ++i) {
            rl[i] = bounded(i, false) ? -gl[i] * yl[i] : 0.0;
            ru[i] = bounded(i, true) ? -gu[i] * yu[i] : 0.0;
        }
        newton_rhs();
        newton(h, dxa);
        multipliers(dxa, rl, ru, dyla, dyua);
        const double aa = max_step(dxa, dyla, dyua);
        double comp_aff = 0.0;
        for (int i = 0; i < m; ++i) {
            if (bounded(i, false)) comp_aff += (gl[i] + aa * dxa[i]) * (yl[i] + aa * dyla[i]);
            if (bounded(i, true)) comp_aff += (gu[i] - aa * dxa[i]) * (yu[i] + aa * dyua[i]);
        }
        const double mu_aff = nb > 0 ? comp_aff / nb : 0.0;
        const double sigma = mu > 0.0 ? std::pow(std::clamp(mu_aff / mu, 0.0, 1.0), 3) : 0.0;
        // corrector: centring sigma mu and the predictor's second-order term
        for (int i = 0; i < m; ++i) {
            rl[i] = bounded(i, false) ? sigma * mu - gl[i] * yl[i] - dxa[i] * dyla[i] : 0.0;
            ru[i] = bounded(i, true) ? sigma * mu - gu[i] * yu[i] + dxa[i] * dyua[i] : 0.0;
        }
        newton_rhs();
        newton(h, dx);
        multipliers(dx, rl, ru, dyl, dyu);
        const double a = std::min(1.0, 0.995 * max_step(dx, dyl, dyu));
        if (!(a > 0.0) || !dx.allFinite()) return false;
        x += a * dx;
        gl += a * dx;
        gu -= a * dx;
        yl += a * dyl;
        yu += a * dyu;
        for (int i = 0; i < m; ++i) {  // multipliers stay >= 0 (round-off of the step)
            if (bounded(i, false)) yl[i] = std::max(yl[i], 0.0);
            if (bounded(i, true)) yu[i] = std::max(yu[i], 0.0);
        }
        sx = st.positions(b, d, x, z);
    }
    return false;
}

}  // namespace stackbeam::detail::sparse
