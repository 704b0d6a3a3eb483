// Benchmarks of stackbeam (Google Benchmark; built with -DSTACKBEAM_BUILD_BENCHMARKS=ON,
// not run as tests). Figures and the command that made them: docs/performance.md.
//
//  - ContactSolve: per-step solve time of each contact solver, replaying the
//    recorded problems of 0.6 s of the paper example (bonded, friction) in order,
//    warm-started as in a run, at tolerances 1e-6 and 1e-8 m. Counters: mean and
//    median microseconds per step, iterations and factorisations per step.
//  - WholeRun: a whole closed-form run (model build, condensation, stepping).
//  - Scaling: closed-form runs on finer meshes and more leaves (the paper's leaf
//    repeated: paper_stack(), tests/test_support.hpp), dense and sparse contact path, bonded and friction
//    case. Counters: set-up (model, condensation, stepper) and wall time per
//    simulated second (set-up + stepping, scaled from the simulated time), contact
//    components, factorisations per step, semismooth Newton iterations per step (sparse
//    path, SolveResult::newton_iterations) and the first step's time. Each is one run (Iterations(1)): the large
//    ones take seconds to minutes and the machine is shared.
//  - ElasticRuns: friction runs with elastic interfaces (paper example, graduated and identical
//    10-leaf stacks up to 400 elements per half leaf) against the paper example, and which
//    step of the sparse path's transition chain settles each step.
//  - Inertia: 1 s of the paper example with steel leaves (7850 kg/m^3): mode newmark
//    (friction and bonded) and mode cvode (bonded; the friction case needs the events
//    between massive leaves, not built yet). Counters: steps, contact iterations and
//    factorisations (newmark), CVODE steps, Jacobians and Newton matrices (cvode).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <string>
#include <map>
#include <memory>
#include <vector>

#include "contact/sparse/driver/switches.hpp"  // the sparse path's methods under their internal names (lib/)
#include "contact/sparse/driver/trace.hpp"     // the transition study's trace (lib/, docs/decisions/036)
#include <cstdio>
#include "stackbeam/time/closed_form_stepper.hpp"
#include "stackbeam/time/cvode_stepper.hpp"
#include "stackbeam/errors.hpp"
#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/time/simulation.hpp"
#include "stackbeam/time/stepper.hpp"
#include "test_support.hpp"  // the many-leaf stacks (tests/)

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

// The many-leaf stacks, shared with the tests (tests/test_support.hpp): paper_stack (the
// paper's example with its leaf repeated: identical pinned leaves, the same interfaces and
// clamps) and graduated_stack (leaves shortened downwards, free ends, two clamps).
using testing::graduated_stack;
using testing::paper_stack;

