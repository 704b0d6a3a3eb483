// libFuzzer target: the sweep spec reader, parse_sweep_spec(text, name) then
// expand_points, on any bytes.
//
// The contract under test (include/stackbeam/study/sweep.hpp, errors.hpp): whatever the
// text, parse_sweep_spec returns a spec and expand_points its points, every one a
// validated scenario, or one of them throws InputError naming a field. Any other
// exception is a bug (reported here and aborted, so that libFuzzer saves the input), as
// is a crash, a hang, running out of memory or a sanitizer report. Built with
// -fsanitize=fuzzer by STACKBEAM_BUILD_FUZZERS=ON (Clang); the same file with
// fuzz/replay_main.cpp is the replay test of the normal builds (docs/fuzzing.md).
//
// Self-contained: a spec names its base scenario as a file relative to the spec; here
// the reader (parse_sweep_spec's ScenarioReader overload) hands out one fixed base
// scenario, kBase below (tests/sweep/rig_small.toml, comments dropped), whatever path the
// fuzzed text names, so that no file is read and every seed (tests/sweep,
// tests/bad_sweep, benchmarks/sweep) reaches its axes. The file reading itself is
// load_sweep_spec's, tested by tests/bad_sweep/missing_scenario.toml.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "stackbeam/errors.hpp"
#include "stackbeam/study/sweep.hpp"

namespace {

/// One of the base scenario's two identical leaves.
const char* const kLeaf = R"([[leaves]]
length_m = 0.5
x_start_m = 0.0
height_m = 0.005
width_m = 0.05
youngs_modulus_pa = 2e10
density_kg_per_m3 = 0.0
left_support = "pinned"
right_support = "pinned"
)";
/// The rest of the base scenario, after its leaves.
const char* const kRest = R"([[interfaces]]
law = "coulomb"
friction_coefficient = 0.5
[[clamps]]
x_m = 0.1
preload_n = 1000.0
[[clamps]]
x_m = 0.4
preload_n = 1000.0
[rigid_body]
mass_kg = 20.0
x_m = 0.25
[loading]
kind = "prescribed-displacement"
[loading.displacement_m]
shape = "triangle"
amplitude = 0.02
frequency_hz = 1.0
[mesh]
element_length_m = 0.05
symmetry = "half"
[probe]
interface_index = 0
x_m = 0.1
[integrator]
mode = "closed-form"
dt_s = 5e-3
t_end_s = 2.0
[integrator.solver]
kind = "exact"
tolerance_m = 1e-9
)";
const std::string kBase = std::string("description = \"fuzz: the base scenario of every fuzzed spec\"\n") + kLeaf + kLeaf + kRest;

/// Points expanded at most: a spec may ask for up to 10 million (point_count's limit),
/// each a scenario parsed and validated, which takes its time by design, not by a bug;
/// above this only point_count runs (the reading and checking of the axes is done by then).
constexpr int kMaxPoints = 64;

[[noreturn]] void bug(const char* what, const char* detail) {
    std::fprintf(stderr, "fuzz_sweep_spec: %s%s%s\n", what, detail[0] ? ": " : "", detail);
    std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    const auto read_base = [](const std::string&, const std::string&) { return kBase; };
    try {
        const stackbeam::SweepSpec spec = stackbeam::parse_sweep_spec(text, "fuzz/spec.toml", read_base);
        if (spec.source != "fuzz/spec.toml" || spec.scenario_text != kBase || spec.axes.empty())
            bug("parse_sweep_spec returned a spec without its source, base scenario or axes", "");
        const int n = stackbeam::point_count(spec);
        if (n < 1) bug("point_count is below 1 for a spec parse_sweep_spec returned", "");
        if (n <= kMaxPoints) {
            const std::vector<stackbeam::SweepPoint> points = stackbeam::expand_points(spec);
            if (static_cast<int>(points.size()) != n) bug("expand_points gave another number of points than point_count", "");
            for (int i = 0; i < n; ++i) {
                const stackbeam::SweepPoint& p = points[static_cast<std::size_t>(i)];
                // a point returned is validated: its index in table order, a value per axis, leaves
                if (p.index != i || p.values.size() != spec.axes.size() || p.scenario.model.leaves.empty())
                    bug("expand_points returned a point out of order or unvalidated", "");
            }
        }
    } catch (const stackbeam::InputError& e) {
        // bad input must be named: a field (key path, option or file name) and a message
        if (e.field().empty() || std::string(e.what()).empty()) bug("InputError without a field", e.what());
    } catch (const std::exception& e) {
        bug("the spec reader threw an exception other than InputError", e.what());
    } catch (...) {
        bug("the spec reader threw a non-standard exception", "");
    }
    return 0;
}
