// Benchmarks of stackbeam (Google Benchmark; built with -DSTACKBEAM_BUILD_BENCHMARKS=ON,
// not run as tests). Figures and the command that made them: BENCHMARKS.md.
//
//  - ContactSolve: per-step solve time of each contact solver, replaying the
//    recorded problems of 0.6 s of the paper example (bonded, friction) in order,
//    warm-started as in a run, at tolerances 1e-6 and 1e-8 m. Counters: mean and
//    median microseconds per step, iterations and factorisations per step.
//  - WholeRun: a whole closed-form run (model build, condensation, stepping).
//  - Scaling: a friction run of 0.1 s on finer meshes and more leaves.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <memory>
#include <vector>

#include "stackbeam/paper_example.hpp"
#include "stackbeam/simulation.hpp"

using namespace stackbeam;

namespace {

struct Recorded {
    std::vector<ContactProblem> problems;
    Eigen::VectorXd p0;
};

const Recorded& recorded(PaperCase c) {
    static std::map<PaperCase, Recorded> cache;
    auto it = cache.find(c);
    if (it != cache.end()) return it->second;
    static std::vector<std::unique_ptr<System>> systems;
    systems.push_back(std::make_unique<System>(Model::build(paper_example(c))));
    SimulationOptions so;
    so.solver.tolerance_m = 1e-12;
    ClosedFormStepper st(*systems.back(), so);
    Recorded r;
    r.p0 = st.contact_forces();
    for (int i = 0; i < 600; ++i) {
        st.step();
        r.problems.push_back(st.last_problem());
    }
    return cache.emplace(c, std::move(r)).first->second;
}

void ContactSolve(benchmark::State& state, PaperCase c, SolverKind kind, double tol) {
    const Recorded& rec = recorded(c);
    SolverOptions o;
    o.kind = kind;
    o.tolerance_m = tol;
    o.max_iterations = 2000000;
    std::vector<double> us;
    double iterations = 0.0, factorizations = 0.0;
    long steps = 0;
    for (auto _ : state) {
        auto solver = make_solver(o);
        Eigen::VectorXd p = rec.p0;
        for (const auto& pr : rec.problems) {
            const auto t0 = std::chrono::steady_clock::now();
            const SolveResult r = solver->solve(pr, p);
            us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
            if (!r.converged) state.SkipWithError(r.message.c_str());
            iterations += r.iterations;
            factorizations += r.factorizations;
            ++steps;
        }
    }
    std::nth_element(us.begin(), us.begin() + us.size() / 2, us.end());
    state.counters["median_us"] = us[us.size() / 2];
    state.counters["max_us"] = *std::max_element(us.begin(), us.end());
    state.counters["iter_per_step"] = iterations / steps;
    state.counters["fact_per_step"] = factorizations / steps;
    state.SetItemsProcessed(steps);
}

void WholeRun(benchmark::State& state, PaperCase c, double t_end) {
    for (auto _ : state) {
        const System s(Model::build(paper_example(c)));
        SimulationOptions so;
        so.t_end_s = t_end;
        benchmark::DoNotOptimize(simulate(s, so));
    }
}

void Scaling(benchmark::State& state) {
    const int elements = static_cast<int>(state.range(0));
    const int leaves = static_cast<int>(state.range(1));
    ModelSpec spec = paper_example(PaperCase::friction, PaperExampleOptions{elements});
    while (static_cast<int>(spec.leaves.size()) < leaves) {
        spec.leaves.push_back(spec.leaves.back());
        spec.interfaces.push_back(spec.interfaces.back());
    }
    double setup = 0.0;
    for (auto _ : state) {
        const auto t0 = std::chrono::steady_clock::now();
        const System s(Model::build(spec));
        setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        SimulationOptions so;
        so.t_end_s = 0.1;
        benchmark::DoNotOptimize(simulate(s, so));
        state.counters["contact_components"] = s.num_components();
    }
    state.counters["setup_s"] = setup;
}

}  // namespace

BENCHMARK_CAPTURE(ContactSolve, bonded_exact_1e6, PaperCase::bonded, SolverKind::exact, 1e-6)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(ContactSolve, bonded_exact_1e8, PaperCase::bonded, SolverKind::exact, 1e-8)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(ContactSolve, friction_exact_1e6, PaperCase::friction, SolverKind::exact, 1e-6)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(ContactSolve, friction_exact_1e8, PaperCase::friction, SolverKind::exact, 1e-8)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(ContactSolve, bonded_gauss_seidel_1e6, PaperCase::bonded, SolverKind::accelerated, 1e-6)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(ContactSolve, bonded_gauss_seidel_1e8, PaperCase::bonded, SolverKind::accelerated, 1e-8)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(ContactSolve, friction_gauss_seidel_1e6, PaperCase::friction, SolverKind::accelerated, 1e-6)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(ContactSolve, friction_gauss_seidel_1e8, PaperCase::friction, SolverKind::accelerated, 1e-8)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(ContactSolve, bonded_block_jacobi_1e6, PaperCase::bonded, SolverKind::block_jacobi, 1e-6)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(ContactSolve, bonded_paper_1e6, PaperCase::bonded, SolverKind::paper, 1e-6)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_CAPTURE(ContactSolve, friction_paper_1e6, PaperCase::friction, SolverKind::paper, 1e-6)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_CAPTURE(WholeRun, bonded_0p6s, PaperCase::bonded, 0.6)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(WholeRun, friction_1s, PaperCase::friction, 1.0)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(WholeRun, frictionless_0p6s, PaperCase::frictionless, 0.6)->Unit(benchmark::kMillisecond);
BENCHMARK(Scaling)->Args({20, 3})->Args({40, 3})->Args({80, 3})->Args({160, 3})->Args({20, 6})->Args({20, 10})->Args({80, 10})
    ->Unit(benchmark::kMillisecond)->Iterations(1);

BENCHMARK_MAIN();
