#pragma once
/// @file summary.hpp
/// The results of a run: the text summary on stdout and the --summary JSON file.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "options.hpp"
#include "run.hpp"
#include "stackbeam/model/model.hpp"
#include "stackbeam/post/fancher.hpp"
#include "stackbeam/post/hysteresis.hpp"

namespace stackbeam::cli {

/// The loop figures of the last period of a periodic loading, or a note why there are none,
/// and Fancher's model fitted to that loop (docs/reduced-model.md), or a note why not.
struct LoopFigures {
    std::optional<HysteresisMetrics> metrics;
    std::string note;
    std::optional<FancherFit> fancher;
    std::string fancher_note;
    std::vector<std::pair<double, double>> fancher_loop;  ///< the fitted model over the cycle: (w [m], F [N])
};
/// The last cycle's figures of a finished run (an interrupted one has none).
LoopFigures loop_figures(const RunRequest& request, const RunResult& result);

/// The text summary of a finished run on stdout.
void print_summary(const RunRequest& request, const System& system, const RunResult& result, const LoopFigures& loop);

/// The JSON summary's text (what write_json_summary writes; the Python module's Result.summary).
std::string json_summary(const RunRequest& request, const Model& model, const RunResult& result, const LoopFigures& loop);

/// Writes the JSON summary to request.summary (via FILE.partial, renamed when written).
/// An interrupted run's summary says so ("interrupted": true, the signal, the time
/// reached, the energies of the last whole record, the .partial files).
void write_json_summary(const RunRequest& request, const Model& model, const RunResult& result, const LoopFigures& loop);

}  // namespace stackbeam::cli
