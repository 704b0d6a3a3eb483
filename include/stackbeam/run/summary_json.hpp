#pragma once
/// @file summary_json.hpp
/// A run's JSON summary (docs/cli.md, "--summary"): the command line's --summary file, the
/// Python module's Result.summary. The keys are the summary's content (RunSummary); a front-end
/// adds only where its files are and, for a run it stopped, why (SummaryContext).
#include <string>

#include "stackbeam/model/model.hpp"
#include "stackbeam/run/run.hpp"

namespace stackbeam {

/// What the front-end knows beyond the RunSummary: its files ("outputs"; "" none) and, for an
/// interrupted run, the signal ("signal", 0: not written) and a note ("interrupted_note").
struct SummaryContext {
    std::string csv_file, events_file, pairs_file, nodes_file, stresses_file;
    int signal = 0;
    std::string interrupted_note;
};

/// The JSON summary's text (2-space indent) of `summary`, a run of `model`.
std::string summary_json(const RunSummary& summary, const Model& model, const SummaryContext& context = {});

}  // namespace stackbeam
