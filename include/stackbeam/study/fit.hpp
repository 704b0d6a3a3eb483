#pragma once
/// @file fit.hpp
/// Calibration: the values of some scenario keys (a friction coefficient, an interface
/// stiffness, a clamp preload: any numeric key) fitted to force-displacement loops measured
/// on a rig. The user's guide is docs/calibration.md; the choices, docs/decisions/059-calibration.md.
///
///   FitSpec spec = load_fit_spec("fit.toml");   // InputError: spec file:line, key; the CSVs read and checked
///   FitResult r = fit(spec, FitOptions{});       // the fitted values, their uncertainty, the loops
///
/// The objective: for every measured loop l (one closed cycle, samples (w_i, F_i)) the base
/// scenario with the loop's own settings (its loading) and the trial values is run and its
/// last cycle compared with the measured one, branch by branch: a sample on the loading
/// branch (w rising, from the loop's lowest w to its highest) is compared with the
/// simulated loading branch at the same w, an unloading sample with the unloading branch.
/// Residuals (dimensionless, all squared and summed):
///   r_force,i = sqrt(weight_force weight_l / N_l) (F_sim(w_i, branch_i) - F_i) / F_half,l
///   r_area    = sqrt(weight_area weight_l) (A_sim - A_meas) / A_scale,l
///   r_secant  = sqrt(weight_secant weight_l) (k_s,sim - k_s,meas) / k_s,meas   (and dynamic rate alike)
/// with F_half = (F_max - F_min)/2 of the measured loop and A_scale = max(|A_meas|, 1e-3 F_half w_half).
/// Minimised by Ceres' Levenberg-Marquardt within the bounds, on the parameters scaled to
/// their bounds (u = (x - lower)/(upper - lower) in [0, 1]); the Jacobian by forward
/// differences (the first column central when n is even, so that a batch has an even number
/// of runs); every trial point is run together with its Jacobian's points as one batch on
/// `jobs` threads (run_sweep), speculatively: an accepted step finds its Jacobian done, a
/// rejected one wastes n runs; restarts from several starting points keep the lowest misfit.
///
/// Uncertainty: the covariance s^2 (J^T J)^-1 at the optimum (J the Jacobian of the residuals
/// in the parameters' units, s^2 = sum r^2 / (m - n)): the standard error assumes the misfit
/// is noise, independent from sample to sample. A parameter whose column of J is near zero
/// (the data do not depend on it) or nearly parallel to another's is reported as not
/// identifiable, its standard error infinite, not as a confident value.
///
/// Threads: the runs of a batch go on `jobs` threads; the answer does not depend on `jobs`
/// (each run is deterministic and its residuals go to their place). The library prints
/// nothing and writes no file: the command line (`stackbeam fit`) writes the fitted
/// scenario, the history and the loops.
#include <atomic>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "stackbeam/errors.hpp"
#include "stackbeam/study/sweep.hpp"

