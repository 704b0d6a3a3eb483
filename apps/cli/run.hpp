#pragma once
/// @file run.hpp
/// One run of `stackbeam simulate`: the rows streamed to FILE.partial files, the
/// progress line, and a clean stop on SIGINT / SIGTERM.
///
/// Interruption: the signal handler only sets a flag (async-signal-safe); the run
/// checks it before writing each record (simulate's per-record callback), drops the
/// record in progress and stops. Every file then ends on a whole row: the CSV, the
/// --pairs, --nodes and --stresses files hold the records before it, and they keep their .partial names, so
/// that nobody mistakes them for a complete run. The --events log is not written
/// (the library hands it over at the end of a run). The --summary is written, marked
/// "interrupted", with the time reached and the energies of the last whole record.
/// The exit status is then 128 + the signal: 130 (SIGINT), 143 (SIGTERM).
///
/// The run itself is the library's (stackbeam/run/run.hpp, run_scenario); this file is its
/// sink: the rows to the files, the progress line, the stack at the extreme deflections.
#include <string>
#include <vector>

#include "options.hpp"
#include "stackbeam/fe/system.hpp"
#include "stackbeam/run/run.hpp"
#include "stackbeam/run/summary_json.hpp"

namespace stackbeam::cli {

/// The stack at one record: every leaf's nodes and every pair (the deformed stack figure).
struct StackSnapshot {
    double t_s = 0.0, w_m = 0.0, seat_rotation_rad = 0.0;  ///< the record's t [s], w [m], theta_R [rad]
    std::vector<LeafNodes> nodes;
    std::vector<PairRecord> pairs;
    std::vector<LeafStresses> stresses;  ///< --stack-color stress: every leaf's stresses (whole leaves); else empty
};

struct RunResult {
    RunSummary summary;               ///< the library's: stats, records, report, loop figures, stepper
    int signal = 0;                   ///< the signal that stopped the run, 0 if it finished
    /// The files written, as the JSON summary names them: csv_file where the rows are (FILE, or
    /// FILE.partial when interrupted), likewise pairs_file, nodes_file, stresses_file ("" none);
    /// events_file the event log written ("" none)
    SummaryContext files;
    /// With --plot: the stack at the records of the largest and the smallest w (the first such record),
    /// or of the seat's rotation theta_R where the loading loads the seat (a windup run: loads_the_seat).
    StackSnapshot stack_at_max, stack_at_min;
    bool snapshots_by_seat_rotation = false;  ///< stack_at_max / _min are theta_R's
};

/// Installs the SIGINT / SIGTERM handlers that ask the run to stop.
void install_interrupt_handlers();

/// Installs `handler` for SIGINT and SIGTERM (it must be async-signal-safe: set a flag).
void install_stop_handlers(void (*handler)(int));

/// Runs `request` on `system`, writing the CSV, --pairs and --events files.
RunResult run(const SimulateRequest& request, const System& system);

}  // namespace stackbeam::cli
