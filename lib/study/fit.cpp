// Calibration (study/fit.hpp): the misfit of the measured loops, its minimisation by Ceres'
// Levenberg-Marquardt within bounds, the covariance and identifiability at the optimum.
// The runs are sweep points (study/sweep.hpp): the base scenario with the trial values set
// at the parameters' keys, run on threads by run_sweep.
#include "stackbeam/study/fit.hpp"

#include <ceres/ceres.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>

#include "fit_trial.hpp"
#include "stackbeam/post/hysteresis.hpp"

namespace stackbeam {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

/// +1 for a sample on the loading branch (cyclically from the lowest w to the highest), -1 unloading.
std::vector<int> branches_of(const std::vector<double>& w) {
    const int n = static_cast<int>(w.size());
    const int imin = static_cast<int>(std::min_element(w.begin(), w.end()) - w.begin());
    const int imax = static_cast<int>(std::max_element(w.begin(), w.end()) - w.begin());
    const int rise = (imax - imin + n) % n;
    std::vector<int> b(w.size());
    for (int i = 0; i < n; ++i) b[static_cast<std::size_t>(i)] = (i - imin + n) % n <= rise ? 1 : -1;
    return b;
}

/// One branch of a loop as F(w): the samples sorted by w; linear between them, constant beyond.
struct Branch {
    std::vector<std::pair<double, double>> points;
    double at(double w) const {
        if (points.empty()) return nan;
        if (w <= points.front().first) return points.front().second;
        if (w >= points.back().first) return points.back().second;
        const auto hi = std::lower_bound(points.begin(), points.end(), std::make_pair(w, -std::numeric_limits<double>::infinity()));
        const auto lo = hi - 1;
        const double dw = hi->first - lo->first;
        return dw > 0.0 ? lo->second + (hi->second - lo->second) * (w - lo->first) / dw : hi->second;
    }
};

/// The loop figures of measured samples: hysteresis_metrics on records one sample apart in time.
HysteresisMetrics measured_metrics(const MeasuredLoop& loop) {
    std::vector<StepRecord> records(loop.w_m.size());
    for (std::size_t i = 0; i < records.size(); ++i) {
        records[i].t_s = static_cast<double>(i);
        records[i].w_m = loop.w_m[i];
        records[i].spring_force_n = loop.force_n[i];
    }
    return hysteresis_metrics(records, 0.0, static_cast<double>(records.size() - 1));
}

/// What one loop's measured data give the misfit (fixed during the fit).
struct LoopReference {
    std::vector<int> branch;
    double f_half = 0.0, w_half = 0.0, area_scale = 0.0;
    HysteresisMetrics measured;
};

/// One evaluation of the misfit at some values: the residuals and, per loop, the fitted loop.
struct Evaluation {
    bool ok = false;
    std::string message;       ///< why not ok
    VectorXd residuals;
    std::vector<FitLoopResult> loops;
    std::vector<std::pair<double, double>> simulated_stroke;  ///< per loop, the last cycle's w_min, w_max [m]
};

class Objective {
public:
    Objective(const FitSpec& spec, const FitOptions& options) : spec_(spec), options_(options) {
        n_ = static_cast<int>(spec.parameters.size());
        figure_terms_ = (spec.weights.loop_area > 0) + (spec.weights.secant_stiffness > 0) + (spec.weights.dynamic_rate > 0);
        for (const MeasuredLoop& loop : spec.loops) {
            LoopReference ref;
            ref.branch = branches_of(loop.w_m);
            const auto [fmin, fmax] = std::minmax_element(loop.force_n.begin(), loop.force_n.end());
            const auto [wmin, wmax] = std::minmax_element(loop.w_m.begin(), loop.w_m.end());
            ref.f_half = std::max(0.5 * (*fmax - *fmin), 1e-300);
            ref.w_half = 0.5 * (*wmax - *wmin);
            ref.measured = measured_metrics(loop);
            ref.area_scale = std::max(std::abs(ref.measured.loop_area_j), 1e-3 * ref.f_half * ref.w_half);
            refs_.push_back(ref);
            offsets_.push_back(m_);
            m_ += (spec.weights.force > 0 ? static_cast<int>(loop.w_m.size()) : 0) + figure_terms_;
        }
    }
    int n() const { return n_; }
    int m() const { return m_; }
    int runs() const { return runs_; }
    bool stopped() const { return options_.stop && options_.stop->load(); }

