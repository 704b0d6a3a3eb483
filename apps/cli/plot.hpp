#pragma once
/// @file plot.hpp
/// --plot: PNG figures of a run with gnuplot from its CSV.
#include <optional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace stackbeam::cli {

/// gnuplot's PNG terminal ("pngcairo" or "png"), or none and why in `note` (no gnuplot on
/// PATH, no PNG terminal).
std::optional<std::string> plot_terminal(std::string& note);

/// gnuplot's PNG terminal ("pngcairo" or "png"), or none and why in `note` (no gnuplot on
/// PATH, no PNG terminal).
std::optional<std::string> plot_terminal(std::string& note);

/// Displacement, forces, friction force at the probe and the loop (spring force against
/// w) as PREFIX_*.png. Returns the files written, or none and a note why in `note`.
/// `fitted_loop`: Fancher's model fitted to the last cycle, (w [m], F [N]) (summary.hpp's
/// LoopFigures::fancher_loop), drawn over the loop (written to PREFIX_fancher_loop.csv);
/// empty: none.
std::vector<std::string> plot_run(const std::string& csv, const std::string& prefix, std::string& note,
                                  const std::vector<std::pair<double, double>>& fitted_loop = {});

}  // namespace stackbeam::cli
