#pragma once
// Private to lib/study/fit*.cpp: the scenarios of trial values, as sweep points.
#include <vector>

#include "stackbeam/study/fit.hpp"

namespace stackbeam::detail {

/// The zip sweep whose point q is the base scenario of `spec` with values[q] (one value per
/// parameter, parameters' units) set at the parameters' keys, and `loop`'s own settings when
/// `loop` is given. SweepPoints(...).point(q) makes and checks it: an InputError names the key.
/// The one place a trial scenario is built (the runs, the bound checks, the fitted scenario).
SweepSpec trial_sweep(const FitSpec& spec, const std::vector<std::vector<double>>& values, const MeasuredLoop* loop);

}  // namespace stackbeam::detail