    double value_of(int j, double u) const {
        const FitParameter& p = spec_.parameters[static_cast<std::size_t>(j)];
        return p.lower + std::clamp(u, 0.0, 1.0) * (p.upper - p.lower);
    }
    std::vector<double> values_of(const VectorXd& u) const {
        std::vector<double> x(static_cast<std::size_t>(n_));
        for (int j = 0; j < n_; ++j) x[static_cast<std::size_t>(j)] = value_of(j, u[j]);
        return x;
    }

    /// The evaluations at `us` (scaled values), from the cache or run as one batch on the threads.
    std::vector<const Evaluation*> evaluate(const std::vector<VectorXd>& us) {
        std::vector<std::vector<double>> keys;
        std::vector<std::size_t> missing;
        for (std::size_t k = 0; k < us.size(); ++k) {
            keys.emplace_back(us[k].data(), us[k].data() + n_);
            if (!cache_.count(keys.back()) &&
                std::find_if(missing.begin(), missing.end(), [&](std::size_t q) { return keys[q] == keys.back(); }) ==
                    missing.end())
                missing.push_back(k);
        }
        if (!missing.empty()) run_batch(us, keys, missing);
        std::vector<const Evaluation*> out;
        for (const auto& key : keys) {
            const auto it = cache_.find(key);
            out.push_back(it == cache_.end() ? nullptr : &it->second);
        }
        return out;
    }

    const std::vector<LoopReference>& references() const { return refs_; }

private:
    /// One scenario per (evaluation, loop): a zip sweep over the parameters' keys and the loop's settings.
    void run_batch(const std::vector<VectorXd>& us, const std::vector<std::vector<double>>& keys,
                   const std::vector<std::size_t>& missing) {
        const std::size_t loops = spec_.loops.size();
        std::vector<SweepPoint> points;
        std::vector<std::vector<double>> values;
        for (const std::size_t k : missing) values.push_back(values_of(us[k]));
        for (std::size_t l = 0; l < loops; ++l) {
            const SweepSpec sweep = detail::trial_sweep(spec_, values, &spec_.loops[l]);  // SweepPoints keeps a reference
            const SweepPoints generator(sweep);
            for (std::size_t q = 0; q < missing.size(); ++q) {
                SweepPoint p = generator.point(static_cast<int>(q));
                p.index = static_cast<int>(q * loops + l);
                points.push_back(std::move(p));
            }
        }
        std::sort(points.begin(), points.end(), [](const SweepPoint& a, const SweepPoint& b) { return a.index < b.index; });
        std::vector<Evaluation> results(missing.size());
        for (auto& e : results) {
            e.ok = true;
            e.residuals = VectorXd::Zero(m_);
            e.loops.resize(loops);
            e.simulated_stroke.resize(loops);
        }
        std::vector<bool> done(points.size(), false);
        SweepRunOptions run;
        run.jobs = options_.jobs;
        run.stop = options_.stop;
        run_sweep(points, run, [&](const PointResult& r) {
            const std::size_t q = static_cast<std::size_t>(r.index) / loops, l = static_cast<std::size_t>(r.index) % loops;
            done[static_cast<std::size_t>(r.index)] = true;
            ++runs_;
            Evaluation& e = results[q];
            if (r.status != PointStatus::ok) {
                e.ok = false;
                e.message = spec_.loops[l].name + ": " + r.message;
                return;
            }
            try {
                loop_residuals(l, *r.records, r.point->scenario.simulation.loading.period_s(), e);
            } catch (const InputError& error) {
                e.ok = false;
                e.message = spec_.loops[l].name + ": " + error.what();
            }
        });
        for (std::size_t q = 0; q < missing.size(); ++q) {
            bool complete = true;
            for (std::size_t l = 0; l < loops; ++l) complete = complete && done[q * loops + l];
            if (!complete) continue;  // stopped: not cached, the optimiser sees a failed step
            cache_.emplace(keys[missing[q]], std::move(results[q]));
        }
    }

