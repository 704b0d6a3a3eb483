// Study (not a test): Ceres' bounded Levenberg-Marquardt (the library's `fit`) against NLopt
// on the same calibrations, from 50 % below and 50 % above the true values: the simulation
// runs to converge, the final misfit (sum r^2 / 2) and the values found. Recorded in
// docs/decisions/059-calibration.md. Run from the source tree:
//   build/studies/fit_optimisers
// NLopt has no least-squares algorithm, so it minimises the scalar misfit f(u) = sum r^2 / 2
// on the values scaled to their bounds (u in [0, 1], as Ceres sees them): BOBYQA
// (derivative-free, quadratic models) with the runs one at a time, and SLSQP with the gradient
// J^T r from forward differences (the n + 1 runs of a gradient as one batch). Stopping as
// Ceres': relative decrease of f below 1e-6 or a step below 1e-5 of the bound width, at most
// 200 evaluations.
#include <nlopt.hpp>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "stackbeam/study/fit.hpp"

using namespace stackbeam;

namespace {

struct Case {
    const char* name;
    const char* spec;
    std::vector<double> truth;  // the values the loops were made at
};

struct Outcome {
    int runs = 0;
    double cost = NAN;
    std::vector<double> values;
};

double misfit(const std::vector<double>& r) {
    double s = 0.0;
    for (double x : r) s += x * x;
    return 0.5 * s;
}

std::vector<double> values_of(const FitSpec& spec, const std::vector<double>& u) {
    std::vector<double> x(u.size());
    for (std::size_t j = 0; j < u.size(); ++j)
        x[j] = spec.parameters[j].lower + std::min(std::max(u[j], 0.0), 1.0) * (spec.parameters[j].upper - spec.parameters[j].lower);
    return x;
}

Outcome with_nlopt(const FitSpec& spec, nlopt::algorithm algorithm, const std::vector<double>& start) {
    const std::size_t n = spec.parameters.size(), loops = spec.loops.size();
    const double h = spec.difference_step;
    Outcome out;
    FitOptions options;
    options.jobs = 1;
    auto objective = [&](const std::vector<double>& u, std::vector<double>& grad) {
        std::vector<std::vector<double>> points{values_of(spec, u)};
        std::vector<double> steps(n, h);
        if (!grad.empty())
            for (std::size_t j = 0; j < n; ++j) {
                std::vector<double> v = u;
                if (v[j] + h > 1.0) steps[j] = -h;
                v[j] += steps[j];
                points.push_back(values_of(spec, v));
            }
        const auto r = fit_residuals(spec, points, options);
        out.runs += static_cast<int>(points.size() * loops);
        if (r[0].empty()) return HUGE_VAL;
        for (std::size_t j = 0; j < grad.size(); ++j) {
            double g = 0.0;  // d f / d u_j = sum_i r_i d r_i / d u_j
            for (std::size_t i = 0; i < r[0].size(); ++i) g += r[0][i] * (r[j + 1][i] - r[0][i]) / steps[j];
            grad[j] = g;
        }
        return misfit(r[0]);
    };
    using Objective = decltype(objective);
    nlopt::opt opt(algorithm, static_cast<unsigned>(n));
    opt.set_lower_bounds(std::vector<double>(n, 0.0));
    opt.set_upper_bounds(std::vector<double>(n, 1.0));
    // the C++ interface's vfunc form (std::vector arguments)
    opt.set_min_objective(
        [](const std::vector<double>& u, std::vector<double>& grad, void* data) { return (*static_cast<Objective*>(data))(u, grad); },
        &objective);
    opt.set_ftol_rel(1e-6);
    opt.set_xtol_abs(1e-5);
    opt.set_maxeval(200);
    std::vector<double> u(n);
    for (std::size_t j = 0; j < n; ++j)
        u[j] = (start[j] - spec.parameters[j].lower) / (spec.parameters[j].upper - spec.parameters[j].lower);
    double f = NAN;
    try {
        opt.optimize(u, f);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "nlopt: %s\n", e.what());
    }
    out.cost = f;
    out.values = values_of(spec, u);
    return out;
}

Outcome with_ceres(const FitSpec& spec, const std::vector<double>& start) {
    FitOptions options;
    options.jobs = 1;
    options.start_values = start;
    const FitResult r = fit(spec, options);
    Outcome out;
    out.runs = r.runs;
    out.cost = r.cost;
    for (const auto& p : r.parameters) out.values.push_back(p.value);
    return out;
}

}  // namespace

int main() {
    const Case cases[] = {
        {"rig, mu and E, one 20 mm loop", "benchmarks/fit/two_parameters.toml", {0.35, 2e10}},
        {"rig, mu, 20 mm and 10 mm loops", "examples/calibration/fit.toml", {0.35}},
    };
    std::printf("| fit | start | optimiser | runs | final misfit | largest error of a value |\n| --- | --- | --- | --- | --- | --- |\n");
    for (const Case& c : cases) {
        const FitSpec spec = load_fit_spec(c.spec);
        for (const double factor : {0.5, 1.5}) {
            std::vector<double> start;
            for (double x : c.truth) start.push_back(factor * x);
            const Outcome outcomes[] = {with_ceres(spec, start), with_nlopt(spec, nlopt::LN_BOBYQA, start),
                                        with_nlopt(spec, nlopt::LD_SLSQP, start)};
            const char* names[] = {"Ceres LM", "NLopt BOBYQA", "NLopt SLSQP"};
            for (int k = 0; k < 3; ++k) {
                double worst = 0.0;
                for (std::size_t j = 0; j < c.truth.size(); ++j)
                    worst = std::max(worst, std::abs(outcomes[k].values[j] / c.truth[j] - 1.0));
                std::printf("| %s | %s | %s | %d | %.6g | %.2g %% |\n", c.name, factor < 1 ? "-50 %" : "+50 %", names[k],
                            outcomes[k].runs, outcomes[k].cost, 100 * worst);
                std::fflush(stdout);
            }
        }
    }
}
