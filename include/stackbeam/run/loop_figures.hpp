#pragma once
/// @file loop_figures.hpp
/// The figures of a periodic run's last cycle, computed here once for every front-end: the
/// command line's summary, the Python module's Result.summary, the sweep's point figures.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "stackbeam/post/fancher.hpp"
#include "stackbeam/post/hysteresis.hpp"
#include "stackbeam/time/simulation.hpp"

namespace stackbeam {

/// The loop figures of the last period of a periodic loading (hysteresis.hpp), or a note why
/// there are none, and Fancher's model fitted to that loop (fancher.hpp, docs/reduced-model.md),
/// or a note why not.
struct LoopFigures {
    std::optional<HysteresisMetrics> metrics;
    std::string note;          ///< why there are no metrics ("" when there are)
    std::optional<FancherFit> fancher;
    std::string fancher_note;  ///< why there is no fit ("" when there is one, or no metrics)
    std::vector<std::pair<double, double>> fancher_loop;  ///< the fitted model over the cycle: (w [m], F [N])
};

/// The last cycle's figures of `records` for a loading of period `period_s` [s] (0: not
/// periodic, then a note). The cycle: last_cycle(); the fit: fit_fancher_loop() over the
/// records hysteresis_metrics() read (t in [t_start, t_end]). Bad data (too few records in the
/// cycle) gives a note, never an exception.
LoopFigures loop_figures(const std::vector<StepRecord>& records, double period_s);

}  // namespace stackbeam