    void loop_residuals(std::size_t l, const std::vector<StepRecord>& records, double period_s, Evaluation& e) const {
        const MeasuredLoop& loop = spec_.loops[l];
        const LoopReference& ref = refs_[l];
        const auto cycle = last_cycle(records, period_s);
        const HysteresisMetrics sim = hysteresis_metrics(records, cycle.first, cycle.second);
        std::vector<double> w, f;
        for (const StepRecord& r : records)
            if (r.t_s >= cycle.first && r.t_s <= cycle.second) {
                w.push_back(r.w_m);
                f.push_back(r.spring_force_n);
            }
        const std::vector<int> b = branches_of(w);
        Branch up, down;
        for (std::size_t k = 0; k < w.size(); ++k) (b[k] > 0 ? up : down).points.emplace_back(w[k], f[k]);
        std::sort(up.points.begin(), up.points.end());
        std::sort(down.points.begin(), down.points.end());
        FitLoopResult& out = e.loops[l];
        out.name = loop.name;
        out.w_m = loop.w_m;
        out.measured_force_n = loop.force_n;
        out.branch = ref.branch;
        out.fitted_force_n.resize(loop.w_m.size());
        double sum2 = 0.0;
        int row = offsets_[l];
        const double n_samples = static_cast<double>(loop.w_m.size());
        for (std::size_t i = 0; i < loop.w_m.size(); ++i) {
            const double fit = (ref.branch[i] > 0 ? up : down).at(loop.w_m[i]);
            out.fitted_force_n[i] = fit;
            sum2 += (fit - loop.force_n[i]) * (fit - loop.force_n[i]);
            if (spec_.weights.force > 0)
                e.residuals[row++] = std::sqrt(spec_.weights.force * loop.weight / n_samples) * (fit - loop.force_n[i]) / ref.f_half;
        }
        out.rms_force_error_n = std::sqrt(sum2 / n_samples);
        out.measured_area_j = ref.measured.loop_area_j;
        out.fitted_area_j = sim.loop_area_j;
        out.measured_secant_n_per_m = ref.measured.secant_stiffness_n_per_m;
        out.fitted_secant_n_per_m = sim.secant_stiffness_n_per_m;
        out.measured_dynamic_rate_n_per_m = ref.measured.dynamic_rate_n_per_m;
        out.fitted_dynamic_rate_n_per_m = sim.dynamic_rate_n_per_m;
        const FitWeights& wt = spec_.weights;
        if (wt.loop_area > 0)
            e.residuals[row++] = std::sqrt(wt.loop_area * loop.weight) * (sim.loop_area_j - ref.measured.loop_area_j) / ref.area_scale;
        if (wt.secant_stiffness > 0)
            e.residuals[row++] = std::sqrt(wt.secant_stiffness * loop.weight) *
                                 (sim.secant_stiffness_n_per_m - ref.measured.secant_stiffness_n_per_m) /
                                 std::max(std::abs(ref.measured.secant_stiffness_n_per_m), 1e-300);
        if (wt.dynamic_rate > 0)
            e.residuals[row++] = std::sqrt(wt.dynamic_rate * loop.weight) *
                                 (sim.dynamic_rate_n_per_m - ref.measured.dynamic_rate_n_per_m) /
                                 std::max(std::abs(ref.measured.dynamic_rate_n_per_m), 1e-300);
        e.simulated_stroke[l] = {sim.w_min_m, sim.w_max_m};
    }

