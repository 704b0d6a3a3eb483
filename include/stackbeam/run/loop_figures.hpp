#pragma once
/// @file loop_figures.hpp
/// The figures of a periodic run's last cycle, computed here once for every front-end: the
/// command line's summary, the Python module's Result.summary, the sweep's point figures.
#include <array>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "stackbeam/fe/system.hpp"
#include "stackbeam/post/fancher.hpp"
#include "stackbeam/model/loading.hpp"
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

/// The seat's tangent stiffness at a contact state (decision 068): the 3 x 3 matrix over the seat's
/// motions (w [m], theta_R [rad], u_R [m], in that order) of the force, moment and axial force on the
/// spring at the seat [N, N m, N] per unit motion, every other DOF in equilibrium, with each contact
/// pair as its state says: a sticking pair tied (both rows held; an elastic layer's compliance on
/// them), a slipping one (or a frictionless one) held normally and free tangentially, an open one
/// free. Whole spring.
/// Rows and columns of a motion the seat does not have (u_R where the seat locates the stack) are NaN.
struct SeatStiffness {
    double t_s = 0.0;                 ///< the record whose contact state it is [s]
    int stick = 0, slip = 0, open = 0;  ///< the pairs by state
    /// K_t[i][j]: [N/m, N/rad, N/m; N m/m, N m/rad, N m/m; N/m, N/rad, N/m]
    std::array<std::array<double, 3>, 3> matrix{};
    /// The vertical rate with the seat free to turn and slide [N/m]: K_t condensed to w (the vertical
    /// rig's tangent rate at that state)
    double vertical_rate_n_per_m = std::numeric_limits<double>::quiet_NaN();
};

/// The seat's tangent stiffness of `system` at the contact state `pairs` (Stepper::pairs() of a
/// record at t_s), from the reduced stiffness, the contact rows and the layer's compliance (one sparse
/// LU of the stack's saddle-point system with the held rows). Throws SolverError where that system
/// is singular.
SeatStiffness seat_tangent_stiffness(const System& system, const std::vector<PairRecord>& pairs, double t_s);

/// The windup figures of a run loaded at the seat (docs/windup.md, "The windup figures"; decision
/// 068): the loops of the last period of the seat's loading, by hysteresis_metrics (the vertical
/// loop's code, on other record columns).
struct WindupFigures {
    /// The windup loop, seat_moment [N m] against seat_rotation [rad] (HysteresisMetrics' w_ members
    /// hold theta_R [rad], force_ the moment [N m]): secant_stiffness_n_per_m is the windup stiffness
    /// k_theta [N m/rad] (peak-to-peak moment over peak-to-peak rotation), loop_area_j the closed
    /// integral of M dtheta [J per cycle], loss_factor and energy_loss_factor as the vertical loop's.
    /// Over the last period of the windup rig, else of the seat moment, else of the longitudinal force
    /// (its moment -H h); none (windup_note says why) when that loading is not periodic.
    std::optional<HysteresisMetrics> windup;
    std::string windup_note;
    /// The longitudinal loop, the force H(t) [N] (the loading's, at each record) against seat_axial
    /// u_R [m], over the last period of a periodic longitudinal force (w_ members: u_R [m], force_: H [N]).
    std::optional<HysteresisMetrics> longitudinal;
    std::string longitudinal_note;
    /// The seat's longitudinal compliance [m/N]: peak-to-peak u_R over peak-to-peak H (1 / the
    /// longitudinal loop's secant); NaN without that loop.
    double longitudinal_compliance_m_per_n = std::numeric_limits<double>::quiet_NaN();
    /// The vertical rate at the same state [N/m]: the secant of the same run's vertical loop (its
    /// summary's "hysteresis") where the vertical loading is periodic (of the same period as the
    /// seat's); NaN otherwise (then a vertical rig at the same preload gives it: decision 068).
    double vertical_rate_n_per_m = std::numeric_limits<double>::quiet_NaN();
    /// The seat's tangent stiffness at the last record's contact state (run_scenario fills it: it needs
    /// the System and the stepper), or a note why none
    std::optional<SeatStiffness> tangent;
    std::string tangent_note;
};

/// Whether `loading` loads the seat (a windup rig, a seat moment or a longitudinal force): then a
/// run has windup figures (the summary's "windup" section).
bool loads_the_seat(const Loading& loading);

/// The period of the windup loop's cycle [s]: the windup rig's, else the seat moment's (when > 0), else
/// the longitudinal force's where it has a moment (h != 0); 0 when none of them is periodic.
double windup_period_s(const Loading& loading);

/// The period of the vertical loading itself [s]: the applied force's or the prescribed (or base)
/// displacement's; 0 for initial conditions or a loading that is not periodic. Loading::period_s()
/// falls back to the seat's loading where this is 0, so a windup run's vertical "loop" is then w
/// following the windup (or held), no vertical rate.
double vertical_period_s(const Loading& loading);

/// The windup figures of `records` under `loading` (loads_the_seat), with the vertical rate from
/// `vertical` (the same run's loop_figures). Bad data gives notes, never an exception.
WindupFigures windup_figures(const std::vector<StepRecord>& records, const Loading& loading, const LoopFigures& vertical);

}  // namespace stackbeam
