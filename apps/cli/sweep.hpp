#pragma once
/// @file sweep.hpp
/// `stackbeam sweep SPEC.toml`: a thin layer over the library's sweep
/// (stackbeam/study/sweep.hpp, sweep_output.hpp): the arguments, progress on a
/// terminal, SIGINT / SIGTERM, the figures (sweep_plot.cpp) and, when built with MPI,
/// the points spread over the ranks of `mpirun` (sweep_mpi.cpp). docs/sweep.md.
#include <CLI/CLI.hpp>

#include <string>

#include "sweep_mpi.hpp"

namespace stackbeam::cli {

/// `sweep`'s arguments as given.
struct SweepArgs {
    std::string spec;
    int jobs = 0;           ///< 0: not given
    std::string out_dir;
    bool restart = false;
    bool keep_series = false;
    bool progress = false;
    bool no_plot = false;
    int stop_after = 0;     ///< hidden, for tests: stop as on SIGINT after this many points (0: never)
};

/// Adds the subcommand `sweep` to `app` with every flag, storing them in `args`.
CLI::App* add_sweep_command(CLI::App& app, SweepArgs& args);

/// Runs the sweep; returns the exit status (0 all points ok, 3 some failed, 130 / 143
/// stopped). `world`: mpi_start's (rank 0 writes the results, the others run points). Throws InputError / ArgumentError for a bad spec or argument (exit 2).
int run_sweep_command(const SweepArgs& args, MpiWorld world);

}  // namespace stackbeam::cli