    const FitSpec& spec_;
    const FitOptions& options_;
    int n_ = 0, m_ = 0, figure_terms_ = 0, runs_ = 0;
    std::vector<LoopReference> refs_;
    std::vector<int> offsets_;
    std::map<std::vector<double>, Evaluation> cache_;
};

/// The runs of one evaluation at u: u itself and the points of its Jacobian, run as one batch.
/// Forward differences u + s_j e_j (s_j = h, or -h when u_j + h > 1), and, when that makes an
/// odd number of runs (n even), the backward point u - s_0 e_0 too, so the first column is a
/// central difference: a batch of an even number of runs fills two threads (the extra run
/// costs no wall time there and makes one column second-order accurate). The same points
/// whatever `jobs` is, so the answer does not depend on it.
struct Stencil {
    std::vector<VectorXd> points;  ///< [0] u, [1 + j] u + s_j e_j, [n + 1] (when central) u - s_0 e_0
    std::vector<double> steps;     ///< s_j
    bool central = false;          ///< column 0 by central difference
};

Stencil stencil_at(const VectorXd& u, double h) {
    Stencil st;
    const int n = static_cast<int>(u.size());
    st.points.push_back(u);
    st.steps.assign(static_cast<std::size_t>(n), h);
    for (int j = 0; j < n; ++j) {
        VectorXd v = u;
        if (v[j] + h > 1.0) st.steps[static_cast<std::size_t>(j)] = -h;
        v[j] += st.steps[static_cast<std::size_t>(j)];
        st.points.push_back(v);
    }
    const double back = u[0] - st.steps[0];
    if ((n + 1) % 2 == 1 && back >= 0.0 && back <= 1.0) {
        VectorXd v = u;
        v[0] = back;
        st.points.push_back(v);
        st.central = true;
    }
    return st;
}

/// The Jacobian of the residuals in the scaled values from the evaluations at the stencil's points.
MatrixXd jacobian_of(const Stencil& st, const std::vector<const Evaluation*>& e) {
    const int n = static_cast<int>(st.steps.size());
    MatrixXd ju(e[0]->residuals.size(), n);
    for (int j = 0; j < n; ++j) {
        const double s = st.steps[static_cast<std::size_t>(j)];
        ju.col(j) = j == 0 && st.central
                        ? ((e[1]->residuals - e[static_cast<std::size_t>(n + 1)]->residuals) / (2.0 * s)).eval()
                        : ((e[static_cast<std::size_t>(j + 1)]->residuals - e[0]->residuals) / s).eval();
    }
    return ju;
}

/// The misfit as Ceres sees it: one residual block of m residuals in the n scaled values.
class MisfitCost final : public ceres::CostFunction {
public:
    MisfitCost(Objective& objective, double step) : objective_(objective), step_(step) {
        set_num_residuals(objective.m());
        mutable_parameter_block_sizes()->push_back(objective.n());
    }
    bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
        const int n = objective_.n(), m = objective_.m();
        const VectorXd u = Eigen::Map<const VectorXd>(parameters[0], n);
        const bool with_jacobian = jacobians && jacobians[0];
        // The trial point is run with its Jacobian's points (speculatively: if Ceres accepts
        // the step it asks for the Jacobian there next, from the cache; if it rejects it the
        // n extra runs are wasted): one batch of n + 1 or n + 2 runs instead of a trial run
        // alone, then n runs.
        const Stencil st = stencil_at(u, step_);
        const auto e = objective_.evaluate(st.points);
        if (!e[0] || !e[0]->ok) return false;  // a failed run: Ceres shrinks the step
        Eigen::Map<VectorXd>(residuals, m) = e[0]->residuals;
        if (with_jacobian) {
            for (const Evaluation* x : e)
                if (!x || !x->ok) return false;
            const MatrixXd ju = jacobian_of(st, e);
            for (int i = 0; i < m; ++i)
                for (int j = 0; j < n; ++j) jacobians[0][i * n + j] = ju(i, j);  // row-major
        }
        return true;
    }

private:
    Objective& objective_;
    double step_;
};

class Progress final : public ceres::IterationCallback {
public:
    Progress(const Objective& objective, const FitOptions& options, const double* u, int start,
             std::vector<FitIteration>& history)
        : objective_(objective), options_(options), u_(u), start_(start), history_(history) {}
    ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
        FitIteration it;
        it.start = start_;
        it.iteration = s.iteration;
        it.cost = s.cost;
        it.values = objective_.values_of(Eigen::Map<const VectorXd>(u_, objective_.n()));
        it.runs = objective_.runs();
        it.accepted = s.step_is_successful || s.iteration == 0;
        history_.push_back(it);
        if (options_.on_iteration) options_.on_iteration(it);
        return objective_.stopped() ? ceres::SOLVER_TERMINATE_SUCCESSFULLY : ceres::SOLVER_CONTINUE;
    }

private:
    const Objective& objective_;
    const FitOptions& options_;
    const double* u_;
    int start_;
    std::vector<FitIteration>& history_;
};

double halton(int index, int base) {
    double f = 1.0, r = 0.0;
    for (int i = index; i > 0; i /= base) {
        f /= base;
        r += f * (i % base);
    }
    return r;
}

