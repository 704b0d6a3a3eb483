#pragma once
// `stackbeam fmu SCENARIO.toml --out spring.fmu`: the scenario's spring as an FMI 2.0
// co-simulation FMU (docs/fmu.md; the exporter: fmu/include/stackbeam_fmu/export.hpp).
#include <CLI/CLI.hpp>

#include <string>

namespace stackbeam::cli {

struct FmuArgs {
    std::string scenario;  ///< the scenario file
    std::string out;       ///< the FMU to write
    std::string binary;    ///< the FMU's binary (empty: this build's)
};

/// Adds the subcommand `fmu` to `app`, filling `args`; returns it.
CLI::App* add_fmu_command(CLI::App& app, FmuArgs& args);
/// Writes the FMU; prints one line. Returns the exit status (0), throws InputError for bad input.
int run_fmu_command(const FmuArgs& args);

}  // namespace stackbeam::cli
