// Benchmarks of the paper example's contact solvers and runs, the modes with leaf mass and the
// stress output (part of bench_stackbeam; figures and the commands that made them: docs/performance.md).
//
//  - ContactSolve: per-step solve time of each contact solver, replaying the
//    recorded problems of 0.6 s of the paper example (bonded, friction) in order,
//    warm-started as in a run, at tolerances 1e-6 and 1e-8 m. Counters: mean and
//    median microseconds per step, iterations and factorisations per step.
//  - WholeRun: a whole closed-form run (model build, condensation, stepping).
//  - Inertia: 1 s of the paper example with steel leaves (7850 kg/m^3): mode newmark
//    (friction and bonded) and mode cvode (bonded; the friction case needs the events
//    between massive leaves, not built yet). Counters: steps, contact iterations and
//    factorisations (newmark), CVODE steps, Jacobians and Newton matrices (cvode).
//  - MassiveStack: the whole massive stack under mode cvode.
//  - StressOutput: the cost of the stress output on a rig stroke.
#include "bench_support.hpp"

using namespace stackbeam;
using namespace stackbeam::bench;

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
        st.advance();
        r.problems.push_back(st.contact_solver().last_dense_problem());
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

/// args: case (0 bonded, 1 friction), mode (0 newmark, 1 cvode), dt [us] (newmark) or -log10(rtol) (cvode),
/// modal cut-off [rad/s] (cvode on the friction case; 0: the default, 10 x the first frequency).
void Inertia(benchmark::State& state) {
    const PaperCase c = state.range(0) == 0 ? PaperCase::bonded : PaperCase::friction;
    const bool cvode = state.range(1) == 1;
    ModelSpec spec = paper_example(c);
    for (auto& leaf : spec.leaves) leaf.density_kg_per_m3 = 7850.0;
    SimulationOptions so;
    so.t_end_s = 1.0;
    so.mode = cvode ? Mode::cvode : Mode::newmark;
    if (cvode) so.cvode.rtol = std::pow(10.0, -static_cast<double>(state.range(2)));
    else so.dt_s = 1e-6 * static_cast<double>(state.range(2));
    so.cvode.modal_cutoff_rad_per_s = static_cast<double>(state.range(3));
    RunReport rep;
    for (auto _ : state) {
        const System s(Model::build(spec));
        simulate(s, so, {}, &rep);
    }
    state.SetLabel(std::string(to_string(c)) + ", " + to_string(so.mode));
    state.counters["steps"] = static_cast<double>(rep.steps);
    state.counters["contact_iter"] = static_cast<double>(rep.contact_iterations);
    state.counters["fact"] = static_cast<double>(rep.factorizations);
    state.counters["jac"] = static_cast<double>(rep.cvode.jacobian_evaluations);
    state.counters["newton_mat"] = static_cast<double>(rep.cvode.linear_setups);
    state.counters["events"] = static_cast<double>(rep.cvode.events);
    state.counters["restarts"] = static_cast<double>(rep.cvode.restarts);
    state.counters["modes"] = static_cast<double>(rep.cvode.retained_modes);
    // the split of the (last) run's time: inside CVode(), contact iterations, other event handling
    state.counters["cvode_s"] = rep.cvode.cvode_time_s;
    state.counters["contact_s"] = rep.cvode.contact_time_s;
    state.counters["event_s"] = rep.cvode.event_time_s;
}