/// Standard errors, correlation and identifiability from the Jacobian J_u (scaled values) at the fit.
void covariance(const FitSpec& spec, const MatrixXd& ju, double cost, FitResult& result) {
    const int m = static_cast<int>(ju.rows()), n = static_cast<int>(ju.cols());
    std::vector<double> norms(static_cast<std::size_t>(n));
    double largest = 0.0;
    for (int j = 0; j < n; ++j) largest = std::max(largest, norms[static_cast<std::size_t>(j)] = ju.col(j).norm());
    // a column is "near zero" when the misfit moves less over the parameter's whole bound range than
    // 1e-4 of the loop's force half-range (rms), or 1e-4 of the strongest parameter's effect
    std::vector<int> kept;
    for (int j = 0; j < n; ++j) {
        FitParameterResult& p = result.parameters[static_cast<std::size_t>(j)];
        const double c = norms[static_cast<std::size_t>(j)];
        if (c < 1e-4 || c < 1e-4 * largest) {
            p.identifiable = false;
            p.note = "the data do not depend on it: over its whole bound range it moves the misfit by " + format_value(c) +
                     " (relative to the strongest parameter: " + format_value(largest > 0 ? c / largest : 0.0) + ")";
        } else {
            kept.push_back(j);
        }
    }
    for (std::size_t a = 0; a < kept.size(); ++a)
        for (std::size_t b = a + 1; b < kept.size(); ++b) {
            const int j = kept[a], k = kept[b];
            const double cosine = std::abs(ju.col(j).dot(ju.col(k))) / (norms[static_cast<std::size_t>(j)] * norms[static_cast<std::size_t>(k)]);
            if (cosine > 0.999)
                for (const int q : {j, k}) {
                    FitParameterResult& p = result.parameters[static_cast<std::size_t>(q)];
                    p.identifiable = false;
                    p.note = "its effect on the loop is nearly parallel to " + spec.parameters[static_cast<std::size_t>(q == j ? k : j)].key +
                             "'s (cosine " + format_value(cosine) + "): the data identify a combination of the two, not each";
                }
        }
    const int nk = static_cast<int>(kept.size());
    result.correlation.assign(static_cast<std::size_t>(n), std::vector<double>(static_cast<std::size_t>(n), nan));
    for (auto& p : result.parameters) p.standard_error = std::numeric_limits<double>::infinity();
    if (nk > 0) {
        MatrixXd jk(m, nk);
        for (int a = 0; a < nk; ++a) {
            const FitParameter& p = spec.parameters[static_cast<std::size_t>(kept[static_cast<std::size_t>(a)])];
            jk.col(a) = ju.col(kept[static_cast<std::size_t>(a)]) / (p.upper - p.lower);  // d r / d x
        }
        const double s2 = 2.0 * cost / std::max(m - nk, 1);
        const Eigen::JacobiSVD<MatrixXd> svd(jk, Eigen::ComputeThinV);
        const VectorXd sv = svd.singularValues();
        VectorXd inv2 = VectorXd::Zero(nk);
        for (int a = 0; a < nk; ++a)
            inv2[a] = sv[a] > 1e-12 * sv[0] ? 1.0 / (sv[a] * sv[a]) : std::numeric_limits<double>::infinity();
        const MatrixXd& v = svd.matrixV();
        MatrixXd cov = s2 * v * inv2.asDiagonal() * v.transpose();
        for (int a = 0; a < nk; ++a) {
            const std::size_t j = static_cast<std::size_t>(kept[static_cast<std::size_t>(a)]);
            result.parameters[j].standard_error = std::sqrt(cov(a, a));
            for (int b = 0; b < nk; ++b)
                result.correlation[j][static_cast<std::size_t>(kept[static_cast<std::size_t>(b)])] =
                    cov(a, b) / std::sqrt(cov(a, a) * cov(b, b));
        }
    }
    for (const auto& p : result.parameters) {
        if (!p.identifiable) result.warnings.push_back(p.key + " is not identifiable from the data given: " + p.note);
        if (p.at_bound)
            result.warnings.push_back(p.key + " = " + format_value(p.value) +
                                      " lies at its bound: the best value may lie outside [" + format_value(p.lower) +
                                      ", " + format_value(p.upper) + "]");
    }
}

}  // namespace

