// Fancher's leaf-spring model and its least-squares fit to a loop (fancher.hpp,
// docs/reduced-model.md, docs/decisions/023-fancher-fit-and-fuzzing.md).
#include "stackbeam/post/fancher.hpp"

#include <Eigen/Dense>
#include <unsupported/Eigen/NonLinearOptimization>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "stackbeam/errors.hpp"

namespace stackbeam {

namespace {

/// The parameters as the recursion uses them: the two envelopes and beta.
struct Law {
    double ku, cu, kl, cl, beta;
};

Law law_of(const FancherParameters& p) {
    if (!(p.beta_m > 0.0) || !std::isfinite(p.beta_m))
        throw InputError("beta_m", "value " + format_value(p.beta_m) + " is not allowed: the decay length [m] must be > 0 and finite");
    return {p.upper_rate_n_per_m, p.upper_offset_n, p.lower_rate_n_per_m, p.lower_offset_n, p.beta_m};
}

/// d/d(ku, cu, kl, cl, ln beta) of a force.
using Grad = std::array<double, 5>;

/// One step from (w0, f0) to w1, with the gradient `g` of f0 carried to the result when
/// `g` is given: the deviation from the active envelope E decays with the travel,
/// F = E(w1) + (f0 - E(w0)) e, e = exp(-|w1 - w0|/beta), de/d(ln beta) = e |dw|/beta.
double step(const Law& m, double w0, double f0, double w1, Grad* g) {
    const double dw = w1 - w0;
    if (dw == 0.0) return f0;  // w does not move: neither does F (and its gradient)
    const bool up = dw > 0.0;
    const double rate = up ? m.ku : m.kl, offset = up ? m.cu : m.cl;
    const double deviation = f0 - (rate * w0 + offset);
    const double travel = std::abs(dw);
    const double e = std::exp(-travel / m.beta);
    if (g) {
        Grad& d = *g;
        for (double& x : d) x *= e;
        d[up ? 0 : 2] += w1 - e * w0;
        d[up ? 1 : 3] += 1.0 - e;
        d[4] += deviation * e * travel / m.beta;
    }
    return rate * w1 + offset + deviation * e;
}

/// The periodic start (the fixed point of one pass over w, closed back to w[0]) and
/// its gradient when `g` is given.
double periodic_start(const Law& m, const std::vector<double>& w, Grad* g) {
    // one pass from F = 0 (gradient 0) gives b, db; the pass is affine in its start
    // with slope a = exp(-travel/beta) (each step multiplies the start by its e)
    double b = 0.0, travel = 0.0;
    Grad db{};
    const std::size_t n = w.size();
    for (std::size_t i = 1; i <= n; ++i) {
        const double w0 = w[i - 1], w1 = w[i % n];
        b = step(m, w0, b, w1, g ? &db : nullptr);
        travel += std::abs(w1 - w0);
    }
    const double a = std::exp(-travel / m.beta);
    const double start = b / (1.0 - a);
    if (g) {
        for (int k = 0; k < 5; ++k) (*g)[k] = db[k] / (1.0 - a);
        (*g)[4] += b * (a * travel / m.beta) / ((1.0 - a) * (1.0 - a));  // da/d(ln beta) = a travel/beta
    }
    return start;
}

/// The model along w from its periodic start: F (n) and, when `jac` is given, the
/// n x 5 Jacobian d F / d(ku, cu, kl, cl, ln beta).
Eigen::VectorXd periodic_path(const Law& m, const std::vector<double>& w, Eigen::MatrixXd* jac) {
    const std::size_t n = w.size();
    Eigen::VectorXd f(static_cast<Eigen::Index>(n));
    Grad g{};
    double force = periodic_start(m, w, jac ? &g : nullptr);
    for (std::size_t i = 0; i < n; ++i) {
        if (i > 0) force = step(m, w[i - 1], force, w[i], jac ? &g : nullptr);
        const auto r = static_cast<Eigen::Index>(i);
        f(r) = force;
        if (jac)
            for (int k = 0; k < 5; ++k) (*jac)(r, k) = g[k];
    }
    return f;
}

// The fit works on the loop scaled to unit ranges, w' = (w - w_c)/W, F' = (F - F_c)/R,
// so that its tolerances and the scan of beta are the same for every spring.
constexpr double kLogBetaMin = -11.512925464970229;  // ln 1e-5: beta' below this is a switch at the sample
constexpr double kLogBetaMax = 6.907755278982137;    // ln 1e3: beyond, the approach is a straight line

/// ln beta' clamped to [1e-5, 1e3] (the Levenberg-Marquardt steps are not bounded).
double beta_of(double log_beta) { return std::exp(std::clamp(log_beta, kLogBetaMin, kLogBetaMax)); }

/// The least-squares problem in Eigen's functor form: x = (ku', cu', kl', cl', ln beta').
struct Residuals {
    using Scalar = double;
    using InputType = Eigen::VectorXd;
    using ValueType = Eigen::VectorXd;
    using JacobianType = Eigen::MatrixXd;
    enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };

