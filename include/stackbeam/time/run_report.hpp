#pragma once
/// @file run_report.hpp
/// What a run reports besides its records: the counters of every mode (RunReport), and
/// for the event-driven mode cvode its event log (ContactEvent) and CVODE's counters
/// (CvodeStats). simulate() fills one; every Stepper (stepper.hpp) gives one.
#include <string>
#include <vector>

#include "stackbeam/time/simulation.hpp"

namespace stackbeam {

/// One transition of one pair.
struct ContactEvent {
    double t_s = 0.0;            ///< time [s]
    int pair = 0;                ///< index in System::pairs()
    int interface_index = 0;     ///< interface i: leaf i above, leaf i+1 below
    double x_m = 0.0;            ///< position of the pair along the leaves [m]
    std::string from, to;        ///< pair modes: stick, slip+, slip-, open, closed (frictionless), released (clamp)
    std::string cause;           ///< "start" (t = 0), "root" (CVODE root-finding), "check" (found by the per-step check) or
                                 ///< "loading" (at a break of the loading: a table's point, the modal stepper)
    double w_m = 0.0;            ///< displacement of R at the event [m]
    double w_dot_m_per_s = 0.0;  ///< velocity of R at the event [m/s]

    /// True when both modes are among stick, slip+, slip- (a stick-slip transition).
    bool is_stick_slip() const;
};

/// Counters of a cvode run.
struct CvodeStats {
    long steps = 0;                ///< accepted CVODE steps
    long rhs_evaluations = 0;      ///< right-hand side evaluations
    long root_evaluations = 0;     ///< witness function evaluations
    long events = 0;               ///< event times handled (after t = 0); one may switch several pairs
    long missed_events = 0;        ///< events the per-step check found (root-finding missed them)
    long restarts = 0;             ///< CVodeReInit calls
    long settled_transitions = 0;  ///< massive leaves: passes at an event that changed a pair whose decided
                                   ///< modes did not hold at the event's state itself (EventDriver::settle_at_state)
    long mode_factorizations = 0;  ///< dense LU factorisations of a mode set
    long contact_iterations = 0;   ///< iterations of the contact solvers (checks and event decisions)
    double max_force_jump_n = 0.0; ///< largest change of a contact force across an event [N] (0 in exact arithmetic)
    double max_check_residual_m = 0.0; ///< largest ||v|| (eq. 9) of the mode solution in the per-step check [m]
    double max_check_force_difference_n = 0.0; ///< largest change the per-step contact iteration made to the
                                                ///< mode solution it accepted [N]
    long jacobian_evaluations = 0; ///< Jacobian evaluations (leaf inertia: BDF with Newton; 0 otherwise)
    long linear_setups = 0;        ///< Newton matrix factorisations (leaf inertia; 0 otherwise)
    int retained_modes = 0;        ///< leaf inertia with friction: modes carrying the inertia (0 otherwise)
    double modal_cutoff_rad_per_s = 0.0; ///< leaf inertia with friction: the cut used [rad/s]
    // The event-driven steppers (massless, and leaf inertia with friction): where the wall-clock time went [s].
    double cvode_time_s = 0.0;     ///< inside CVode() (right-hand sides, root functions, steps)
    double contact_time_s = 0.0;   ///< contact iterations: per-step checks and event decisions' solves
    double event_time_s = 0.0;     ///< the rest of event handling: new modes, records of events, CVodeReInit
    double min_jump_dissipation_j = 0.0; ///< leaf inertia with friction: the smallest energy taken by a force
                                         ///< jump at an event (>= 0 up to round-off: a jump cannot add energy) [J]
};

/// What a run did besides its records (simulate's optional report).
struct RunReport {
    Mode mode = Mode::closed_form;
    long steps = 0;                     ///< closed-form steps or CVODE steps
    long contact_iterations = 0;        ///< total contact iterations
    long factorizations = 0;            ///< total dense factorisations (solver and mode sets)
    std::vector<ContactEvent> events;   ///< mode cvode: the event log
    CvodeStats cvode;                   ///< mode cvode: its counters
};

}  // namespace stackbeam