FitResult fit(const FitSpec& spec, const FitOptions& options) {
    if (spec.parameters.empty()) throw InputError("parameters", "at least one parameter is required", spec.source);
    if (spec.loops.empty()) throw InputError("loops", "at least one measured loop is required", spec.source);
    const int n = static_cast<int>(spec.parameters.size());
    if (!options.start_values.empty() && static_cast<int>(options.start_values.size()) != n)
        throw InputError("start_values", "has " + std::to_string(options.start_values.size()) + " values; the spec has " +
                                             std::to_string(n) + " parameters");
    Objective objective(spec, options);
    if (objective.m() < n)
        throw InputError("loops", std::to_string(objective.m()) + " residuals for " + std::to_string(n) +
                                      " parameters: more measured samples are needed", spec.source);
    FitResult result;
    result.residual_count = objective.m();

    // the starting points, scaled to the bounds
    std::vector<VectorXd> starts;
    VectorXd first(n);
    for (int j = 0; j < n; ++j) {
        const FitParameter& p = spec.parameters[static_cast<std::size_t>(j)];
        const double x = options.start_values.empty() ? p.start : options.start_values[static_cast<std::size_t>(j)];
        first[j] = std::isnan(x) ? 0.5 : std::clamp((x - p.lower) / (p.upper - p.lower), 0.0, 1.0);
    }
    starts.push_back(first);
    static const int primes[] = {2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37};
    const int count = options.start_values.empty() ? spec.starts : 1;
    for (int k = 1; k < count; ++k) {
        VectorXd u(n);
        for (int j = 0; j < n; ++j) u[j] = halton(k, primes[j % 12]);
        starts.push_back(u);
    }

    // the starting point run first (with its Jacobian's points, which the optimiser asks for
    // next): a loop the loading cannot stroke is bad input, named
    {
        const auto e = objective.evaluate(stencil_at(first, spec.difference_step).points);
        if (objective.stopped()) {
            result.stopped = true;
            result.termination = "stopped before the first run finished";
            return result;
        }
        if (!e[0] || !e[0]->ok)
            throw std::runtime_error("the runs at the starting values failed: " + (e[0] ? e[0]->message : std::string("?")));
        for (std::size_t l = 0; l < spec.loops.size(); ++l) {
            const MeasuredLoop& loop = spec.loops[l];
            const auto [wmin, wmax] = std::minmax_element(loop.w_m.begin(), loop.w_m.end());
            const auto stroke = e[0]->simulated_stroke[l];
            const double slack = 0.01 * (*wmax - *wmin);  // 1 % of the measured stroke
            if (stroke.first > *wmin + slack || stroke.second < *wmax - slack) {
                std::string settings;
                for (const auto& [key, value] : loop.settings) settings += (settings.empty() ? "" : ", ") + key + " = " + to_string(value);
                throw InputError(loop.name, "the measured loop spans w = " + format_value(*wmin) + " .. " + format_value(*wmax) +
                                                " m but the scenario's loading" + (settings.empty() ? "" : " (with " + settings + ")") +
                                                " strokes its last cycle over " + format_value(stroke.first) + " .. " +
                                                format_value(stroke.second) + " m: set the loop's loading in [loops.set] "
                                                "(e.g. loading.displacement_m.amplitude) to cover the measured stroke",
                                 loop.location);
            }
        }
    }

    double best = std::numeric_limits<double>::infinity();
    VectorXd best_u = first;
    for (std::size_t k = 0; k < starts.size() && !objective.stopped(); ++k) {
        VectorXd u = starts[k];
        ceres::Problem::Options problem_options;
        problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
        ceres::Problem problem(problem_options);
        MisfitCost cost(objective, spec.difference_step);
        problem.AddResidualBlock(&cost, nullptr, u.data());
        for (int j = 0; j < n; ++j) {
            problem.SetParameterLowerBound(u.data(), j, 0.0);
            problem.SetParameterUpperBound(u.data(), j, 1.0);
        }
        ceres::Solver::Options so;
        so.minimizer_type = ceres::TRUST_REGION;
        so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
        so.linear_solver_type = ceres::DENSE_QR;
        so.max_num_iterations = spec.max_iterations;
        so.function_tolerance = 1e-6;   // relative decrease of the misfit
        so.parameter_tolerance = 1e-5;  // of the scaled values: 1e-5 of the bound width
        so.gradient_tolerance = 1e-10;
        so.num_threads = 1;             // the runs have their own threads (run_sweep)
        so.logging_type = ceres::SILENT;
        so.minimizer_progress_to_stdout = false;
        so.update_state_every_iteration = true;
        Progress progress(objective, options, u.data(), static_cast<int>(k), result.history);
        so.callbacks.push_back(&progress);
        ceres::Solver::Summary summary;
        ceres::Solve(so, &problem, &summary);
        result.iterations += static_cast<int>(summary.iterations.size()) - 1;
        const auto e = objective.evaluate({u});
        const double final_cost = e[0] && e[0]->ok ? 0.5 * e[0]->residuals.squaredNorm() : summary.final_cost;
        if (final_cost < best) {
            best = final_cost;
            best_u = u;
            result.best_start = static_cast<int>(k);
            result.converged = summary.termination_type == ceres::CONVERGENCE;
            result.termination = summary.message;
        }
    }
    result.stopped = objective.stopped();

    // the answer at the best values: the Jacobian there (its runs mostly cached), the covariance
    const Stencil around = stencil_at(best_u, spec.difference_step);
    const auto e = result.stopped ? objective.evaluate({best_u}) : objective.evaluate(around.points);
    if (!e[0] || !e[0]->ok) throw std::runtime_error("the run at the fitted values failed: " + (e[0] ? e[0]->message : std::string("stopped")));
    result.cost = 0.5 * e[0]->residuals.squaredNorm();
    result.loops = e[0]->loops;
    const std::vector<double> x = objective.values_of(best_u);
    for (int j = 0; j < n; ++j) {
        const FitParameter& p = spec.parameters[static_cast<std::size_t>(j)];
        FitParameterResult r;
        r.key = p.key;
        r.value = x[static_cast<std::size_t>(j)];
        r.lower = p.lower;
        r.upper = p.upper;
        r.at_bound = best_u[j] < 1e-6 || best_u[j] > 1.0 - 1e-6;
        result.parameters.push_back(r);
    }
    bool jacobian = !result.stopped;
    for (const Evaluation* x_e : e) jacobian = jacobian && x_e && x_e->ok;
    if (jacobian) {
        const MatrixXd ju = jacobian_of(around, e);
        covariance(spec, ju, result.cost, result);
    } else {
        result.correlation.assign(static_cast<std::size_t>(n), std::vector<double>(static_cast<std::size_t>(n), nan));
        for (auto& p : result.parameters) p.standard_error = nan;
        result.warnings.push_back("no uncertainty: " + std::string(result.stopped ? "the fit was stopped" : "a run around the fit failed"));
    }
    if (!result.converged && !result.stopped)
        result.warnings.push_back("the optimiser did not report convergence: " + result.termination);
    result.runs = objective.runs();

    // the fitted scenario: the base with the values set (as a sweep point's scenario)
    const SweepSpec fitted = detail::trial_sweep(spec, {x}, nullptr);  // SweepPoints keeps a reference
    result.fitted_scenario_text = SweepPoints(fitted).point(0).scenario_text;
    return result;
}

