// libFuzzer target: the scenario reader, parse_scenario(text, name), on any bytes.
//
// The contract under test (include/stackbeam/io/scenario.hpp, errors.hpp): whatever
// the text, parse_scenario returns a validated Scenario or throws InputError naming a
// field (or SolverError). Any other exception is a bug (reported here and aborted, so
// that libFuzzer saves the input), as is a crash, a hang, running out of memory or a
// sanitizer report. Built with -fsanitize=fuzzer by STACKBEAM_BUILD_FUZZERS=ON
// (Clang); the same file with fuzz/replay_main.cpp is the replay test of the normal
// builds (docs/fuzzing.md).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "stackbeam/errors.hpp"
#include "stackbeam/io/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        const stackbeam::Scenario s = stackbeam::parse_scenario(text, "fuzz.toml");
        // a Scenario returned is validated: its model has leaves and the source is kept
        if (s.model.leaves.empty() || s.source != "fuzz.toml") {
            std::fprintf(stderr, "fuzz_scenario: parse_scenario returned an unvalidated scenario\n");
            std::abort();
        }
    } catch (const stackbeam::InputError& e) {
        // bad input must be named: a field (key path, option or file name) and a message
        if (e.field().empty() || std::string(e.what()).empty()) {
            std::fprintf(stderr, "fuzz_scenario: InputError without a field: '%s'\n", e.what());
            std::abort();
        }
    } catch (const stackbeam::SolverError&) {
        // a numerical failure (the assembly's solve) is a stated outcome, not a bug
    } catch (const std::exception& e) {
        std::fprintf(stderr, "fuzz_scenario: parse_scenario threw an exception other than InputError/SolverError: %s\n",
                     e.what());
        std::abort();
    } catch (...) {
        std::fprintf(stderr, "fuzz_scenario: parse_scenario threw a non-standard exception\n");
        std::abort();
    }
    return 0;
}
