#pragma once
// What the benchmark files share (bench_*.cpp, one program bench_stackbeam; docs/performance.md):
// the headers, the many-leaf stacks of the tests and the figures of one ElasticRuns-style run.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "contact/sparse/driver/switches.hpp"  // the sparse path's methods under their internal names (lib/)
#include "contact/sparse/driver/trace.hpp"     // the transition study's trace (lib/, docs/decisions/036)
#include "stackbeam/errors.hpp"
#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/time/closed_form_stepper.hpp"
#include "stackbeam/time/cvode_stepper.hpp"
#include "stackbeam/time/simulation.hpp"
#include "stackbeam/time/stepper.hpp"
#include "test_support.hpp"  // the many-leaf stacks (tests/)

namespace stackbeam::bench {

// The many-leaf stacks, shared with the tests (tests/test_support.hpp): paper_stack (the
// paper's example with its leaf repeated: identical pinned leaves, the same interfaces and
// clamps) and graduated_stack (leaves shortened downwards, free ends, two clamps).
using testing::graduated_stack;
using testing::paper_stack;

/// Wall time since `t0` [s].
inline double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// The default options (mode closed-form, dt 1 ms) of a run to t_sim_s [s] on the contact path `path`.
inline SimulationOptions run_to(double t_sim_s, ContactPath path) {
    SimulationOptions so;
    so.t_end_s = t_sim_s;
    so.contact_path = path;
    return so;
}

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
        total = seconds_since(t0);
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

}  // namespace stackbeam::bench
