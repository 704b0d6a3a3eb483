#pragma once
/// @file sweep_plot.hpp
/// The figures of a sweep with gnuplot, in DIR/figures/: the loop family along each
/// axis (the other axes at their middle value) and maps of the loss factor and the
/// dynamic rate over the first two numeric axes with two or more values.
#include <string>
#include <vector>

#include "stackbeam/study/sweep.hpp"

namespace stackbeam::cli {

/// Draws the figures from DIR/loops/ and the results; returns the PNG files written, or
/// none and why in `note`.
std::vector<std::string> plot_sweep(const std::string& directory, const SweepSpec& spec,
                                    const SweepPoints& points, const std::vector<PointResult>& results,
                                    std::string& note);

}  // namespace stackbeam::cli
