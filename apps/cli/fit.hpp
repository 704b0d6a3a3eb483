#pragma once
/// @file fit.hpp
/// `stackbeam fit SPEC.toml`: a thin layer over the library's calibration
/// (stackbeam/study/fit.hpp): the arguments, progress on a terminal, SIGINT / SIGTERM,
/// the output directory (fitted.toml, fit.json, history.csv, loops.csv, loops.png).
/// docs/calibration.md.
#include <CLI/CLI.hpp>

#include <string>

namespace stackbeam::cli {

/// `fit`'s arguments as given.
struct FitArgs {
    std::string spec;
    int jobs = 0;          ///< 0: the machine's cores
    std::string out_dir;   ///< "": the spec's [outputs] directory, else SPEC's name without .toml + "_fit"
    bool restart = false;  ///< ignore an earlier history.csv (start from the spec's starts)
    bool no_plot = false;
    int stop_after = 0;    ///< tests: stop as on SIGINT after this many iterations (0: never)
};

/// Adds the subcommand `fit` to `app` with every flag, storing them in `args`.
CLI::App* add_fit_command(CLI::App& app, FitArgs& args);

/// Runs the fit; returns the exit status (0 done, 130 / 143 stopped: run again to resume).
/// Throws InputError / ArgumentError for a bad spec or argument (exit 2).
int run_fit_command(const FitArgs& args);

}  // namespace stackbeam::cli