std::vector<std::vector<double>> fit_residuals(const FitSpec& spec, const std::vector<std::vector<double>>& values,
                                               const FitOptions& options) {
    Objective objective(spec, options);
    std::vector<VectorXd> us;
    for (const auto& x : values) {
        if (x.size() != spec.parameters.size())
            throw InputError("values", "has " + std::to_string(x.size()) + " values; the spec has " +
                                           std::to_string(spec.parameters.size()) + " parameters");
        VectorXd u(objective.n());
        for (int j = 0; j < objective.n(); ++j) {
            const FitParameter& p = spec.parameters[static_cast<std::size_t>(j)];
            const double xj = x[static_cast<std::size_t>(j)];
            if (!(xj >= p.lower && xj <= p.upper))
                throw InputError(p.key, "value " + format_value(xj) + " is not allowed: must lie in its bounds [" +
                                            format_value(p.lower) + ", " + format_value(p.upper) + "]",
                                 p.location);
            u[j] = (xj - p.lower) / (p.upper - p.lower);
        }
        us.push_back(u);
    }
    std::vector<std::vector<double>> out;
    for (const Evaluation* e : objective.evaluate(us))
        out.push_back(e && e->ok ? std::vector<double>(e->residuals.data(), e->residuals.data() + e->residuals.size())
                                 : std::vector<double>());
    return out;
}

}  // namespace stackbeam
