#pragma once
// Internal: the record loop of a run, once, for simulate() (simulation.cpp) and the run layer's
// run_scenario() (lib/run/run.cpp). A caller that wants another output per record reads it
// from the stepper in its callback.
#include <functional>

#include "stackbeam/fe/system.hpp"
#include "stackbeam/time/run_report.hpp"
#include "stackbeam/time/simulation.hpp"
#include "stackbeam/time/stepper.hpp"

namespace stackbeam::detail {

/// The steps of a run of `options` to t_end_s: ceil(t_end_s / dt_s), the records one more (t = 0).
long record_steps(const SimulationOptions& options);

/// Makes the stepper for `options` (make_stepper: validates them), then hands record 0 (the
/// initial state) and each step's record to `on_record` with the stepper that made it (its
/// pairs, nodes, stresses are those at the record's time). The stop check
/// (options.stop_requested) is asked before each step: true throws RunStopped naming the last
/// record's time. An exception from `on_record` ends the loop and reaches the caller. Returns
/// the stepper's report after the last record.
RunReport run_records(const System& system, const SimulationOptions& options,
                      const std::function<void(const Stepper& stepper, const StepRecord& record)>& on_record);

}  // namespace stackbeam::detail
