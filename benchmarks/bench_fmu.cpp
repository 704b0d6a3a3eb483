// The FMU's cost against the library's own run (issue 45's target: the FMU stepping the rig
// scenario costs at most 10 % more than `stackbeam simulate` of the same run; figures and the
// command: docs/performance.md, "The FMU"). Built with the benchmarks when the FMU is
// (-DSTACKBEAM_BUILD_BENCHMARKS=ON and libzip).
//
//  - SimulateRig: Model::build + stackbeam::simulate() of scenarios/rig_friction.toml (3 s,
//    3000 steps, closed-form), the run `stackbeam simulate` makes, without its CSV and summary.
//  - FmuRig: the same run through the FMU's binary (binaries/linux64/stackbeam_spring.so,
//    dlopen()ed from the build tree with the scenario as its resources), driven as
//    tests/fmu/test_fmu.cpp's importer does: at each of the 3000 communication points
//    (h = dt) set the three seat inputs from the scenario's stroke, read the four outputs
//    (force, dissipated energy, strain energy, work: the records simulate() makes), fmi2DoStep.
//    Instantiation (the scenario read, the model built) is inside the timing, as in SimulateRig.
// Counter us_per_step: CPU microseconds per step. The ratio FmuRig / SimulateRig is the target's.
#include <benchmark/benchmark.h>
#include <dlfcn.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "fmi2FunctionTypes.h"
#include "stackbeam/io/scenario.hpp"
#include "stackbeam/time/simulation.hpp"
#include "variables.hpp"  // guid_of (fmu/src): the GUID the exporter would write

namespace fs = std::filesystem;
using namespace stackbeam;

namespace {

void quiet_logger(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...) {}
const fmi2CallbackFunctions kCallbacks = {quiet_logger, std::calloc, std::free, nullptr, nullptr};

std::string slurp(const std::string& path) {
    std::ifstream is(path, std::ios::binary);
    if (!is) throw std::runtime_error("cannot read " + path);
    std::stringstream s;
    s << is.rdbuf();
    return s.str();
}

/// The FMU's binary loaded once, its resources (the scenario) in a temporary directory.
struct Module {
    void* handle = nullptr;
    fs::path resources;
    std::string guid;
    Scenario scenario;
#define F(name) name##TYPE* name = nullptr;
    F(fmi2Instantiate) F(fmi2FreeInstance) F(fmi2SetupExperiment) F(fmi2EnterInitializationMode)
    F(fmi2ExitInitializationMode) F(fmi2SetReal) F(fmi2GetReal) F(fmi2DoStep)
#undef F
    Module() {
        const std::string text = slurp(BENCH_FMU_SCENARIO);
        guid = fmu::guid_of(text);
        resources = fs::temp_directory_path() / ("stackbeam_bench_fmu_" + std::to_string(::getpid()));
        fs::create_directories(resources);
        std::ofstream(resources / "scenario.toml", std::ios::binary) << text;
        scenario = parse_scenario(text, BENCH_FMU_SCENARIO);
        scenario.simulation.loading.prepare(false);
        handle = dlopen(BENCH_FMU_BINARY, RTLD_NOW | RTLD_LOCAL);
        if (handle == nullptr) throw std::runtime_error(std::string("dlopen: ") + dlerror());
#define F(name) name = reinterpret_cast<name##TYPE*>(dlsym(handle, #name));
        F(fmi2Instantiate) F(fmi2FreeInstance) F(fmi2SetupExperiment) F(fmi2EnterInitializationMode)
        F(fmi2ExitInitializationMode) F(fmi2SetReal) F(fmi2GetReal) F(fmi2DoStep)
#undef F
    }
    ~Module() {
        dlclose(handle);
        fs::remove_all(resources);
    }
};

Module& module() {
    static Module m;
    return m;
}

void SimulateRig(benchmark::State& state) {
    const Scenario& sc = module().scenario;
    long steps = 0;
    for (auto _ : state) {
        const System system(Model::build(sc.model));
        const auto records = simulate(system, sc.simulation);
        steps = static_cast<long>(records.size()) - 1;
        benchmark::DoNotOptimize(records.back().spring_force_n);
    }
    state.counters["steps"] = static_cast<double>(steps);
    state.counters["us_per_step"] =
        benchmark::Counter(static_cast<double>(steps) * 1e-6, benchmark::Counter::kIsIterationInvariantRate |
                                                                  benchmark::Counter::kInvert);
}

void FmuRig(benchmark::State& state) {
    Module& m = module();
    const SimulationOptions& so = m.scenario.simulation;
    const TimeFunction& w = so.loading.displacement_m;
    const long n = std::lround(so.t_end_s / so.dt_s);
    // value references as modelDescription.xml gives them (fmu/src/variables.hpp)
    const fmi2ValueReference in[3] = {fmu::vr_seat_displacement, fmu::vr_seat_velocity, fmu::vr_seat_acceleration};
    const fmi2ValueReference out[4] = {fmu::vr_seat_force, fmu::vr_dissipated, fmu::vr_strain_energy,
                                       fmu::vr_external_work};
    const std::string uri = "file://" + m.resources.string();
    for (auto _ : state) {
        fmi2Component c = m.fmi2Instantiate("bench", fmi2CoSimulation, m.guid.c_str(), uri.c_str(), &kCallbacks,
                                            fmi2False, fmi2False);
        if (c == nullptr) {
            state.SkipWithError("fmi2Instantiate failed");
            return;
        }
        m.fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2True, so.t_end_s);
        m.fmi2EnterInitializationMode(c);
        m.fmi2ExitInitializationMode(c);
        double y[4] = {0.0, 0.0, 0.0, 0.0};
        for (long i = 0; i <= n; ++i) {
            const double t = static_cast<double>(i) * so.dt_s;
            if (i > 0 && m.fmi2DoStep(c, t - so.dt_s, so.dt_s, fmi2True) != fmi2OK) {
                state.SkipWithError("fmi2DoStep failed");
                return;
            }
            const double u[3] = {w.value(t), w.derivative(t), w.second_derivative(t)};
            m.fmi2SetReal(c, in, 3, u);
            if (m.fmi2GetReal(c, out, 4, y) != fmi2OK) {
                state.SkipWithError("fmi2GetReal failed");
                return;
            }
        }
        benchmark::DoNotOptimize(y[0]);
        m.fmi2FreeInstance(c);
    }
    state.counters["steps"] = static_cast<double>(n);
    state.counters["us_per_step"] =
        benchmark::Counter(static_cast<double>(n) * 1e-6, benchmark::Counter::kIsIterationInvariantRate |
                                                              benchmark::Counter::kInvert);
}

}  // namespace

BENCHMARK(SimulateRig)->Unit(benchmark::kMillisecond)->Repetitions(5);
BENCHMARK(FmuRig)->Unit(benchmark::kMillisecond)->Repetitions(5);

BENCHMARK_MAIN();
