/// @file work_precision.cpp
/// Work-precision table of the two time-stepping modes on the paper's friction
/// case (three leaves, mu = 0.5, clamp force 1000 N, 20 kg body at 2 m/s), 1 s
/// simulated: for the closed-form step at several dt and CVODE at several rtol,
/// the steps, right-hand sides, events, restarts, contact iterations, wall time
/// (median of repeated whole runs: model, condensation, stepping) and the error:
/// max over the 1 ms output grid of |w - w_ref| with w_ref a cvode run at rtol
/// 1e-12 (its own error ~1e-10 m), and the energy balance error at 1 s.
///
///   work_precision [repeats]      (default 5)
///
/// Prints a Markdown table (docs/performance.md keeps the latest).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "stackbeam/time/cvode_stepper.hpp"
#include "stackbeam/model/paper_example.hpp"

using namespace stackbeam;

namespace {
struct Result {
    std::vector<StepRecord> records;
    RunReport report;
    double wall_s = 0.0;
};

Result run(Mode mode, double dt, double rtol, int repeats) {
    Result r;
    std::vector<double> walls;
    for (int i = 0; i < repeats; ++i) {
        const auto t0 = std::chrono::steady_clock::now();
        const System s(Model::build(paper_example(PaperCase::friction)));
        SimulationOptions o;
        o.mode = mode;
        o.t_end_s = 1.0;
        o.dt_s = dt;
        o.cvode.rtol = rtol;
        if (mode == Mode::cvode) o.solver.kind = SolverKind::accelerated;
        r.records = simulate(s, o, {}, &r.report);
        walls.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    std::sort(walls.begin(), walls.end());
    r.wall_s = walls[walls.size() / 2];
    return r;
}

double error_vs(const std::vector<StepRecord>& a, const std::vector<StepRecord>& ref) {
    double e = 0.0;
    for (const auto& x : a) {
        const long i = std::lround(x.t_s / 1e-3);
        if (std::abs(i * 1e-3 - x.t_s) > 1e-12 || i >= static_cast<long>(ref.size())) continue;
        e = std::max(e, std::abs(x.w_m - ref[static_cast<std::size_t>(i)].w_m));
    }
    return e;
}
}  // namespace

int main(int argc, char** argv) {
    const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 5;
    const Result ref = run(Mode::cvode, 1e-3, 1e-12, 1);
    std::printf("| mode | dt or rtol | steps | RHS evals | events | restarts | contact iterations | wall [ms] | "
                "max abs(w - w_ref) [m] | energy error at 1 s [J] |\n");
    std::printf("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
    for (double dt : {2e-3, 1e-3, 5e-4, 2.5e-4}) {
        const Result r = run(Mode::closed_form, dt, 1e-8, repeats);
        std::printf("| closed-form | dt %g s | %ld | - | - | - | %ld | %.1f | %.2e | %.2e |\n", dt, r.report.steps,
                    r.report.contact_iterations, 1e3 * r.wall_s, error_vs(r.records, ref.records),
                    r.records.back().energy_balance_error_j);
    }
    for (double rtol : {1e-6, 1e-8, 1e-10}) {
        const Result r = run(Mode::cvode, 1e-3, rtol, repeats);
        const auto& c = r.report.cvode;
        std::printf("| cvode | rtol %g | %ld | %ld | %ld | %ld | %ld | %.1f | %.2e | %.2e |\n", rtol, c.steps,
                    c.rhs_evaluations, c.events, c.restarts, c.contact_iterations, 1e3 * r.wall_s,
                    error_vs(r.records, ref.records), r.records.back().energy_balance_error_j);
    }
    return 0;
}
