#pragma once
/// @file options.hpp
/// `stackbeam simulate`'s arguments: the flags (the integrator's from the library's
/// option table, option_table.hpp, the rest the command line's own) and their
/// translation into a ModelSpec, SimulationOptions and the output files.
#include <CLI/CLI.hpp>

#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>

#include "stackbeam/io/scenario.hpp"
#include "stackbeam/model/model.hpp"
#include "stackbeam/time/simulation.hpp"

namespace stackbeam::cli {

/// Exit status of `stackbeam`.
constexpr int exit_ok = 0;
constexpr int exit_other = 1;
constexpr int exit_input = 2;
constexpr int exit_solver = 3;

/// Bad command-line input; reported like stackbeam::InputError ("--flag: ...").
struct ArgumentError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// The files of a run ("" = none): --out (the records' CSV, required), --events, --summary,
/// --pairs, --nodes, --stresses and the --plot prefix (or the scenario's outputs.*).
struct OutputPaths {
    std::string out, events, summary, pairs, nodes, stresses, plot;
};

/// The text of `simulate`'s arguments as given (the files as given: OutputPaths).
struct SimulateArgs : OutputPaths {
    std::string case_name;
    std::string scenario;
    std::string elements;      ///< "" = the library's default (PaperExampleOptions)
    bool full_model = false;
    std::string beam_density;  ///< "" = the leaves' own density (the case's: 0, massless)
    std::string interface;     ///< --interface: "" = the case's or the file's contact law (rigid | elastic)
    std::string stack_color;   ///< --stack-color: "" = state
    bool quiet = false;
    std::map<std::string, std::string> table_text;  ///< flag (or alias) of the option table -> text
    std::set<std::string> given;                     ///< the flags given on the command line
};

/// Adds the subcommand `simulate` to `app` with every flag, storing their text in `args`.
CLI::App* add_simulate_command(CLI::App& app, SimulateArgs& args);

/// One run, ready to go: everything checked (the files: OutputPaths, out required).
struct SimulateRequest : OutputPaths {
    ModelSpec spec;
    SimulationOptions options;
    std::string setup;                              ///< the summary's first line: the case or the scenario
    bool stack_stress = false;  ///< --stack-color stress: the deformed stack's leaves coloured by their fibre stresses
    bool quiet = false;
    std::optional<Scenario> scenario;  ///< the file read, for --scenario (its keys' locations)
};

/// Reads the arguments (and the scenario file): throws ArgumentError naming the flag,
/// or InputError naming the scenario's key, line and column, before any work.
SimulateRequest make_request(const SimulateArgs& args);

}  // namespace stackbeam::cli