/// args: elements per half leaf, leaves, case (0 bonded, 1 friction, 2 frictionless), path (0 dense, 1 sparse),
/// simulated time in ms.
void Scaling(benchmark::State& state) {
    const int elements = static_cast<int>(state.range(0));
    const int leaves = static_cast<int>(state.range(1));
    const PaperCase c = state.range(2) == 0 ? PaperCase::bonded : state.range(2) == 1 ? PaperCase::friction
                                                                                       : PaperCase::frictionless;
    const ContactPath path = state.range(3) == 0 ? ContactPath::dense : ContactPath::sparse;
    const double t_sim = 1e-3 * static_cast<double>(state.range(4));
    const ModelSpec spec = paper_stack(c, elements, leaves);
    double setup = 0.0, total = 0.0, factorizations = 0.0, newton = 0.0, first_step = 0.0;
    int components = 0;
    long steps = 0;
    for (auto _ : state) {
        const auto t0 = std::chrono::steady_clock::now();
        const System s(Model::build(spec));
        SimulationOptions so;
        so.t_end_s = t_sim;
        so.contact_path = path;
        ClosedFormStepper st(s, so);
        setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        steps = static_cast<long>(std::ceil(t_sim / so.dt_s - 1e-9));
        factorizations = newton = 0.0;
        for (long i = 0; i < steps; ++i) {
            factorizations += st.advance().factorizations;
            newton += st.last_solve().newton_iterations;
            if (i == 0) first_step = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() - setup;
        }
        total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        components = s.num_components();
    }
    state.SetLabel(std::string(to_string(c)) + ", " + to_string(path));
    state.counters["components"] = components;
    state.counters["setup_s"] = setup;
    state.counters["s_per_sim_s"] = total / t_sim;
    state.counters["ms_per_step"] = 1e3 * (total - setup) / static_cast<double>(steps);
    state.counters["fact_per_step"] = factorizations / static_cast<double>(steps);
    state.counters["newton_per_step"] = newton / static_cast<double>(steps);  // sparse path: semismooth Newton iterations
    state.counters["first_step_s"] = first_step;
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
        wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
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
// Scaling: {elements per half leaf, leaves, case (0 bonded, 1 friction, 2 frictionless), path (0 dense,
// 1 sparse), simulated ms}. The paper example itself (20 x 3) is the reference of the
// issue's target (10 leaves x 400 elements: at most 30x its time per simulated second).
// Dense runs stop where they become impractical (10 x 400: W alone would be 400 MB),
// sparse friction runs where a step takes minutes (see docs/performance.md).
BENCHMARK(Scaling)
    ->ArgNames({"el", "leaves", "friction", "sparse", "ms"})
    // reference: the paper example, 1 s simulated
    ->Args({20, 3, 0, 0, 1000})->Args({20, 3, 0, 1, 1000})->Args({20, 3, 1, 0, 1000})->Args({20, 3, 1, 1, 1000})
    // elements per half leaf, 3 leaves
    ->Args({40, 3, 0, 0, 200})->Args({40, 3, 0, 1, 200})->Args({40, 3, 1, 0, 50})->Args({40, 3, 1, 1, 50})
    ->Args({80, 3, 0, 0, 200})->Args({80, 3, 0, 1, 200})->Args({80, 3, 1, 0, 50})->Args({80, 3, 1, 1, 50})
    ->Args({160, 3, 0, 0, 100})->Args({160, 3, 0, 1, 200})->Args({160, 3, 1, 0, 20})->Args({160, 3, 1, 1, 20})
    ->Args({400, 3, 0, 0, 50})->Args({400, 3, 0, 1, 200})->Args({400, 3, 1, 0, 10})->Args({400, 3, 1, 1, 10})
    // leaves, 20 elements per half leaf
    ->Args({20, 6, 0, 0, 200})->Args({20, 6, 0, 1, 200})->Args({20, 6, 1, 0, 50})->Args({20, 6, 1, 1, 50})
    ->Args({20, 10, 0, 0, 200})->Args({20, 10, 0, 1, 200})->Args({20, 10, 1, 0, 20})->Args({20, 10, 1, 1, 20})
    // the target size: 10 leaves x 400 elements per half leaf (sparse; bonded and frictionless;
    // its first friction step takes over 10 minutes and fails: not run, see docs/performance.md);
    // friction on 10 leaves x 100 elements (1,782 rows), 20 steps
    ->Args({80, 10, 0, 1, 1000})->Args({400, 10, 0, 1, 1000})->Args({400, 10, 2, 1, 1000})
    ->Args({100, 10, 1, 1, 20})
    ->Unit(benchmark::kMillisecond)->Iterations(1);


/// The sparse path's transition methods on friction runs of 10 leaves (closed-form mode,
/// dt = 1 ms). args: elements per half leaf, stack (0 identical leaves, 1 graduated),
/// transition (0 newton: semismooth, then smoothing; 3 Tresca only: box QPs by pivoting, then
/// the interior-point method where pivoting does not settle; SparseTransitionMethod's values;
/// 1, semismooth only, was removed by decision 053), simulated time in ms, box QP method of the
/// Tresca fixed point (SparseBoxQpMethod's values: 0 pivoting then interior point, 1 interior
/// point first; 2, pivoting only, was removed by decision 053),
/// Anderson depth of the fixed point on the friction limits (SolverOptions::tresca_anderson_depth;
/// 0 the plain fixed point, 8 the default).
void Transitions(benchmark::State& state) {
    const int elements = static_cast<int>(state.range(0));
    const ModelSpec spec = state.range(1) == 1 ? graduated_stack(elements, 10) : paper_stack(PaperCase::friction, elements, 10);
    const double t_sim = 1e-3 * static_cast<double>(state.range(3));
    double total = 0.0, factorizations = 0.0, newton = 0.0, smoothing = 0.0, passes = 0.0, worst_step = 0.0;
    long steps = 0, tresca = 0;
    int components = 0;
    for (auto _ : state) {
        const auto t0 = std::chrono::steady_clock::now();
        const System s(Model::build(spec));
        SimulationOptions so;
        so.t_end_s = t_sim;
        so.contact_path = ContactPath::sparse;
        SparsePathMethods switches;
        switches.transition = static_cast<SparseTransitionMethod>(state.range(2));
        switches.box_qp = static_cast<SparseBoxQpMethod>(state.range(4));
        so.sparse_tuning.methods = switches;  // for the stepper's solvers
        so.solver.tresca_anderson_depth = static_cast<int>(state.range(5));
        ClosedFormStepper st(s, so);
        steps = static_cast<long>(std::ceil(t_sim / so.dt_s - 1e-9));
        factorizations = newton = smoothing = passes = worst_step = 0.0;
        tresca = 0;
        for (long i = 0; i < steps; ++i) {
            const auto t1 = std::chrono::steady_clock::now();
            factorizations += st.advance().factorizations;
            worst_step = std::max(worst_step, std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count());
            newton += st.last_solve().newton_iterations;
            smoothing += st.last_solve().smoothing_iterations;
            passes += st.last_solve().tresca_iterations;
            if (st.last_solve().fell_back) ++tresca;
        }
        total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        components = s.num_components();
    }
    state.counters["components"] = components;
    state.counters["s_per_sim_s"] = total / t_sim;
    state.counters["fact_per_step"] = factorizations / static_cast<double>(steps);
    state.counters["newton_per_step"] = newton / static_cast<double>(steps);
    state.counters["smooth_per_step"] = smoothing / static_cast<double>(steps);
    state.counters["tresca_per_step"] = passes / static_cast<double>(steps);  // fixed-point passes (box QPs)
    state.counters["fell_back_steps"] = static_cast<double>(tresca);  // answers of the Tresca fixed point (or the dense solver)
    state.counters["worst_step_s"] = worst_step;
}
BENCHMARK(Transitions)
    ->ArgNames({"el", "graduated", "transition", "ms", "box", "depth"})
    ->Args({100, 1, 0, 100, 0, 8})
    ->Args({100, 0, 0, 300, 0, 8})
    ->Args({100, 1, 3, 5, 0, 8})->Args({100, 0, 3, 20, 0, 8})
    ->Args({100, 1, 3, 30, 0, 0})->Args({100, 1, 3, 30, 0, 8})->Args({100, 1, 3, 100, 0, 8})
    ->Args({100, 0, 3, 100, 0, 0})->Args({100, 0, 3, 100, 0, 8})
    // 50 elements per half leaf: friction-mesh ratio 0.5 with mu = 0.5 (FrictionMeshRatioRuns below)
    ->Args({50, 1, 0, 300, 0, 8})->Args({50, 0, 0, 300, 0, 8})
    ->Unit(benchmark::kMillisecond)->Iterations(1);

/// The friction-mesh ratio kappa = mu (t_i + t_i+1) / (2 h) (model.hpp) against the exact
/// solver's fixed point on the friction limits: the graduated 10-leaf spring above with every
/// interface's mu set to args[1] / 10000, closed-form mode, dt = 1 ms, from rest. args:
/// elements per half leaf, mu x 1e4, transition (detail::sparse::TransitionMethod: 3 the Tresca fixed point
/// only, 0 the default chain), simulated time in ms, Anderson depth (0: the plain fixed
/// point). A step that fails ends the run (failed_at_step, 0 when none failed); the figures
/// are over the steps made.
void FrictionMeshRatioRuns(benchmark::State& state) {
    const int elements = static_cast<int>(state.range(0));
    ModelSpec spec = graduated_stack(elements, 10);
    for (auto& f : spec.interfaces) f.friction_coefficient = 1e-4 * static_cast<double>(state.range(1));
    const double t_sim = 1e-3 * static_cast<double>(state.range(3));
    double total = 0.0, passes = 0.0, most_passes = 0.0, kappa = 0.0, worst_step = 0.0;
    long steps = 0, failed_at = 0, fell_back = 0;
    for (auto _ : state) {
        const auto t0 = std::chrono::steady_clock::now();
        const Model model = Model::build(spec);
        kappa = friction_mesh_ratio(model).ratio;
        const System s(model);
        SimulationOptions so;
        so.t_end_s = t_sim;
        so.contact_path = ContactPath::sparse;
        SparsePathMethods switches;
        switches.transition = static_cast<SparseTransitionMethod>(state.range(2));
        so.sparse_tuning.methods = switches;  // for the stepper's solvers
        so.solver.tresca_anderson_depth = static_cast<int>(state.range(4));
        ClosedFormStepper st(s, so);
        const long n = static_cast<long>(std::ceil(t_sim / so.dt_s - 1e-9));
        passes = most_passes = worst_step = 0.0;
        steps = failed_at = fell_back = 0;
        for (long i = 0; i < n; ++i) {
            const auto t1 = std::chrono::steady_clock::now();
            try {
                st.advance();
            } catch (const SolverError&) {
                failed_at = i + 1;
                break;
            }
            ++steps;
            worst_step = std::max(worst_step, std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count());
            passes += st.last_solve().tresca_iterations;
            most_passes = std::max(most_passes, static_cast<double>(st.last_solve().tresca_iterations));
            if (st.last_solve().fell_back) ++fell_back;
        }
        total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    state.counters["kappa"] = kappa;
    state.counters["failed_at_step"] = static_cast<double>(failed_at);
    state.counters["steps"] = static_cast<double>(steps);
    state.counters["s_per_sim_s"] = steps > 0 ? total / (1e-3 * static_cast<double>(steps)) : 0.0;
    state.counters["tresca_per_step"] = steps > 0 ? passes / static_cast<double>(steps) : 0.0;
    state.counters["most_tresca_in_a_step"] = most_passes;
    state.counters["fell_back_steps"] = static_cast<double>(fell_back);  // answers the passes did not confirm
    state.counters["worst_step_s"] = worst_step;
}
BENCHMARK(FrictionMeshRatioRuns)
    ->ArgNames({"el", "mu_e4", "transition", "ms", "depth"})
    // 10 x 100 (h = 2.5 mm): kappa 0.25, 0.5, 1, 2, plain fixed point
    ->Args({100, 1250, 3, 25, 0})->Args({100, 2500, 3, 25, 0})->Args({100, 5000, 3, 25, 0})->Args({100, 10000, 3, 5, 0})
    // 10 x 400 (h = 0.625 mm): kappa 0.5, 1, 2, plain fixed point
    ->Args({400, 625, 3, 6, 0})->Args({400, 1250, 3, 6, 0})->Args({400, 2500, 3, 6, 0})
    // 10 x 400, the default chain at kappa 0.5 and 0.8
    ->Args({400, 625, 0, 100, 8})->Args({400, 1000, 0, 100, 8})
    // the paper's mu = 0.5 at kappa = 0.5: 50 elements per half leaf, the default chain
    ->Args({50, 5000, 0, 300, 8})
    ->Unit(benchmark::kMillisecond)->Iterations(1);

/// Elastic interfaces (issue 18's and 27's targets): closed-form runs of friction stacks with every
/// interface rigid or elastic (layer derived from the leaves), default solver chain, dt = 1 ms.
/// args: elements per half leaf, stack (0 the paper example, 1 graduated 10 leaves, 2 identical
/// 10 leaves, 3 graduated 10 leaves bonded, 4 identical 10 leaves bonded), elastic (0/1),
/// simulated ms, contact path (0 automatic: sparse from kSparsePathMinComponents rows; 1 sparse), inc (1 the
/// incremental solve, the default; 0 the way before it: Switches::incremental), schur (> 0:
/// SparsePathTuning::schur_max_rows; 0 its default), primal (SparsePathTuning::primal_min_rows:
/// -1 its default (0: off), 0 off: the large held sets on the sparse LU; > 0 the primal
/// route from that many held rows, docs/decisions/027), fixed (Switches::fixed_pattern: -1 its
/// default; 0 the variable saddle-point LU per held set, 1 Eigen's SparseLU on the fixed
/// pattern, 2 KLU on it, docs/decisions/031), border (SparsePathTuning::max_border_rows; -1 its
/// default), lu (docs/decisions/035, a bit mask: 1 Switches::block_border_solves, 2
/// Switches::residual_refactor_check, 4 Switches::fixed_border_rows at its default, 8
/// Switches::schur_fresh_max_rows at its default (docs/decisions/038); -1 the defaults, all
/// on; 0 the way before), fborder (Switches::fixed_border_rows; -1 as lu says). Counters: wall
/// and CPU time per simulated second (set-up plus stepping), factorisations and Newton
/// iterations per step, mode-set solves (factorisations plus updates) per transition step,
/// failed steps (residual above the tolerance; the run does not stop), and which step of the
/// sparse path's chain settled each step: the active-set passes alone, the semismooth Newton
/// method, the smoothing Newton method, the Tresca fixed point (its answer or the dense fallback).
/// The figures of one ElasticRuns-style run (closed-form stepper, dt = 1 ms, every step made
/// even if it does not converge): CPU and wall time, factorisations and Newton iterations per
/// step, mode-set solves per transition step, and which step of the sparse chain settled each.
struct ElasticFigures {
    double total = 0.0, cpu = 0.0, factorizations = 0.0, newton = 0.0, mode_solves = 0.0;
    long steps = 0, failed = 0, by_passes = 0, by_semismooth = 0, by_smoothing = 0, by_tresca = 0;
    long transition_steps = 0;
    int components = 0;
    double final_w_m = 0.0, dissipated_j = 0.0, z_norm = 0.0;  // the run's answer at its end

    void run(const ModelSpec& spec, const SimulationOptions& so) {
        const auto t0 = std::chrono::steady_clock::now();
        const std::clock_t c0 = std::clock();
        const System s(Model::build(spec));
        ClosedFormStepper st(s, so);
        steps = static_cast<long>(std::ceil(so.t_end_s / so.dt_s - 1e-9));
        factorizations = newton = mode_solves = 0.0;
        failed = by_passes = by_semismooth = by_smoothing = by_tresca = transition_steps = 0;
        for (long i = 0; i < steps; ++i) {
            const int f = st.advance().factorizations;
            factorizations += f;
            const SolveResult& r = st.last_solve();
            if (f + r.updates > 0) {
                ++transition_steps;
                mode_solves += f + r.updates;
            }
            newton += r.newton_iterations;
            if (!r.converged) ++failed;
            if (r.fell_back || r.tresca_iterations > 0) ++by_tresca;
            else if (r.smoothing_iterations > 0) ++by_smoothing;
            else if (r.newton_iterations > 0) ++by_semismooth;
            else ++by_passes;
        }
        total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
        components = s.num_components();
        final_w_m = st.current().w_m;
        dissipated_j = st.current().dissipated_energy_j;
        z_norm = st.reduced_displacements().norm();
    }

    void put(benchmark::State& state, double t_sim) const {
        state.counters["components"] = components;
        state.counters["s_per_sim_s"] = total / t_sim;
        state.counters["cpu_s_per_sim_s"] = cpu / t_sim;
        state.counters["fact_per_step"] = factorizations / static_cast<double>(steps);
        state.counters["transition_steps"] = static_cast<double>(transition_steps);  // steps with a factorisation or update
        state.counters["solves_per_transition"] =
            transition_steps > 0 ? mode_solves / static_cast<double>(transition_steps) : 0.0;
        state.counters["newton_per_step"] = newton / static_cast<double>(steps);
        state.counters["failed_steps"] = static_cast<double>(failed);
        state.counters["by_passes"] = static_cast<double>(by_passes);
        state.counters["by_semismooth"] = static_cast<double>(by_semismooth);
        state.counters["by_smoothing"] = static_cast<double>(by_smoothing);
        state.counters["by_tresca"] = static_cast<double>(by_tresca);
    }
};

void ElasticRuns(benchmark::State& state) {
    const int elements = static_cast<int>(state.range(0));
    const int stack = static_cast<int>(state.range(1));
    ModelSpec spec = stack == 0                ? paper_example(PaperCase::friction, PaperExampleOptions{elements})
                     : stack == 1 || stack == 3 ? graduated_stack(elements, 10)
                                                : paper_stack(PaperCase::friction, elements, 10);
    if (state.range(2) == 1)
        for (auto& f : spec.interfaces) f.contact = InterfaceContact::elastic;
    if (stack >= 3)
        for (auto& f : spec.interfaces) f.law = InterfaceLaw::bonded;
    const double t_sim = 1e-3 * static_cast<double>(state.range(3));
    SparsePathMethods sw;
    sw.incremental = state.range(5) != 0;
    if (state.range(8) >= 0) sw.fixed_pattern = static_cast<int>(state.range(8));
    if (state.range(10) >= 0) {
        sw.block_border_solves = (state.range(10) & 1) != 0;
        sw.residual_refactor_check = (state.range(10) & 2) != 0;
        if ((state.range(10) & 4) == 0) sw.fixed_border_rows = -1;
        if ((state.range(10) & 8) == 0) sw.schur_fresh_max_rows = -1;
    }
    if (state.range(11) >= 0) sw.fixed_border_rows = static_cast<int>(state.range(11));
    SimulationOptions so;
    so.sparse_tuning.methods = sw;
    so.t_end_s = t_sim;
    so.stop_on_nonconvergence = false;
    if (state.range(4) == 1) so.contact_path = ContactPath::sparse;
    if (state.range(6) > 0) so.sparse_tuning.schur_max_rows = static_cast<int>(state.range(6));
    if (state.range(7) >= 0) so.sparse_tuning.primal_min_rows = static_cast<int>(state.range(7));
    if (state.range(9) >= 0) so.sparse_tuning.max_border_rows = static_cast<int>(state.range(9));
    ElasticFigures fig;
    for (auto _ : state) fig.run(spec, so);
    fig.put(state, t_sim);
}
BENCHMARK(ElasticRuns)
    ->ArgNames({"el", "stack", "elastic", "ms", "sparse", "inc", "schur", "primal", "fixed", "border", "lu", "fborder"})
    // the reference: the paper example, rigid and elastic, 1 s
    ->Args({20, 0, 0, 1000, 0, 1, 0, -1, -1, -1, -1, -1})->Args({20, 0, 1, 1000, 0, 1, 0, -1, -1, -1, -1, -1})
    // graduated and identical 10 leaves, elastic, 100 / 200 / 400 elements per half leaf, 1 s
    // (the target's measure: the first 50 ms, from rest at 2 m/s, are not typical of the second)
    ->Args({100, 1, 1, 1000, 0, 1, 0, -1, -1, -1, -1, -1})->Args({200, 1, 1, 1000, 0, 1, 0, -1, -1, -1, -1, -1})->Args({400, 1, 1, 1000, 0, 1, 0, -1, -1, -1, -1, -1})
    ->Args({100, 2, 1, 1000, 0, 1, 0, -1, -1, -1, -1, -1})->Args({200, 2, 1, 1000, 0, 1, 0, -1, -1, -1, -1, -1})->Args({400, 2, 1, 1000, 0, 1, 0, -1, -1, -1, -1, -1})
    // issue 27's targets: 100 ms, graduated / identical 10 x 400 elastic against the same mesh
    // bonded, the incremental solve and the way before; graduated 50 / 100 / 200 / 400
    ->Args({400, 1, 1, 100, 0, 1, 0, -1, -1, -1, -1, -1})->Args({400, 1, 1, 100, 0, 0, 0, -1, -1, -1, -1, -1})->Args({400, 3, 0, 100, 0, 1, 0, -1, -1, -1, -1, -1})
    ->Args({400, 2, 1, 100, 0, 1, 0, -1, -1, -1, -1, -1})->Args({400, 2, 1, 100, 0, 0, 0, -1, -1, -1, -1, -1})->Args({400, 4, 0, 100, 0, 1, 0, -1, -1, -1, -1, -1})
    ->Args({50, 1, 1, 100, 0, 1, 0, -1, -1, -1, -1, -1})->Args({100, 1, 1, 100, 0, 1, 0, -1, -1, -1, -1, -1})->Args({200, 1, 1, 100, 0, 1, 0, -1, -1, -1, -1, -1})
    ->Args({50, 1, 1, 100, 0, 0, 0, -1, -1, -1, -1, -1})->Args({100, 1, 1, 100, 0, 0, 0, -1, -1, -1, -1, -1})->Args({200, 1, 1, 100, 0, 0, 0, -1, -1, -1, -1, -1})
    // the primal route (docs/decisions/027; off by default) from 401 held rows: 10 x 400
    // graduated and identical, graduated 100 / 200; and its threshold 100 / 200 / 800
    ->Args({400, 1, 1, 100, 0, 1, 0, 401, -1, -1, -1, -1})->Args({400, 2, 1, 100, 0, 1, 0, 401, -1, -1, -1, -1})
    ->Args({100, 1, 1, 100, 0, 1, 0, 401, -1, -1, -1, -1})->Args({200, 1, 1, 100, 0, 1, 0, 401, -1, -1, -1, -1})
    ->Args({400, 1, 1, 30, 0, 1, 0, 100, -1, -1, -1, -1})->Args({400, 1, 1, 30, 0, 1, 0, 200, -1, -1, -1, -1})->Args({400, 1, 1, 30, 0, 1, 0, 800, -1, -1, -1, -1})
    // the Schur way's limit (SparsePathTuning::schur_max_rows) with the incremental solve
    ->Args({400, 1, 1, 30, 0, 1, 0, -1, -1, -1, -1, -1})->Args({400, 1, 1, 30, 0, 1, 1200, -1, -1, -1, -1, -1})->Args({400, 1, 1, 30, 0, 1, 2500, -1, -1, -1, -1, -1})
    // the fixed-pattern LU (docs/decisions/031): off / Eigen / KLU, graduated and identical
    // 10 x 400, 30 ms (quick) and 100 ms (the targets' measure), graduated 100 / 200
    ->Args({400, 1, 1, 30, 0, 1, 0, -1, 0, -1, -1, -1})->Args({400, 1, 1, 30, 0, 1, 0, -1, 1, -1, -1, -1})->Args({400, 1, 1, 30, 0, 1, 0, -1, 2, -1, -1, -1})
    ->Args({400, 1, 1, 100, 0, 1, 0, -1, 0, -1, -1, -1})->Args({400, 1, 1, 100, 0, 1, 0, -1, 1, -1, -1, -1})->Args({400, 1, 1, 100, 0, 1, 0, -1, 2, -1, -1, -1})
    ->Args({400, 2, 1, 100, 0, 1, 0, -1, 0, -1, -1, -1})->Args({400, 2, 1, 100, 0, 1, 0, -1, 1, -1, -1, -1})->Args({400, 2, 1, 100, 0, 1, 0, -1, 2, -1, -1, -1})
    ->Args({100, 1, 1, 100, 0, 1, 0, -1, 0, -1, -1, -1})->Args({100, 1, 1, 100, 0, 1, 0, -1, 2, -1, -1, -1})
    ->Args({200, 1, 1, 100, 0, 1, 0, -1, 0, -1, -1, -1})->Args({200, 1, 1, 100, 0, 1, 0, -1, 2, -1, -1, -1})
    // docs/decisions/035: the bordered update's block solves (lu bit 1), the KLU
    // refactorisation kept by the backward error (lu bit 2) and the bordered update's limit on
    // the fixed pattern (lu bit 4), all on by default, against the way before (lu:0);
    // graduated and identical 10 x 400, 30 / 100 ms; the bordered update's limits (border,
    // fborder) on the identical stack; graduated 50 / 100 / 200 before
    ->Args({400, 1, 1, 30, 0, 1, 0, -1, -1, -1, 0, -1})->Args({400, 1, 1, 30, 0, 1, 0, -1, -1, -1, 1, -1})
    ->Args({400, 1, 1, 30, 0, 1, 0, -1, -1, -1, 2, -1})->Args({400, 1, 1, 30, 0, 1, 0, -1, -1, -1, 3, -1})
    ->Args({400, 2, 1, 30, 0, 1, 0, -1, -1, -1, 0, -1})->Args({400, 2, 1, 30, 0, 1, 0, -1, -1, -1, 3, -1})
    ->Args({400, 1, 1, 100, 0, 1, 0, -1, -1, -1, 0, -1})->Args({400, 2, 1, 100, 0, 1, 0, -1, -1, -1, 0, -1})
    ->Args({400, 2, 1, 100, 0, 1, 0, -1, -1, 40, -1, -1})->Args({400, 2, 1, 100, 0, 1, 0, -1, -1, 20, -1, -1})
    ->Args({400, 2, 1, 100, 0, 1, 0, -1, -1, 0, -1, -1})
    ->Args({400, 2, 1, 100, 0, 1, 0, -1, -1, -1, -1, 0})->Args({400, 2, 1, 100, 0, 1, 0, -1, -1, -1, -1, 20})
    ->Args({400, 2, 1, 100, 0, 1, 0, -1, -1, -1, 3, -1})
    // docs/decisions/038: the held sets' own KLU systems (fixed 4, the default) and the Schur
    // way's fresh-LU limit (lu bit 8) against the way before (fixed:2, lu:7); graduated and
    // identical 10 x 400, 100 ms, and graduated 100 / 200 (per doubling)
    ->Args({400, 1, 1, 100, 0, 1, 0, -1, 2, -1, 7, -1})->Args({400, 2, 1, 100, 0, 1, 0, -1, 2, -1, 7, -1})
    ->Args({400, 1, 1, 100, 0, 1, 0, -1, -1, -1, 7, -1})->Args({400, 2, 1, 100, 0, 1, 0, -1, -1, -1, 7, -1})
    ->Args({100, 1, 1, 100, 0, 1, 0, -1, 2, -1, 7, -1})->Args({200, 1, 1, 100, 0, 1, 0, -1, 2, -1, 7, -1})
    ->Args({100, 1, 1, 100, 0, 1, 0, -1, -1, -1, -1, -1})->Args({200, 1, 1, 100, 0, 1, 0, -1, -1, -1, -1, -1})
    ->Args({50, 1, 1, 100, 0, 1, 0, -1, -1, -1, 0, -1})->Args({100, 1, 1, 100, 0, 1, 0, -1, -1, -1, 0, -1})
    ->Args({200, 1, 1, 100, 0, 1, 0, -1, -1, -1, 0, -1})
    // which step of the sparse chain settles the steps (docs/decisions/014): elastic at 100
    // elements, rigid and elastic at 50 (rigid kappa 0.5), 300 ms, sparse path
    ->Args({100, 1, 1, 300, 1, 1, 0, -1, -1, -1, -1, -1})->Args({100, 2, 1, 300, 1, 1, 0, -1, -1, -1, -1, -1})
    ->Args({50, 1, 0, 300, 1, 1, 0, -1, -1, -1, -1, -1})->Args({50, 2, 0, 300, 1, 1, 0, -1, -1, -1, -1, -1})->Args({50, 1, 1, 300, 1, 1, 0, -1, -1, -1, -1, -1})->Args({50, 2, 1, 300, 1, 1, 0, -1, -1, -1, -1, -1})
    ->Unit(benchmark::kMillisecond)->Iterations(1);

/// A study of the transition steps (docs/decisions/036, 037, 038): ElasticRuns' figures on the
/// graduated (stack 1) or identical (stack 2) 10-leaf spring with elastic interfaces, or the same
/// meshes bonded with rigid interfaces (stacks 3 / 4: the targets' reference), with the
/// transition method of decision 037 in part or whole (`way`, a bit mask of its changes, each
/// bit the Switches field at its default, else the way before: 1 newton_passes, 2
/// smoothing_from_rest, 4 first_pass_start, 8 creep_limit, 16 nonmonotone_memory; 29 the
/// default (smoothing_from_rest is off), 0 the way before; bit 32 decision 038's routes,
/// Switches::fixed_pattern 4 and schur_fresh_max_rows 200, else 2 and none; 61 every default;
/// bit 64 decision 041's homotopy from rest off, Switches::rest_path_violations 0, so 125 is
/// 61 the way before 041) and, with trace 1, the statistics of
/// every transition step (SparsePathTuning::observer, trace.hpp) printed to stderr: mode changes per Newton
/// iteration, pairs back in a mode they had left, the distances of the start, a predicted start
/// and the Newton method's first modes to the step's final modes, how the semismooth method
/// ended; per phase and route the mode solver's calls and their CPU time (decision 038).
/// args: elements per half leaf, stack, simulated ms, way, trace, schur (> 0:
/// SparsePathTuning::schur_max_rows; 0 its default), fixed (Switches::fixed_pattern; -1 its
/// default), path (the homotopy, docs/decisions/040: 0 off, the way before; > 0 on with a
/// new base past that many changed rows, Switches::path_rebase_rows, 48 the default; -1 on
/// without new bases), hits (Switches::path_max_start_hits; -1 its default 500, 0 no
/// limit), repair (docs/decisions/042; -1 the defaults, else a bit mask of its changes, each bit
/// the Switches field at its default, else the way before: 1 path_clamp_slip, 2
/// path_max_pair_switches, 4 path_fold_ends, 8 path_keep_base (decision 045); 0 the way before
/// 042, 7 the way before 045). Each run's answer at its end (w, dissipated energy, |z|) goes to
/// stderr to 17 digits, with the trace the homotopy's counts.
void TransitionStudy(benchmark::State& state) {
    const int elements = static_cast<int>(state.range(0));
    const int stack = static_cast<int>(state.range(1));
    ModelSpec spec = stack == 1 || stack == 3 ? graduated_stack(elements, 10) : paper_stack(PaperCase::friction, elements, 10);
    for (auto& f : spec.interfaces) {
        if (stack <= 2) f.contact = InterfaceContact::elastic;
        else f.law = InterfaceLaw::bonded;
    }
    const double t_sim = 1e-3 * static_cast<double>(state.range(2));
    const int way = static_cast<int>(state.range(3));
    detail::sparse::TransitionTrace trace;
    const SparsePathMethods now;
    SparsePathMethods sw = SparsePathMethods::before_037();
    if ((way & 1) != 0) sw.newton_passes = now.newton_passes;
    if ((way & 2) != 0) sw.smoothing_from_rest = true;
    if ((way & 4) != 0) sw.first_pass_start = now.first_pass_start;
    if ((way & 8) != 0) sw.creep_limit = now.creep_limit;
    if ((way & 16) != 0) sw.nonmonotone_memory = now.nonmonotone_memory;
    if ((way & 32) == 0) {  // decision 038's routes off: the fixed pattern's KLU, no fresh-LU limit
        sw.fixed_pattern = 2;
        sw.schur_fresh_max_rows = -1;
    }
    if (state.range(6) >= 0) sw.fixed_pattern = static_cast<int>(state.range(6));
    const int path_arg = static_cast<int>(state.range(7));
    sw.path_following = path_arg != 0 ? 1 : 0;
    if (path_arg != 0) sw.path_rebase_rows = path_arg > 0 ? path_arg : 0;
    if (state.range(8) >= 0) sw.path_max_start_hits = static_cast<int>(state.range(8));
    if ((way & 64) != 0) sw.rest_path_violations = 0;  // decision 041's homotopy from rest off
    if (state.range(9) >= 0) {  // decision 042's repairs of the homotopy, else the way before
        sw.path_clamp_slip = (state.range(9) & 1) != 0;
        sw.path_max_pair_switches = (state.range(9) & 2) != 0 ? now.path_max_pair_switches : 6;
        sw.path_fold_ends = (state.range(9) & 4) != 0 ? now.path_fold_ends : true;
        sw.path_keep_base = (state.range(9) & 8) != 0 ? now.path_keep_base : 0;  // decision 045
    }
    SimulationOptions so;
    so.sparse_tuning.methods = sw;
    if (state.range(4) == 1) so.sparse_tuning.observer = &trace;  // the trace argument
    so.t_end_s = t_sim;
    so.stop_on_nonconvergence = false;
    if (state.range(5) > 0) so.sparse_tuning.schur_max_rows = static_cast<int>(state.range(5));
    ElasticFigures fig;
    for (auto _ : state) {
        trace.steps.clear();
        fig.run(spec, so);
    }
    fig.put(state, t_sim);
    std::fprintf(stderr, "# TransitionStudy el:%d stack:%d ms:%d way:%d path:%d answer: w %.17g m, dissipated %.17g J, |z| %.17g\n",
                 elements, stack, static_cast<int>(state.range(2)), way, path_arg, fig.final_w_m, fig.dissipated_j,
                 fig.z_norm);
    if (state.range(4) != 1) return;
    // the homotopy (Switches::path_following, docs/decisions/040): the steps it ran on, those
    // it settled (its modes confirmed), its breakpoints, columns (and the multi-column solves
    // that made them), base factorisations, pairs evaluated exactly per pair test, the
    // confirming passes' solves, and the fallbacks by reason
    {
        double runs = 0, settled = 0, bp = 0, cols = 0, blocks = 0, fact = 0, conf = 0, rebases = 0, evals = 0, tests = 0;
        double col_s = 0, base_s = 0, all_s = 0, kept = 0, start_rows = 0, end_rows = 0;
        std::map<int, int> start_hist, end_hist;  // rows by bins of 8
        std::map<int, int> path_ends;
        for (const auto& t : trace.steps) {
            if (t.path.end == 0) continue;
            ++runs;
            settled += t.path_confirmed;
            bp += t.path.breakpoints;
            cols += t.path.columns;
            blocks += t.path.column_blocks;
            fact += t.path.factorizations;
            rebases += t.path.rebases;
            conf += t.path_confirm_solves;
            evals += static_cast<double>(t.path.evaluations);
            tests += static_cast<double>(t.path.pair_tests);
            col_s += t.path.column_s;
            base_s += t.path.base_s;
            all_s += t.path.total_s;
            end_rows += t.path.end_rows;
            ++end_hist[t.path.end_rows / 8 * 8];
            if (t.path.kept_base) {
                ++kept;
                start_rows += t.path.start_rows;
                ++start_hist[t.path.start_rows / 8 * 8];
            }
            ++path_ends[static_cast<int>(t.path.end) * 10 + (t.path_confirmed ? 0 : 1)];
        }
        state.counters["path_runs"] = runs;
        state.counters["path_fallbacks"] = runs - settled;
        state.counters["breakpoints_per_path"] = runs > 0 ? bp / runs : 0.0;
        state.counters["columns_per_path"] = runs > 0 ? cols / runs : 0.0;
        if (runs > 0) {
            std::fprintf(stderr, "# path: %g runs, %g settled; per run %.2f breakpoints, %.2f columns in %.2f solves, %.2f factorisations (%.2f new bases), %.2f confirming solves; pairs evaluated %.3f of tested; ends (10 x end + unconfirmed):",
                         runs, settled, bp / runs, cols / runs, blocks / runs, fact / runs, rebases / runs, conf / runs,
                         tests > 0 ? evals / tests : 0.0);
            std::fprintf(stderr, " CPU ms per run: %.2f (columns %.2f, bases %.2f);", 1e3 * all_s / runs,
                         1e3 * col_s / runs, 1e3 * base_s / runs);
            for (const auto& e : path_ends) std::fprintf(stderr, " [%d]=%d", e.first, e.second);
            // decision 045: the base kept from the run before, the rows the start modes differ from
            // it, the rows the end modes differ from the last base (by bins of 8 rows: first row)
            std::fprintf(stderr, " kept base %g runs, start rows %.1f, end rows %.1f; start rows hist:", kept,
                         kept > 0 ? start_rows / kept : 0.0, end_rows / runs);
            for (const auto& e : start_hist) std::fprintf(stderr, " %d:%d", e.first, e.second);
            std::fprintf(stderr, "; end rows hist:");
            for (const auto& e : end_hist) std::fprintf(stderr, " %d:%d", e.first, e.second);
            std::fprintf(stderr, " (1 reached, 2 n/a, 3 singular, 4 rows, 5 breakpoints, 6 stalled, 7 folded, 8 cycled, 9 singular modes, 10 start hits)\n");
            // per run: the start modes' failing conditions (the first ratio test's hits), its
            // breakpoints, columns, CPU ms, settled
            std::fprintf(stderr, "# path runs: start hits / breakpoints / columns / CPU ms / settled:");
            for (const auto& t : trace.steps)
                if (t.path.end != 0)
                    std::fprintf(stderr, " %d/%d/%d/%.1f/%d", t.path.start_hits, t.path.breakpoints, t.path.columns,
                                 1e3 * t.path.total_s, t.path_confirmed ? 1 : 0);
            std::fprintf(stderr, "\n");
        }
    }
    // the statistics over the steps with a Newton method (and over those the passes settled)
    const auto& steps = trace.steps;
    std::fprintf(stderr, "\n# TransitionStudy el:%d stack:%d ms:%d way:%d: %zu solves\n", elements, stack,
                 static_cast<int>(state.range(2)), way, steps.size());
    std::fprintf(stderr, "# step solves fact passes settled newton end conf confsolves smooth ok | start(n,t) pred(n,t) first(n,t) passes(n,t) | pairs changed maxch | per iteration: n+t changes/returns/step/violations\n");
    struct Sum { double n = 0, v = 0; void add(double x) { n += 1; v += x; } double mean() const { return n > 0 ? v / n : 0.0; } };
    Sum newton_its, pass_solves, confirm, smooth, solves, start_n, start_t, pred_n, pred_t, first_n, first_t, passes_n,
        passes_t, changed, maxch, set_start_n, set_start_t, set_pred_n, set_pred_t, pairs_sum, returns;
    std::map<int, int> ends;
    std::vector<Sum> it_changes(20), it_returns(20), it_full(20), it_viol(20);
    int idx = 0, newton_steps = 0, settled_steps = 0, smoothing_steps = 0, smoothing_ok = 0, revisit_steps = 0;
    for (const auto& t : steps) {
        ++idx;
        if (t.solves == 0) continue;
        std::fprintf(stderr, "%4d %3d %3d %2d %d %2zu %d %d %d %3d %d | %4d %4d  %4d %4d  %4d %4d  %4d %4d | %4d %4d %2d |", idx,
                     t.solves, t.factorizations, t.pass_solves, t.passes_settled, t.iterations.size(), t.newton_end,
                     t.newton_confirmed, t.confirm_solves, t.smoothing_iterations, t.smoothing_ok, t.start_n, t.start_t,
                     t.pred_n, t.pred_t, t.first_n, t.first_t, t.passes_n, t.passes_t, t.pairs, t.pairs_changed,
                     t.max_changes_per_pair);
        for (const auto& it : t.iterations)
            std::fprintf(stderr, " %d/%d/%.2g/%d", it.n_changes + it.t_changes, it.returns, it.step, it.violations);
        std::fprintf(stderr, "\n");
        pairs_sum.add(t.pairs);
        if (t.passes_settled) {
            ++settled_steps;
            if (t.start_n >= 0) { set_start_n.add(t.start_n); set_start_t.add(t.start_t); }
            if (t.pred_n >= 0) { set_pred_n.add(t.pred_n); set_pred_t.add(t.pred_t); }
            continue;
        }
        if (t.iterations.empty() && t.newton_end == 0) continue;
        ++newton_steps;
        ++ends[t.newton_end];
        newton_its.add(static_cast<double>(t.iterations.size()));
        pass_solves.add(t.pass_solves);
        confirm.add(t.confirm_solves);
        solves.add(t.solves);
        if (t.smoothing_iterations > 0) {
            ++smoothing_steps;
            smoothing_ok += t.smoothing_ok;
            smooth.add(t.smoothing_iterations);
        }
        if (t.start_n >= 0) { start_n.add(t.start_n); start_t.add(t.start_t); }
        if (t.pred_n >= 0) { pred_n.add(t.pred_n); pred_t.add(t.pred_t); }
        if (t.first_n >= 0) { first_n.add(t.first_n); first_t.add(t.first_t); }
        if (t.passes_n >= 0) { passes_n.add(t.passes_n); passes_t.add(t.passes_t); }
        changed.add(t.pairs_changed);
        maxch.add(t.max_changes_per_pair);
        int ret = 0;
        for (std::size_t k = 0; k < t.iterations.size(); ++k) {
            const auto& it = t.iterations[k];
            ret += it.returns;
            const std::size_t b = std::min<std::size_t>(k, it_changes.size() - 1);
            it_changes[b].add(it.n_changes + it.t_changes);
            it_returns[b].add(it.returns);
            it_full[b].add(it.step == 1.0 ? 1.0 : 0.0);
            it_viol[b].add(it.violations);
        }
        returns.add(ret);
        revisit_steps += ret > 0;
    }
    std::fprintf(stderr, "# pairs %.0f; steps with a solve: passes settled %d (start->final n %.1f t %.1f, predicted->final n %.1f t %.1f)\n",
                 pairs_sum.mean(), settled_steps, set_start_n.mean(), set_start_t.mean(), set_pred_n.mean(), set_pred_t.mean());
    std::fprintf(stderr, "# Newton steps %d: solves %.2f = passes %.2f + Newton iterations %.2f + confirming passes %.2f (+ smoothing)\n",
                 newton_steps, solves.mean(), pass_solves.mean(), newton_its.mean(), confirm.mean());
    std::fprintf(stderr, "#   semismooth ends:");
    for (const auto& e : ends) std::fprintf(stderr, " [%d]=%d", e.first, e.second);
    std::fprintf(stderr, " (1 converged, 2 iteration limit, 3 no decrease, 4 singular, 5 handed to the homotopy from rest); smoothing in %d steps (%d settled), %.1f iterations each\n",
                 smoothing_steps, smoothing_ok, smooth.mean());
    std::fprintf(stderr, "#   distance to the final modes (pairs, normal / tangential): start %.1f / %.1f, predicted %.1f / %.1f, Newton's first %.1f / %.1f, after the passes %.1f / %.1f\n",
                 start_n.mean(), start_t.mean(), pred_n.mean(), pred_t.mean(), first_n.mean(), first_t.mean(), passes_n.mean(), passes_t.mean());
    std::fprintf(stderr, "#   pairs that changed in the Newton iterations %.1f, most changes of one pair %.1f, returns to a left mode %.1f per step (%d of %d steps)\n",
                 changed.mean(), maxch.mean(), returns.mean(), revisit_steps, newton_steps);
    std::fprintf(stderr, "#   per iteration (1..): changes / returns / full steps / violations after:");
    for (std::size_t k = 0; k < it_changes.size(); ++k)
        if (it_changes[k].n > 0)
            std::fprintf(stderr, " %zu:%.1f/%.1f/%.2f/%.0f(n%.0f)", k + 1, it_changes[k].mean(), it_returns[k].mean(),
                         it_full[k].mean(), it_viol[k].mean(), it_changes[k].n);
    std::fprintf(stderr, "\n");
    // where the mode-set solves go (docs/decisions/038): per phase and route, the calls, their
    // mean held rows and CPU time, over the first two steps (from rest) and the rest
    auto routes_table = [&](const char* label, std::size_t from, std::size_t to) {
        detail::sparse::RouteStats sum[detail::sparse::phase_count];
        double phase_s[detail::sparse::phase_count] = {};
        long transition = 0, recallable = 0, seen_earlier = 0;
        for (std::size_t i = from; i < std::min(to, steps.size()); ++i) {
            recallable += steps[i].recallable;
            seen_earlier += steps[i].seen_earlier;
            if (steps[i].solves == 0) continue;
            ++transition;
            for (int ph = 0; ph < detail::sparse::phase_count; ++ph) {
                sum[ph].add(steps[i].phase[ph]);
                phase_s[ph] += steps[i].phase_s[ph];
            }
        }
        std::fprintf(stderr, "# routes, %s (%ld transition steps; sets solved again in the same step %ld, solved in an earlier step %ld): per phase calls / mean held rows / CPU s per route; new-set solves per transition step; the phase's CPU s\n",
                     label, transition, recallable, seen_earlier);
        detail::sparse::RouteStats all;
        double all_s = 0.0;
        for (int ph = 0; ph < detail::sparse::phase_count; ++ph) {
            all.add(sum[ph]);
            all_s += phase_s[ph];
        }
        for (int ph = 0; ph <= detail::sparse::phase_count; ++ph) {
            const auto& rs = ph < detail::sparse::phase_count ? sum[ph] : all;
            std::fprintf(stderr, "#   %-10s", ph < detail::sparse::phase_count ? detail::sparse::phase_name(ph) : "all");
            for (int r = 0; r < detail::sparse::route_count; ++r)
                if (rs.count[r] > 0)
                    std::fprintf(stderr, " %s %ld/%.0f/%.2fs", detail::sparse::route_name(r), rs.count[r],
                                 rs.held[r] / static_cast<double>(rs.count[r]), rs.seconds[r]);
            std::fprintf(stderr, " | %.2f per step | %.2f s (KLU pivoted %ld)\n",
                         transition > 0 ? static_cast<double>(rs.solves()) / static_cast<double>(transition) : 0.0,
                         ph < detail::sparse::phase_count ? phase_s[ph] : all_s, rs.fixed_pivoted);
        }
    };
    routes_table("step 1", 0, 1);
    routes_table("steps 1-2", 0, 2);
    routes_table("steps 3-", 2, steps.size());
    routes_table("all steps", 0, steps.size());
}
BENCHMARK(TransitionStudy)
    ->ArgNames({"el", "stack", "ms", "way", "trace", "schur", "fixed", "path", "hits", "repair"})
    // decision 037: the changes one by one on the graduated 10 x 400, 30 / 100 ms, with the trace
    ->ArgsProduct({{400}, {1}, {30, 100}, {0, 1, 3, 7, 15, 23, 29, 31}, {1}, {0}, {-1}, {0}, {-1}, {-1}})
    // before / after: graduated 50 / 100 / 200 / 400 and identical 400, 30 / 100 ms; the same
    // meshes bonded (the targets' reference)
    ->ArgsProduct({{50, 100, 200, 400}, {1}, {100}, {0, 29, 31}, {0}, {0}, {-1}, {0}, {-1}, {-1}})
    ->ArgsProduct({{400}, {2}, {30, 100}, {0, 29, 31}, {0, 1}, {0}, {-1}, {0}, {-1}, {-1}})
    ->Args({400, 3, 100, 29, 0, 0, -1, 0, -1, -1})->Args({400, 4, 100, 29, 0, 0, -1, 0, -1, -1})
    // decision 038: the identical (and graduated) 10 x 400 stack's routes: the held sets' own KLU
    // systems (fixed 2 the fixed pattern, 3, 4 the default), the Schur way's limit
    ->ArgsProduct({{400}, {1, 2}, {30, 100}, {0, 32, 61}, {0, 1}, {0, 1, 200, 1000}, {2, 3, 4}, {0}, {-1}, {-1}})
    // decisions 037 and 038 together: before both (0), 037 alone (29), 038 alone (32), both (61)
    ->ArgsProduct({{50, 100, 200, 400}, {1}, {100}, {0, 29, 32, 61}, {0}, {0}, {-1}, {0}, {-1}, {-1}})
    ->ArgsProduct({{400}, {2}, {100}, {0, 29, 32, 61}, {0}, {0}, {-1}, {0}, {-1}, {-1}})
    ->ArgsProduct({{100, 200, 400}, {3, 4}, {100}, {61}, {0}, {0}, {-1}, {0}, {-1}, {-1}})
    // decision 040: the homotopy (path) on, a new base past 24 / 48 (its default) / 96 changed
    // rows or none (-1), against off (path 0: registered above without the trace), graduated
    // and identical 10 x 400 and graduated 100 / 200, 100 ms, every default else (way 61)
    ->ArgsProduct({{400}, {1, 2}, {100}, {61}, {1}, {0}, {-1}, {0, 24, 48, 96, -1}, {-1}, {-1}})
    ->ArgsProduct({{400}, {1, 2}, {100}, {61}, {0}, {0}, {-1}, {24, 48, 96, -1}, {-1}, {-1}})
    // the limit on the start modes' failing conditions: none (0), 300, 500 (the default, -1)
    ->ArgsProduct({{400}, {1, 2}, {100}, {61}, {0, 1}, {0}, {-1}, {48}, {0, 300}, {-1}})
    ->ArgsProduct({{100, 200}, {1}, {100}, {61}, {1}, {0}, {-1}, {0, 48}, {-1}, {-1}})
    ->ArgsProduct({{100, 200}, {1}, {100}, {61}, {0}, {0}, {-1}, {48}, {-1}, {-1}})
    // decision 041: the homotopy from rest off (way 125) against on (61, registered above for
    // graduated 100 / 200 / 400 and identical 400), with and without the trace; identical 100 / 200
    ->ArgsProduct({{100, 200, 400}, {1}, {100}, {125}, {0, 1}, {0}, {-1}, {48}, {-1}, {-1}})
    ->ArgsProduct({{400}, {2}, {100}, {125}, {0, 1}, {0}, {-1}, {48}, {-1}, {-1}})
    ->ArgsProduct({{100, 200}, {2}, {100}, {61, 125}, {0, 1}, {0}, {-1}, {48}, {-1}, {-1}})
    // decision 042: the homotopy's repairs off (0, the way before), the clamp's slip entry alone
    // (1), both (-1, the defaults), graduated and identical 100 / 200 / 400, 100 ms
    ->ArgsProduct({{100, 200, 400}, {1, 2}, {100}, {61}, {0, 1}, {0}, {-1}, {48}, {-1}, {0, 1}})
    // issue 27's per-doubling target from 50 elements per half leaf: graduated 10 x 50 with every
    // default and bonded (benchmarks/transition_targets.sh)
    ->Args({50, 1, 100, 61, 0, 0, -1, 48, -1, -1})->Args({50, 3, 100, 61, 0, 0, -1, 0, -1, -1})
    // decision 045: the homotopy's base kept across steps off (repair 7, the way before) against
    // on (-1, the defaults), graduated and identical 100 / 200 / 400, 100 ms
    ->ArgsProduct({{100, 200, 400}, {1, 2}, {100}, {61}, {0, 1}, {0}, {-1}, {48}, {-1}, {7}})
    ->Unit(benchmark::kMillisecond)->Iterations(1);

/// Decision 050: the automatic path's choice (resolve_contact_path) against both paths forced,
/// every other default. args: elements per half leaf, stack (0 the paper example, friction; 5 the
/// paper example bonded; 6 the paper example, friction, elastic interfaces; 1 / 2 graduated /
/// identical 10 leaves, friction, elastic interfaces, as TransitionStudy; 3 / 4 the same bonded),
/// simulated ms, path (0 automatic, 1 dense, 2 sparse). Counters as ElasticRuns (cpu_s_per_sim_s:
/// CPU s per simulated second, set-up and stepping); the answer at the end to stderr (17 digits).
void PathChoice(benchmark::State& state) {
    const int elements = static_cast<int>(state.range(0));
    const int stack = static_cast<int>(state.range(1));
    ModelSpec spec = stack == 0 || stack == 6 ? paper_example(PaperCase::friction, PaperExampleOptions{elements})
                     : stack == 5             ? paper_example(PaperCase::bonded, PaperExampleOptions{elements})
                     : stack == 1 || stack == 3 ? graduated_stack(elements, 10)
                                                : paper_stack(PaperCase::friction, elements, 10);
    for (auto& f : spec.interfaces) {
        if (stack == 1 || stack == 2 || stack == 6) f.contact = InterfaceContact::elastic;
        if (stack == 3 || stack == 4) f.law = InterfaceLaw::bonded;
    }
    SimulationOptions so;
    so.t_end_s = 1e-3 * static_cast<double>(state.range(2));
    so.stop_on_nonconvergence = false;
    const int path = static_cast<int>(state.range(3));
    so.contact_path = path == 1 ? ContactPath::dense : path == 2 ? ContactPath::sparse : ContactPath::automatic;
    ElasticFigures fig;
    for (auto _ : state) fig.run(spec, so);
    fig.put(state, so.t_end_s);
    const int rows = fig.components;
    state.counters["auto_sparse"] =
        resolve_contact_path(ContactPath::automatic, rows, so.solver.kind) == ContactPath::sparse ? 1.0 : 0.0;
    std::fprintf(stderr, "# PathChoice el:%d stack:%d path:%d rows %d answer: w %.17g m, dissipated %.17g J, |z| %.17g\n",
                 elements, stack, path, rows, fig.final_w_m, fig.dissipated_j, fig.z_norm);
}
BENCHMARK(PathChoice)
    ->ArgNames({"el", "stack", "ms", "path"})
    // the graduated 10-leaf spring (about 10.8 rows per element per half leaf) and the paper
    // example's 3 leaves on finer meshes (about 3.9), 100 ms; the crossover's neighbourhood
    ->ArgsProduct({{8, 12, 14, 16, 18, 25, 50, 100}, {1, 3}, {100}, {0, 1, 2}})
    ->ArgsProduct({{20, 30, 40, 50, 80, 160}, {0, 5, 6}, {100}, {0, 1, 2}})
    // whole seconds: the paper example (friction, bonded) and the graduated 10 x 12 / 14 friction
    ->ArgsProduct({{20}, {0, 5}, {1000}, {0, 1, 2}})->ArgsProduct({{12, 14}, {1}, {1000}, {0, 1, 2}})
    // identical 10 leaves, friction and bonded
    ->ArgsProduct({{8, 12, 25, 50}, {2, 4}, {100}, {0, 1, 2}})
    ->Unit(benchmark::kMillisecond)->Iterations(1);

BENCHMARK_MAIN();