    const std::vector<double>& w;
    const Eigen::VectorXd& f;

    int inputs() const { return 5; }
    int values() const { return static_cast<int>(f.size()); }
    static Law law(const Eigen::VectorXd& x) { return {x(0), x(1), x(2), x(3), beta_of(x(4))}; }
    int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& r) const {
        r = periodic_path(law(x), w, nullptr) - f;
        return 0;
    }
    int df(const Eigen::VectorXd& x, Eigen::MatrixXd& jac) const {
        jac.resize(f.size(), 5);
        periodic_path(law(x), w, &jac);
        return 0;
    }
};

/// The scan's start: for each beta' of a log grid, the model is linear in the
/// envelopes (F = A(beta) theta: the periodic start is linear in them too), so
/// theta(beta) is a linear least-squares solution; the beta' of least residual wins.
Eigen::VectorXd scan_start(const std::vector<double>& w, const Eigen::VectorXd& f) {
    constexpr int kGrid = 57;  // 1e-5 .. 1e3, 7 points per decade
    const auto n = static_cast<Eigen::Index>(w.size());
    Eigen::VectorXd best(5);
    double best_sse = std::numeric_limits<double>::infinity();
    Eigen::MatrixXd a(n, 4);
    for (int k = 0; k < kGrid; ++k) {
        const double log_beta = kLogBetaMin + (kLogBetaMax - kLogBetaMin) * k / (kGrid - 1);
        const double beta = std::exp(log_beta);
        for (int j = 0; j < 4; ++j) {  // column j: the model with envelope parameter j = 1, the others 0
            Law unit{0.0, 0.0, 0.0, 0.0, beta};
            (j == 0 ? unit.ku : j == 1 ? unit.cu : j == 2 ? unit.kl : unit.cl) = 1.0;
            a.col(j) = periodic_path(unit, w, nullptr);
        }
        const Eigen::Vector4d theta = a.colPivHouseholderQr().solve(f);
        const double sse = (a * theta - f).squaredNorm();
        if (sse < best_sse) {  // strict: the first of equal ones, deterministic
            best_sse = sse;
            best << theta, log_beta;
        }
    }
    return best;
}

void check_samples(const std::vector<double>& v, const char* field, const char* what) {
    for (std::size_t i = 0; i < v.size(); ++i)
        if (!std::isfinite(v[i]))
            throw InputError(std::string(field) + "[" + std::to_string(i) + "]",
                             "value " + format_value(v[i]) + " is not allowed: " + what + " must be finite");
}

}  // namespace

double fancher_step(const FancherParameters& p, double w_previous_m, double force_previous_n, double w_m) {
    return step(law_of(p), w_previous_m, force_previous_n, w_m, nullptr);
}

std::vector<double> fancher_force(const FancherParameters& p, const std::vector<double>& w_m, double start_force_n) {
    const Law m = law_of(p);
    check_samples(w_m, "w_m", "the deflection");
    std::vector<double> f(w_m.size());
    double force = start_force_n;
    for (std::size_t i = 0; i < w_m.size(); ++i) {
        if (i > 0) force = step(m, w_m[i - 1], force, w_m[i], nullptr);
        f[i] = force;
    }
    return f;
}

double fancher_periodic_start_force(const FancherParameters& p, const std::vector<double>& w_m) {
    const Law m = law_of(p);
    check_samples(w_m, "w_m", "the deflection");
    if (w_m.empty()) throw InputError("w_m", "is empty: the path needs at least one sample");
    return periodic_start(m, w_m, nullptr);
}

