#pragma once
/// @file run.hpp
/// One run of `stackbeam simulate`: the rows streamed to FILE.partial files, the
/// progress line, and a clean stop on SIGINT / SIGTERM.
///
/// Interruption: the signal handler only sets a flag (async-signal-safe); the run
/// checks it before writing each record (simulate's per-record callback), drops the
/// record in progress and stops. Every file then ends on a whole row: the CSV, the
/// --pairs and the --nodes files hold the records before it, and they keep their .partial names, so
/// that nobody mistakes them for a complete run. The --events log is not written
/// (the library hands it over at the end of a run). The --summary is written, marked
/// "interrupted", with the time reached and the energies of the last whole record.
/// The exit status is then 128 + the signal: 130 (SIGINT), 143 (SIGTERM).
#include <string>
#include <vector>

#include "options.hpp"
#include "stackbeam/fe/system.hpp"
#include "stackbeam/time/cvode_stepper.hpp"

namespace stackbeam::cli {

/// What the summary needs of the records, gathered one record at a time (also
/// complete for an interrupted run, whose records the library never returns).
struct RunStats {
    StepRecord first, last;
    long records = 0;
    long contact_iterations = 0;  ///< sum over the records
    int max_contact_iterations = 0;
    double max_abs_balance_j = 0.0;
    double w_min_m = 0.0, w_max_m = 0.0, force_min_n = 0.0, force_max_n = 0.0;
    void add(const StepRecord& r);
};

/// The stack at one record: every leaf's nodes and every pair (the deformed stack figure).
struct StackSnapshot {
    double t_s = 0.0, w_m = 0.0;
    std::vector<LeafNodes> nodes;
    std::vector<PairRecord> pairs;
};

struct RunResult {
    RunStats stats;
    std::vector<StepRecord> records;  ///< every record (empty when interrupted)
    RunReport report;                 ///< the library's counters (default when interrupted)
    int signal = 0;                   ///< the signal that stopped the run, 0 if it finished
    double wall_s = 0.0;              ///< wall time of the build and the run [s]
    std::string csv_file;             ///< where the rows are (FILE, or FILE.partial when interrupted)
    std::string pairs_file;           ///< likewise for --pairs ("" none)
    std::string nodes_file;           ///< likewise for --nodes ("" none)
    /// With --plot: the stack at the records of the largest and the smallest w (the first such record).
    StackSnapshot stack_at_w_max, stack_at_w_min;
    std::string events_file;          ///< the event log written ("" none)
};

/// Installs the SIGINT / SIGTERM handlers that ask the run to stop.
void install_interrupt_handlers();

/// Installs `handler` for SIGINT and SIGTERM (it must be async-signal-safe: set a flag).
void install_stop_handlers(void (*handler)(int));

/// Runs `request` on `system`, writing the CSV, --pairs and --events files.
RunResult run(const RunRequest& request, const System& system);

}  // namespace stackbeam::cli