namespace stackbeam {

/// One fitted parameter: a scenario key (the sweep's key syntax, docs/sweep.md) and its bounds.
struct FitParameter {
    std::string key;      ///< e.g. "interfaces[*].friction_coefficient" (every element gets the value)
    double lower = 0.0;   ///< lower bound, in the key's unit (the key's suffix: _n, _pa_per_m, ...)
    double upper = 0.0;   ///< upper bound, > lower
    /// The starting value; NaN: the middle of the bounds.
    double start = std::numeric_limits<double>::quiet_NaN();
    std::string location; ///< where it is written, "spec.toml:LINE" ("" made in code)
};

/// One measured loop: one closed cycle of a rig's record, and the scenario keys that make
/// the scenario run this loop (its loading: amplitude, frequency).
struct MeasuredLoop {
    std::string name;                 ///< "loops[0]", or the `name` given
    std::string csv_path;             ///< the CSV file (relative paths: to the spec's directory)
    std::string displacement_column;  ///< the column of w [m] (the seat's displacement, +y as the scenario's w)
    std::string force_column;         ///< the column of F [N] (the rig's force on the spring, +y)
    /// Scenario keys set for this loop (the loop's own loading), e.g.
    /// {"loading.displacement_m.amplitude", 0.01}.
    std::vector<std::pair<std::string, AxisValue>> settings;
    double weight = 1.0;              ///< the loop's weight in the misfit (> 0)
    std::vector<double> w_m, force_n; ///< the samples, in time order (one cycle)
    std::string location;             ///< "spec.toml:LINE"
};

/// The weights of the misfit's terms (>= 0; force > 0 or one figure weight > 0).
struct FitWeights {
    double force = 1.0;             ///< the force along the loop, branch by branch
    double loop_area = 0.0;         ///< the loop area (energy dissipated per cycle)
    double secant_stiffness = 0.0;  ///< (F_max - F_min)/(w_max - w_min)
    double dynamic_rate = 0.0;      ///< |F_1/w_1|
};

/// A calibration: the base scenario, the measured loops, the parameters.
struct FitSpec {
    std::string source;             ///< the spec file's name
    std::string description;
    std::string scenario_path;      ///< the base scenario, as resolved (relative to the spec)
    std::string scenario_text;
    std::string scenario_location;
    std::vector<FitParameter> parameters;
    std::vector<MeasuredLoop> loops;
    FitWeights weights;
    int starts = 1;                 ///< starting points: the given start, then starts - 1 spread over the bounds (Halton)
    int max_iterations = 30;        ///< Levenberg-Marquardt iterations per start
    /// The forward-difference step as a fraction of each parameter's bound width.
    double difference_step = 1e-3;
    /// A measured loop closes when its last sample is within this fraction of the stroke
    /// (and of the force range) from its first.
    double closure_tolerance = 0.05;
    std::string output_directory;   ///< `[outputs] directory` ("" none)
};

/// Parses fit spec TOML `text` (docs/calibration.md); relative paths are relative to
/// `source_name`'s directory. Reads the base scenario and the loops' CSV files and checks
/// them: a missing or non-numeric column, a loop that does not close, bounds the scenario
/// refuses (the scenario is made at each bound) all throw InputError naming the spec's key
/// and line (and the CSV's line).
FitSpec parse_fit_spec(const std::string& text, const std::string& source_name);
FitSpec load_fit_spec(const std::string& path);

/// Reads a measured loop's CSV text (a header of column names, then numbers) into
/// loop.w_m / loop.force_n and checks that it closes (closure_tolerance). `field` and
/// `location` name the loop in messages.
void read_loop_csv(const std::string& text, MeasuredLoop& loop, double closure_tolerance, const std::string& field);

/// One iteration of the optimiser (progress and the history).
struct FitIteration {
    int start = 0;              ///< which starting point (0-based)
    int iteration = 0;          ///< the optimiser's iteration (0: the starting point)
    double cost = 0.0;          ///< sum r^2 / 2 at the current values
    std::vector<double> values; ///< the current values (parameters' units)
    int runs = 0;               ///< simulation runs so far (all starts)
    bool accepted = true;       ///< the step was accepted
};

struct FitOptions {
    int jobs = 0;                              ///< threads; 0: the machine's
    const std::atomic<bool>* stop = nullptr;   ///< set from outside to stop (FitResult::stopped)
    std::function<void(const FitIteration&)> on_iteration;  ///< progress, one call per iteration
    /// Starting values (parameters' units) replacing the spec's starts (one start): a stopped
    /// fit restarted from its last values. Empty: the spec's.
    std::vector<double> start_values;
};

struct FitParameterResult {
    std::string key;
    double value = 0.0;           ///< the fitted value
    double standard_error = 0.0;  ///< from the covariance; +inf when not identifiable
    double lower = 0.0, upper = 0.0;
    bool at_bound = false;        ///< within 1e-6 of the bound width from a bound
    bool identifiable = true;
    std::string note;             ///< why not identifiable ("" when it is)
};

/// A loop measured and fitted: at each measured sample, the fitted force on its branch.
struct FitLoopResult {
    std::string name;
    std::vector<double> w_m, measured_force_n, fitted_force_n;
    std::vector<int> branch;      ///< +1 loading (w rising), -1 unloading
    double measured_area_j = 0.0, fitted_area_j = 0.0;
    double measured_secant_n_per_m = 0.0, fitted_secant_n_per_m = 0.0;
    double measured_dynamic_rate_n_per_m = 0.0, fitted_dynamic_rate_n_per_m = 0.0;
    double rms_force_error_n = 0.0;  ///< sqrt(mean (F_fit - F_meas)^2)
};

struct FitResult {
    std::vector<FitParameterResult> parameters;
    std::vector<std::vector<double>> correlation;  ///< n x n; NaN for a parameter not identifiable
    std::vector<std::string> warnings;             ///< not identifiable, nearly parallel, at a bound, not converged
    double cost = 0.0;            ///< sum r^2 / 2 at the fit
    int residual_count = 0;       ///< m
    int runs = 0;                 ///< simulation runs, all starts
    int iterations = 0;           ///< optimiser iterations, all starts
    int best_start = 0;
    bool converged = false;       ///< the best start's optimiser reported convergence
    bool stopped = false;         ///< FitOptions::stop was set: the values are the best so far
    std::string termination;      ///< the optimiser's message
    std::vector<FitIteration> history;
    std::vector<FitLoopResult> loops;
    std::string fitted_scenario_text;  ///< the base scenario with the fitted values (no [outputs])
};

/// Fits spec.parameters to spec.loops. Throws InputError for a loop whose stroke the
/// scenario's loading does not reach (naming the loop), std::runtime_error when the runs at
/// the starting values fail.
FitResult fit(const FitSpec& spec, const FitOptions& options = {});

/// The misfit's residuals (the m of FitResult::residual_count, in the order of the objective
/// above) at each of `values` (one value per parameter, parameters' units), the runs as one
/// batch on options.jobs threads. For studies of the objective (another optimiser, a misfit
/// map); an entry is empty when its run failed or was stopped.
std::vector<std::vector<double>> fit_residuals(const FitSpec& spec, const std::vector<std::vector<double>>& values,
                                               const FitOptions& options = {});

}  // namespace stackbeam
