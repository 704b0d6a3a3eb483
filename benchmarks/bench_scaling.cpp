// Benchmarks of the many-leaf stacks (part of bench_stackbeam; figures and the commands that
// made them: docs/performance.md).
//
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
//  - Transitions, FrictionMeshRatioRuns: the sparse path's transition methods, and the
//    friction-mesh ratio against the fixed point on the friction limits.
#include "bench_support.hpp"

using namespace stackbeam;
using namespace stackbeam::bench;

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
        SimulationOptions so = run_to(t_sim, path);
        ClosedFormStepper st(s, so);
        setup = seconds_since(t0);
        steps = static_cast<long>(std::ceil(t_sim / so.dt_s - 1e-9));
        factorizations = newton = 0.0;
        for (long i = 0; i < steps; ++i) {
            factorizations += st.advance().factorizations;
            newton += st.last_solve().newton_iterations;
            if (i == 0) first_step = seconds_since(t0) - setup;
        }
        total = seconds_since(t0);
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
        SimulationOptions so = run_to(t_sim, ContactPath::sparse);
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
            worst_step = std::max(worst_step, seconds_since(t1));
            newton += st.last_solve().newton_iterations;
            smoothing += st.last_solve().smoothing_iterations;
            passes += st.last_solve().tresca_iterations;
            if (st.last_solve().fell_back) ++tresca;
        }
        total = seconds_since(t0);
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
        SimulationOptions so = run_to(t_sim, ContactPath::sparse);
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
            worst_step = std::max(worst_step, seconds_since(t1));
            passes += st.last_solve().tresca_iterations;
            most_passes = std::max(most_passes, static_cast<double>(st.last_solve().tresca_iterations));
            if (st.last_solve().fell_back) ++fell_back;
        }
        total = seconds_since(t0);
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
