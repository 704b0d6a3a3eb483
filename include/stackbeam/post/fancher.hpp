#pragma once
/// @file fancher.hpp
/// Fancher's leaf-spring model: a five-parameter force law of a leaf spring's
/// hysteresis for vehicle simulations (P. S. Fancher, R. D. Ervin, C. C. MacAdam,
/// C. B. Winkler, "Measurement and representation of the mechanical properties of truck
/// leaf springs", SAE 800905, 1980), and its least-squares fit to one loop of a
/// stackbeam run (docs/reduced-model.md).
///
/// The force F [N] against the deflection w [m] (in a loop of a run: StepRecord::w_m
/// and StepRecord::spring_force_n, hysteresis.hpp) lies between two envelope lines,
///   upper:  F_u(w) = upper_rate_n_per_m * w + upper_offset_n   (active while w increases)
///   lower:  F_l(w) = lower_rate_n_per_m * w + lower_offset_n   (active while w decreases)
/// and approaches the active envelope exponentially with the deflection travelled,
/// with the decay length beta_m: from sample i-1 to i,
///   F_i = F_env(w_i) + (F_{i-1} - F_env(w_{i-1})) * exp(-|w_i - w_{i-1}| / beta_m),
/// F_env the upper envelope if w_i > w_{i-1}, the lower one if w_i < w_{i-1}, and
/// F_i = F_{i-1} if w does not move: the force's distance from the active envelope
/// decays as exp(-travel/beta_m), whatever the steps (a stroke in one step or in a
/// hundred gives the same force; docs/decisions/023-fancher-fit-and-fuzzing.md on the
/// form with F_env(w_i) in both places, which depends on the step). After a reversal
/// the force first follows a steep line (the spring locked by friction: slope
/// K + (F_u - F_l)/beta_m) and then the other envelope. "Upper" is the envelope of
/// increasing w: with stackbeam's signs (F the rig's force on the spring, +y; friction
/// opposes the stroke) it is the upper one of a loop, as Fancher's loading envelope.
#include <vector>

#include "stackbeam/time/simulation.hpp"

namespace stackbeam {

/// The five parameters of Fancher's model (SI units).
struct FancherParameters {
    double upper_rate_n_per_m = 0.0;  ///< slope of the envelope of increasing w [N/m]
    double upper_offset_n = 0.0;      ///< that envelope's force at w = 0 [N]
    double lower_rate_n_per_m = 0.0;  ///< slope of the envelope of decreasing w [N/m]
    double lower_offset_n = 0.0;      ///< that envelope's force at w = 0 [N]
    double beta_m = 0.0;              ///< decay length of the approach to the envelope [m], > 0
};

/// One step of the model, the whole state of a spring in a vehicle model being its
/// last (w, F): the force at `w_m` after (`w_previous_m`, `force_previous_n`).
/// Throws InputError("beta_m", ...) unless beta_m > 0 and finite.
double fancher_step(const FancherParameters& p, double w_previous_m, double force_previous_n, double w_m);

/// The model's force at every sample of the deflection path `w_m`, starting from
/// `start_force_n` at w_m[0] (the first value returned). Throws InputError for a
/// beta_m that is not > 0 or a non-finite w.
std::vector<double> fancher_force(const FancherParameters& p, const std::vector<double>& w_m, double start_force_n);

/// The force at w_m[0] of the model's steady state when the path `w_m` repeats
/// forever (closed by a step from its last sample back to its first): the fixed point
/// of one pass, F* = b / (1 - a), a = exp(-(total travel)/beta_m). The fit compares
/// the model in this state with a loop, so that no start force is fitted.
double fancher_periodic_start_force(const FancherParameters& p, const std::vector<double>& w_m);

/// The result of fit_fancher.
struct FancherFit {
    FancherParameters parameters;
    double start_force_n = 0.0;       ///< the periodic start, fancher_periodic_start_force(parameters, w)
    double rms_error_n = 0.0;         ///< root mean square of F_model - F over the samples [N]
    double rms_error_relative = 0.0;  ///< rms_error_n / (max F - min F) [-]
    int iterations = 0;               ///< Levenberg-Marquardt iterations (after the start's scan of beta)
    int function_evaluations = 0;     ///< evaluations of the model along the loop in those iterations
    bool converged = false;           ///< the iteration stopped on a tolerance, not on its evaluation limit
};

/// Least-squares fit of Fancher's model to one loop: samples (w_m[i], force_n[i]), in
/// their order, over one cycle (e.g. the records between last_cycle's bounds). The
/// model runs in its periodic steady state over the path (fancher_periodic_start_force)
/// and the sum of (F_model,i - force_n[i])^2 is minimised over the five parameters:
/// a scan of beta_m (for each beta_m the model is linear in the four envelope
/// parameters: their linear least squares), then Levenberg-Marquardt on all five
/// (Eigen's, analytic Jacobian) from the scan's best. Deterministic (no threads, no
/// random numbers): the same loop gives the same figures on every thread and rank.
/// Throws InputError naming the field ("w_m", "force_n", with the index of a bad
/// sample) for: sizes that differ, fewer than 8 samples, a non-finite sample, w not
/// moving both up and down, a force that does not change.
FancherFit fit_fancher(const std::vector<double>& w_m, const std::vector<double>& force_n);

/// fit_fancher on the records with t in [t_start_s, t_end_s] (as hysteresis_metrics
/// takes them): w = StepRecord::w_m, F = StepRecord::spring_force_n.
FancherFit fit_fancher(const std::vector<StepRecord>& records, double t_start_s, double t_end_s);

/// A run's loop, its fit and the fitted model's loop along the same path: what
/// `stackbeam simulate`'s summary and a sweep's point (study/sweep.hpp) report, from
/// this one call so that they agree figure for figure.
struct FancherLoopFit {
    FancherFit fit;
    std::vector<double> w_m;            ///< the loop's deflections (the records with t in [t_start_s, t_end_s])
    std::vector<double> force_n;        ///< the loop's spring forces
    std::vector<double> model_force_n;  ///< fancher_force(fit.parameters, w_m, fit.start_force_n)
};

/// fit_fancher(records, t_start_s, t_end_s) with the loop's samples and the model's
/// force along them. Throws InputError as fit_fancher.
FancherLoopFit fit_fancher_loop(const std::vector<StepRecord>& records, double t_start_s, double t_end_s);

}  // namespace stackbeam
