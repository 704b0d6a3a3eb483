#pragma once
/// @file plot.hpp
/// --plot: PNG figures of a run with gnuplot from its CSV.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "run.hpp"
#include "stackbeam/fe/system.hpp"

namespace stackbeam::cli {

/// gnuplot's PNG terminal ("pngcairo" or "png"), or none and why in `note` (no gnuplot on
/// PATH, no PNG terminal).
std::optional<std::string> plot_terminal(std::string& note);

/// Displacement, forces, friction force at the probe and the loop (spring force against
/// w) as PREFIX_*.png. Returns the files written, or none and a note why in `note`.
/// `fitted_loop`: Fancher's model fitted to the last cycle, (w [m], F [N]) (summary.hpp's
/// LoopFigures::fancher_loop), drawn over the loop (written to PREFIX_fancher_loop.csv);
/// empty: none. `windup` (the loading loads the seat): also the windup loop, seat_moment against
/// seat_rotation, as PREFIX_windup_loop.png. `probe` (the model has a probe pair, Model::probe_pair()
/// >= 0): the friction force at the probe, PREFIX_friction.png; without one (a single leaf, or no
/// clamp to put it at) the CSV's probe_friction_force is nan and that figure is left out.
std::vector<std::string> plot_run(const std::string& csv, const std::string& prefix, std::string& note,
                                  const std::vector<std::pair<double, double>>& fitted_loop = {}, bool windup = false,
                                  bool probe = true);

/// The deformed stack at the run's extreme deflections (the records of the largest and the
/// smallest w, RunResult::stack_at_max / _min; of the seat's rotation theta_R in a windup run, the
/// seat then drawn as a segment of slope scale x theta_R on each leaf at the seat, from
/// PREFIX_stack_seat.dat), PREFIX_stack.png: each leaf's axis at its height
/// in the stack plus its deflection times a scale (stack_figure_scale, printed on the figure),
/// every pair a point coloured by its state (stick, slip, open); the half model mirrored. The
/// data in PREFIX_stack_axes.dat and PREFIX_stack_pairs.dat (mm). `stress` (--stack-color stress,
/// the snapshots' stresses kept): instead of the axes and pairs, each leaf a band of its local
/// thickness about its drawn axis coloured by its stress [MPa] (tension positive), the fibres' at
/// its edges and linear between them and between the nodes (gnuplot's pm3d), one colour scale
/// symmetric about 0 over both figures; the data in PREFIX_stack_stress.dat (x [mm], y [mm],
/// sigma [MPa]). Returns the file written, or none and a note why in `note`.
std::vector<std::string> plot_stack(const System& system, const RunResult& result, const std::string& prefix,
                                    std::string& note, bool stress = false);

/// The deflection's scale of the deformed stack figure: the number 1, 2 or 5 times a power of
/// ten at or below 2 H / max |w|, H the stack's height at the seat (the leaves' thicknesses) and
/// max |w| the largest nodal deflection drawn (1 if it is 0), so that the drawn deflection is up
/// to twice the stack's height (docs/python.md gives the same rule for stackbeam.plot).
double stack_figure_scale(double stack_height_m, double max_abs_w_m);

}  // namespace stackbeam::cli
