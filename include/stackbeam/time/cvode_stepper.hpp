#pragma once
/// @file cvode_stepper.hpp
/// Mode "cvode": the rigid body on the massless stack integrated by SUNDIALS
/// CVODE between contact events, with root-finding on every transition.
///
/// Between events every pair keeps its mode (conventions.hpp for the signs):
///   normal      closed (s_n = 0) or open (p_n = 0); clamps and bonds are always closed
///   tangential  stick (s_t = d_t, the anchor), slip+ / slip- (p_t = +-mu tau, the
///               surfaces slipping against p_t), or free (p_t = 0: open, mu = 0, or a
///               clamp pulled apart past its preload)
/// For a mode set the contact conditions are linear in (p, w), so p(w) = P w + r is
/// affine (one dense LU per mode set, system.hpp for s = C'p + c w - d) and the
/// motion of R is a smooth linear ODE:
///   m w'' = c^T p(w) - k w,         D' = -sum_slip p_t ds_t/dt  (friction power >= 0)
/// (m, k, c of the meshed part). State y = [w, w', D]: D is the dissipated energy.
///
/// Witness (root) functions, one per possible transition, each scaled to order one
/// and POSITIVE while its mode holds; the event is its DECREASING crossing of zero
/// (CVodeSetRootDirection -1 for all):
///   closed -> open     g = -p_n / F_ref                 (compression vanishes)
///   open -> closed     g = -s_n / L_ref                 (the gap closes)
///   stick -> slip      g = (mu tau - |p_t|) / F_ref     (friction reaches its limit)
///   slip -> stick      g = -sigma (ds_t/dt) / V_ref     (the slip rate reaches zero)
///   clamp release      g = (F_c - p_n) / F_ref, and back: (p_n - F_c) / F_ref
/// each plus a margin of 1e-9 so that pairs that merely touch (p_n = s_n = 0 to
/// round-off, common between identical leaves) do not chatter. F_ref, L_ref, V_ref:
/// force, displacement and velocity scales of the run (cvode_stepper.cpp).
///
/// At an event (and at t = 0) the contact iteration decides the new modes on the
/// incremental problem a short look-ahead away (|dw| = 1e-7 L_ref along w' and w''),
/// with the stuck pairs' anchors kept and every other pair re-anchored where it is
/// (the paper's section 5 rule): the old modes with the transitions CVODE found
/// applied are tried first and kept when the contact iteration's stop test
/// (||v|| < tolerance) and every witness accept them there; otherwise the exact
/// contact solver solves that problem and its answer gives the modes. The
/// forces at the event in the new modes must equal those of the old ones (the
/// jump is recorded in CvodeStats::max_force_jump_n); CVODE is then re-initialised.
///
/// At every accepted CVODE step (CV_ONE_STEP) the configured contact solver
/// (SimulationOptions::solver; exact by default, as in every mode)
/// is run on the paper's incremental problem, warm-started at the mode solution:
/// it must accept that solution, and every witness must still be positive. A
/// disagreement is a missed event (two crossings inside one step, or a witness
/// that was exactly zero at a restart, which SUNDIALS 6.4.1 deactivates): it is
/// located by bisection on CVODE's dense output, handled as an event at that time
/// (cause "check"), and counted in CvodeStats::missed_events.
///
/// Method: Adams-Moulton (variable order up to 12) with fixed-point iteration: the
/// ODE between events is small (3 states), smooth and non-stiff (one frequency,
/// 25-75 rad/s on the paper example), where Adams needs fewer right-hand sides per
/// step than BDF and no Jacobian.
#include <memory>
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
    std::string cause;           ///< "start" (t = 0), "root" (CVODE root-finding) or "check" (found by the per-step check)
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
    // Leaf inertia with friction: where the wall-clock time went [s].
    double cvode_time_s = 0.0;     ///< inside CVode() (right-hand sides, root functions, steps)
    double contact_time_s = 0.0;   ///< contact iterations: per-step checks and event decisions' solves
    double event_time_s = 0.0;     ///< the rest of event handling: new modes, records of events, CVodeReInit
    double min_jump_dissipation_j = 0.0; ///< leaf inertia with friction: the smallest energy taken by a force
                                         ///< jump at an event (>= 0 up to round-off: a jump cannot add energy) [J]
};

/// The CVODE integration (mode "cvode"). Outputs come on the grid t = i * dt_s
/// (SimulationOptions::dt_s is the output interval here, not a step).
class CvodeStepper {
public:
    /// Throws InputError for bad options (e.g. rtol <= 0), SolverError if the initial
    /// contact state cannot be resolved.
    CvodeStepper(const System& system, const SimulationOptions& options);
    ~CvodeStepper();
    CvodeStepper(const CvodeStepper&) = delete;
    CvodeStepper& operator=(const CvodeStepper&) = delete;

    /// Integrates to the next output time and returns its record. Throws SolverError
    /// (CVODE's flag, the time, the step count and the last step size) on a CVODE failure
    /// or a contact solve that fails.
    const StepRecord& advance();
    /// The record of the last output time (the initial state before the first advance()).
    const StepRecord& current() const noexcept;
    /// Number of output intervals to t_end, as in the closed-form mode.
    long num_outputs() const noexcept;
    long output_index() const noexcept;

    /// Contact forces p [N] at the last output time.
    const Eigen::VectorXd& contact_forces() const noexcept;
    /// Every transition so far, in time order.
    const std::vector<ContactEvent>& events() const noexcept;
    const CvodeStats& stats() const noexcept;
    const System& system() const noexcept;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
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
