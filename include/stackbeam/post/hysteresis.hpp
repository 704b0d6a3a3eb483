#pragma once
/// @file hysteresis.hpp
/// Figures of a force-displacement loop, as a test rig reports them for a leaf spring.
///
/// The loop is the spring force F (StepRecord::spring_force_n: the force of R on the
/// stack, +y, whole spring; the rig's load-cell force) against the deflection w
/// (StepRecord::w_m, relative to the supports) over one cycle [t_start, t_end] of the
/// records, sampled as recorded (every dt). With w_a = (w_max - w_min)/2:
///  - loop area A = closed integral of F dw (trapezoidal): the energy the spring
///    dissipates per cycle [J], > 0 for a loop run anticlockwise in (w, F);
///  - secant stiffness k_s = (F_max - F_min)/(w_max - w_min) [N/m] (peak to peak);
///  - dynamic rate |K*| and loss factor eta = Im K*/Re K* = tan(delta), from the first
///    Fourier harmonics over the cycle, K* = F_1/w_1 (the complex stiffness at the
///    cycle's frequency);
///  - equivalent viscous damping ratio zeta = A/(4 pi E_s), E_s = k_s w_a^2/2 (the
///    viscous damper that dissipates A per cycle at the same amplitude and frequency);
///  - the energy loss factor A/(2 pi E_s) = 2 zeta, comparable with eta.
/// For a steady cycle the loop area equals the friction work of the cycle
/// (dissipated_j below) up to the discretisation: a check of the run.
///
/// The same figures of any other pair of a record's values (LoopColumns): the windup loop,
/// the moment on the spring at the seat against the seat's rotation (k_s then in N m/rad, the
/// windup stiffness; A in J, the closed integral of M dtheta), or the seat's axial displacement
/// against the longitudinal force. The members named w_ and force_ then hold the pair's
/// displacement and force in their units (run/loop_figures.hpp names them).
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "stackbeam/time/simulation.hpp"

namespace stackbeam {

struct HysteresisMetrics {
    double t_start_s = 0.0, t_end_s = 0.0;          ///< the cycle [s]
    int samples = 0;                                ///< records in the cycle
    double w_min_m = 0.0, w_max_m = 0.0;            ///< deflection extremes [m]
    double force_min_n = 0.0, force_max_n = 0.0;    ///< spring force extremes [N]
    double loop_area_j = 0.0;                       ///< energy dissipated per cycle, closed integral of F dw [J]
    double secant_stiffness_n_per_m = 0.0;          ///< (F_max - F_min)/(w_max - w_min) [N/m]
    double dynamic_rate_n_per_m = 0.0;              ///< |F_1/w_1| (first harmonics) [N/m]
    double loss_factor = 0.0;                       ///< Im/Re of F_1/w_1 = tan(delta) [-]
    double energy_loss_factor = 0.0;                ///< A/(2 pi E_s) [-]
    double equivalent_damping_ratio = 0.0;          ///< A/(4 pi E_s) [-]
    double dissipated_j = 0.0;                      ///< friction work over the cycle, from the records [J]
    double external_work_j = 0.0;                   ///< external work over the cycle, from the records [J]
    double strain_energy_change_j = 0.0;            ///< strain energy at the end minus at the start [J]
};

/// The two values of a record a loop is drawn from: a displacement (generalised: m, rad) and
/// the force on the spring that does work on it (N, N m), with the displacement's name for the
/// notes. The default is the vertical loop (w, spring_force_n).
struct LoopColumns {
    std::string displacement_name = "w";
    std::function<double(const StepRecord&)> displacement = [](const StepRecord& r) { return r.w_m; };
    std::function<double(const StepRecord&)> force = [](const StepRecord& r) { return r.spring_force_n; };
};

/// The last complete cycle of `records` as [t_start, t_end] [s]: with period_s > 0
/// (a periodic loading, Loading::period_s) the last whole period before the last
/// record, on the record grid; otherwise between the last two maxima of w (a free
/// vibration: then the "loop" is one decaying cycle). Throws InputError("cycle", ...)
/// when the records do not hold one (too short a run).
std::pair<double, double> last_cycle(const std::vector<StepRecord>& records, double period_s);

/// The loop figures over [t_start_s, t_end_s] (records with t in it, inclusive) of the pair
/// `columns` (default: the vertical loop). Throws InputError("cycle", ...) when fewer than 8
/// records fall in it or the displacement does not move.
HysteresisMetrics hysteresis_metrics(const std::vector<StepRecord>& records, double t_start_s, double t_end_s,
                                     const LoopColumns& columns = LoopColumns());

}  // namespace stackbeam