/// The whole massive stack under mode cvode (issue targets: docs/performance.md, "Leaf mass").
/// args: stack (0: the paper's friction case at 20 elements, 1: the graduated 10-leaf spring at
/// 100 elements per half leaf), simulated time [ms], beta [1e-7 s] (structural damping, 0: none).
/// Steel leaves, elastic interfaces, 10 mm clamps, rtol 1e-6, atol 1e-12 m.
void MassiveStack(benchmark::State& state) {
    ModelSpec spec = state.range(0) == 0 ? paper_example(PaperCase::friction) : graduated_stack(100, 10);
    spec = testing::with_elastic_interfaces(std::move(spec));
    for (auto& leaf : spec.leaves) leaf.density_kg_per_m3 = 7850.0;
    for (auto& cl : spec.clamps) cl.length_m = 0.01;
    SimulationOptions so;
    so.mode = Mode::cvode;
    so.t_end_s = 1e-3 * static_cast<double>(state.range(1));
    so.cvode.rtol = 1e-6;
    so.cvode.leaf_inertia = LeafInertia::massive;
    so.damping.rayleigh_beta_s = 1e-7 * static_cast<double>(state.range(2));
    RunReport rep;
    double wall = 0.0;
    for (auto _ : state) {
        const auto t0 = std::chrono::steady_clock::now();
        const System s(Model::build(spec));
        simulate(s, so, {}, &rep);
        wall = seconds_since(t0);
    }
    state.counters["s_per_sim_s"] = wall / so.t_end_s;
    state.counters["steps"] = static_cast<double>(rep.steps);
    state.counters["newton_mat"] = static_cast<double>(rep.cvode.linear_setups);
    state.counters["events"] = static_cast<double>(rep.cvode.events);
    state.counters["restarts"] = static_cast<double>(rep.cvode.restarts);
    state.counters["mode_fact"] = static_cast<double>(rep.cvode.mode_factorizations);
}

/// The cost of the stress output (docs/stresses-and-fatigue.md, decision 054): a rig stroke of the graduated
/// 10-leaf spring at 100 elements per half leaf (friction, mode closed-form, the default solvers),
/// w(t) = 20 mm tri(t / 1 s), dt = 1 ms, 100 records, with Stepper::stresses() and a
/// StressExtremes fed at every record (stresses:1), or a StressMonitor with a material on every leaf
/// (irregular loading: every node's turning points kept, rainflow at the end; decision 061) (stresses:2),
/// or neither (stresses:0).
void StressOutput(benchmark::State& state) {
    ModelSpec spec = graduated_stack(100, 10);
    spec.rigid_body.initial_velocity_m_per_s = 0.0;  // the rig prescribes w'(0)
    SimulationOptions so;
    so.loading.kind = LoadingKind::prescribed_displacement;
    so.loading.displacement_m.shape = TimeFunction::Shape::triangle;
    so.loading.displacement_m.amplitude = 0.02;
    so.loading.displacement_m.frequency_hz = 1.0;
    so.dt_s = 1e-3;
    so.t_end_s = 0.1;
    const bool stresses = state.range(0) != 0, monitor = state.range(0) == 2;
    if (monitor) {
        FatigueMaterial m;  // about 50CrV4 (docs/stresses-and-fatigue.md)
        m.ultimate_strength_pa = 1.6e9;
        m.endurance_limit_pa = 6.0e8;
        m.fatigue_strength_coefficient_pa = 2.0e9;
        m.fatigue_strength_exponent = -0.1;
        for (auto& l : spec.leaves) l.material = m;
    }
    double peak = 0.0;
    for (auto _ : state) {
        const System s(Model::build(spec));
        const auto stepper = make_stepper(s, so);
        StressExtremes extremes;
        StressMonitor mon(spec, StressMonitorOptions{});
        for (int i = 0; i < 100; ++i) {
            stepper->advance();
            if (monitor) mon.add(stepper->current().t_s, stepper->stresses());
            else if (stresses) extremes.add(stepper->current().t_s, stepper->stresses());
        }
        if (monitor) peak = mon.summary().extremes[0].tension.stress_pa;
        else if (stresses) peak = extremes.leaves()[0].tension.stress_pa;
        benchmark::DoNotOptimize(peak);
    }
    state.counters["peak_top_leaf_mpa"] = 1e-6 * peak;
}

}  // namespace

BENCHMARK(StressOutput)->ArgNames({"stresses"})->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(MassiveStack)
    ->ArgNames({"stack", "ms", "beta_e7"})
    ->Args({0, 10, 0})->Args({0, 1000, 10})->Args({0, 100, 100})->Args({1, 2, 10})
    ->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(Inertia)
    ->ArgNames({"friction", "cvode", "dt_us|rtol", "cut"})
    ->Args({1, 0, 1000, 0})->Args({1, 0, 100, 0})->Args({0, 0, 1000, 0})->Args({0, 0, 100, 0})
    ->Args({0, 1, 6, 0})->Args({0, 1, 8, 0})
    ->Args({1, 1, 6, 0})->Args({1, 1, 8, 0})->Args({1, 1, 6, 1000})
    ->Unit(benchmark::kMillisecond);
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
