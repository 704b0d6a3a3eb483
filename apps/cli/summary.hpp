#pragma once
/// @file summary.hpp
/// The results of a run: the text summary on stdout and the --summary JSON file. The figures
/// are the library's (stackbeam/run/: RunSummary, summary_json); this file only formats them.
#include <string>

#include "options.hpp"
#include "run.hpp"
#include "stackbeam/model/model.hpp"
#include "stackbeam/run/summary_json.hpp"

namespace stackbeam::cli {

/// The text summary of a finished run on stdout.
void print_summary(const SimulateRequest& request, const System& system, const RunResult& result);

/// The JSON summary's context: the files written and, for an interrupted run, the signal.
SummaryContext summary_context(const RunResult& result);

/// Writes the JSON summary to request.summary (via FILE.partial, renamed when written).
/// An interrupted run's summary says so ("interrupted": true, the signal, the time
/// reached, the energies of the last whole record, the .partial files).
void write_json_summary(const SimulateRequest& request, const Model& model, const RunResult& result);

}  // namespace stackbeam::cli
