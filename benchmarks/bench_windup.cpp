// The windup rig's cost against the vertical rig's (issue 44's target: a windup rig loop of the
// graduated 10-leaf spring costs about what the vertical rig loop costs on the same mesh, within
// 1.5x; docs/performance.md, "Windup rig", decision 068).
//
// WindupRig/windup:W/cf:C: graduated_stack(400, 10) (the tests' graduated spring: the paper's leaf,
// mu = 0.5, two 1000 N clamps) with elastic interfaces (the derived layer: 10 x 400 rigid is a mesh
// artefact, docs/performance.md), the full model (the windup rig needs it), massless leaves, one loop
// of 1 s at dt = 10 ms (100 steps; Model::build and the System inside the timing, as a run):
//  - windup:0 the vertical rig, w(t) = 20 mm tri(t / 1 s), with the seat's rotation held at 0 by a
//    constant windup rig: the only way mode newmark with massless leaves takes a vertical rig, so the
//    same stepper as windup:1 (the symmetric spring's seat does not turn under w: the same problem);
//  - windup:1 the windup rig, theta_R(t) = 0.04 rad tri(t / 1 s), w held at 0;
//  - cf:1 the same two loops in mode closed-form (windup:0 the vertical rig alone; windup:1 the windup
//    rig with w held at 0 by the vertical rig).
// Counters: steps, contact iterations and factorisations per step, the loop's peak |force| or |moment|.
#include <benchmark/benchmark.h>

#include <cmath>

#include "stackbeam/fe/system.hpp"
#include "stackbeam/time/simulation.hpp"
#include "stackbeam/time/stepper.hpp"
#include "test_support.hpp"
#include "windup_cases.hpp"

using namespace stackbeam;
using testing::graduated_stack;
using testing::triangle;
using testing::with_elastic_interfaces;

namespace {

void WindupRig(benchmark::State& state) {
    const bool windup = state.range(0) != 0, closed_form = state.range(1) != 0;
    ModelSpec spec = with_elastic_interfaces(graduated_stack(400, 10));
    spec.symmetry = Symmetry::full;
    spec.rigid_body.initial_velocity_m_per_s = 0.0;  // the rigs prescribe the motion from rest
    SimulationOptions so;
    so.mode = closed_form ? Mode::closed_form : Mode::newmark;
    so.dt_s = 0.01;
    so.t_end_s = 1.0;
    so.loading.kind = LoadingKind::prescribed_displacement;
    so.loading.displacement_m = windup ? TimeFunction{} : triangle(0.02);
    if (windup) so.loading.seat_rotation_rad = triangle(0.04);
    else if (!closed_form) so.loading.seat_rotation_rad = TimeFunction{};  // theta_R held at 0
    long steps = 0, iterations = 0, factorizations = 0;
    double peak = 0.0;
    for (auto _ : state) {
        const System system(Model::build(spec));
        const auto stepper = make_stepper(system, so);
        steps = iterations = factorizations = 0;
        peak = 0.0;
        while (stepper->current().t_s < so.t_end_s - 0.5 * so.dt_s) {
            stepper->advance();
            const StepRecord& r = stepper->current();
            ++steps;
            iterations += r.contact_iterations;
            factorizations += r.factorizations;
            peak = std::max(peak, std::abs(windup ? r.seat_moment_n_m : r.spring_force_n));
        }
        benchmark::DoNotOptimize(peak);
    }
    state.counters["steps"] = static_cast<double>(steps);
    state.counters["iter_per_step"] = static_cast<double>(iterations) / static_cast<double>(steps);
    state.counters["fact_per_step"] = static_cast<double>(factorizations) / static_cast<double>(steps);
    state.counters["peak"] = peak;
}

}  // namespace

BENCHMARK(WindupRig)
    ->ArgNames({"windup", "cf"})
    ->Args({0, 0})->Args({1, 0})->Args({0, 1})->Args({1, 1})
    ->Unit(benchmark::kMillisecond)->Iterations(1);