FancherFit fit_fancher(const std::vector<double>& w_m, const std::vector<double>& force_n) {
    if (w_m.size() != force_n.size())
        throw InputError("force_n", "has " + std::to_string(force_n.size()) + " samples, w_m " + std::to_string(w_m.size()) +
                                        ": one force per deflection");
    if (w_m.size() < 8)
        throw InputError("w_m", "has " + std::to_string(w_m.size()) + " samples: a loop to fit needs at least 8");
    check_samples(w_m, "w_m", "the deflection");
    check_samples(force_n, "force_n", "the force");
    int ups = 0, downs = 0;
    for (std::size_t i = 1; i < w_m.size(); ++i) {
        ups += w_m[i] > w_m[i - 1];
        downs += w_m[i] < w_m[i - 1];
    }
    if (ups < 2 || downs < 2)
        throw InputError("w_m", "moves up in " + std::to_string(ups) + " and down in " + std::to_string(downs) +
                                    " steps: a loop needs at least 2 of each (one envelope each way)");
    const auto [w_lo, w_hi] = std::minmax_element(w_m.begin(), w_m.end());
    const auto [f_lo, f_hi] = std::minmax_element(force_n.begin(), force_n.end());
    const double w_range = *w_hi - *w_lo, w_mid = 0.5 * (*w_hi + *w_lo);
    const double f_range = *f_hi - *f_lo, f_mid = 0.5 * (*f_hi + *f_lo);
    if (!(f_range > 0.0))
        throw InputError("force_n", "is " + format_value(*f_lo) + " at every sample: no loop to fit");

    // the scaled loop
    std::vector<double> w(w_m.size());
    Eigen::VectorXd f(static_cast<Eigen::Index>(w_m.size()));
    for (std::size_t i = 0; i < w_m.size(); ++i) {
        w[i] = (w_m[i] - w_mid) / w_range;
        f(static_cast<Eigen::Index>(i)) = (force_n[i] - f_mid) / f_range;
    }
    Eigen::VectorXd x = scan_start(w, f);
    Residuals residuals{w, f};
    Eigen::LevenbergMarquardt<Residuals> lm(residuals);
    lm.parameters.ftol = 1e-14;  // relative reduction of the sum of squares: to round-off
    lm.parameters.xtol = 1e-13;  // relative change of x: parameters to ~1e-12 when the residual vanishes
    lm.parameters.gtol = 0.0;
    lm.parameters.maxfev = 500;  // typically 10-30 evaluations from the scan's start
    const Eigen::LevenbergMarquardtSpace::Status status = lm.minimize(x);

    FancherFit fit;
    fit.iterations = static_cast<int>(lm.iter);
    fit.function_evaluations = static_cast<int>(lm.nfev);
    using S = Eigen::LevenbergMarquardtSpace::Status;
    // the tolerance stops, including "cannot reduce further" at machine precision
    fit.converged = status == S::RelativeReductionTooSmall || status == S::RelativeErrorTooSmall ||
                    status == S::RelativeErrorAndReductionTooSmall || status == S::CosinusTooSmall ||
                    status == S::FtolTooSmall || status == S::XtolTooSmall || status == S::GtolTooSmall;
    // back to physical units: F = F_c + R (k' (w - w_c)/W + c')
    const Law m = Residuals::law(x);
    FancherParameters& p = fit.parameters;
    p.upper_rate_n_per_m = m.ku * f_range / w_range;
    p.upper_offset_n = f_mid + f_range * m.cu - p.upper_rate_n_per_m * w_mid;
    p.lower_rate_n_per_m = m.kl * f_range / w_range;
    p.lower_offset_n = f_mid + f_range * m.cl - p.lower_rate_n_per_m * w_mid;
    p.beta_m = m.beta * w_range;
    // the error in physical units, from the physical parameters (what a user evaluates)
    fit.start_force_n = fancher_periodic_start_force(p, w_m);
    const std::vector<double> model = fancher_force(p, w_m, fit.start_force_n);
    double sse = 0.0;
    for (std::size_t i = 0; i < w_m.size(); ++i) sse += (model[i] - force_n[i]) * (model[i] - force_n[i]);
    fit.rms_error_n = std::sqrt(sse / static_cast<double>(w_m.size()));
    fit.rms_error_relative = fit.rms_error_n / f_range;
    return fit;
}

namespace {

/// w and F of the records with t in [t_start_s, t_end_s] (hysteresis_metrics' selection).
void loop_samples(const std::vector<StepRecord>& records, double t_start_s, double t_end_s, std::vector<double>& w,
                  std::vector<double>& f) {
    const double eps = 1e-9 * std::max(1.0, std::abs(t_end_s));
    for (const auto& r : records)
        if (r.t_s >= t_start_s - eps && r.t_s <= t_end_s + eps) {
            w.push_back(r.w_m);
            f.push_back(r.spring_force_n);
        }
}

}  // namespace

FancherFit fit_fancher(const std::vector<StepRecord>& records, double t_start_s, double t_end_s) {
    std::vector<double> w, f;
    loop_samples(records, t_start_s, t_end_s, w, f);
    return fit_fancher(w, f);
}

FancherLoopFit fit_fancher_loop(const std::vector<StepRecord>& records, double t_start_s, double t_end_s) {
    FancherLoopFit loop;
    loop_samples(records, t_start_s, t_end_s, loop.w_m, loop.force_n);
    loop.fit = fit_fancher(loop.w_m, loop.force_n);
    loop.model_force_n = fancher_force(loop.fit.parameters, loop.w_m, loop.fit.start_force_n);
    return loop;
}

}  // namespace stackbeam
