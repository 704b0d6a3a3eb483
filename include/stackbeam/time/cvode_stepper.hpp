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
/// Seat loads S(t) = [M - H h; H] (loading.hpp; full model) enter as closed-form's condensation
/// (System::SeatCondensation): p = P w + r + P_S S(t), s gains (C'P_S + B) S(t), R feels -g^T S,
/// so the witnesses depend on t as well; t is then one more state (y = [w, w', D, W_e, t]) and
/// the seat loads' work S^T d[theta_R; u_R]/dt goes into W_e (decision 069).
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

#include "stackbeam/time/run_report.hpp"
#include "stackbeam/time/simulation.hpp"
#include "stackbeam/time/stepper.hpp"

namespace stackbeam {

/// The CVODE integration (mode "cvode"). Outputs come on the grid t = i * dt_s
/// (SimulationOptions::dt_s is the output interval here, not a step).
///
/// Its Stepper outputs: advance() integrates to the next output time (SolverError: CVODE's flag,
/// the time, the step count and the last step size, on a CVODE failure or a contact solve that
/// fails); current(), pairs() (forces, relative positions C'p + c w) and nodes() are of the last
/// output time, the nodes of its forces and w (the massless leaves are in equilibrium with them:
/// System::reduced_displacements); stresses() of those nodes and pairs(); report() CVODE's steps,
/// the contact iterations and mode factorisations, the stats and the events.
class CvodeStepper final : public Stepper {
public:
    /// Throws InputError for bad options (e.g. rtol <= 0), SolverError if the initial
    /// contact state cannot be resolved.
    CvodeStepper(const System& system, const SimulationOptions& options);
    ~CvodeStepper() override;
    STACKBEAM_STEPPER_OVERRIDES
    /// Number of output intervals to t_end, as in the closed-form mode.
    long num_outputs() const noexcept;

    /// Contact forces p [N] at the last output time.
    const Eigen::VectorXd& contact_forces() const noexcept;
    /// Every transition so far, in time order.
    const std::vector<ContactEvent>& events() const noexcept;
    const CvodeStats& stats() const noexcept;
    const System& system() const noexcept;

private:
    struct Impl;
    friend struct CvodeStepperAccess;  // internal: make_stepper builds it from the set-up stage
    explicit CvodeStepper(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace stackbeam
