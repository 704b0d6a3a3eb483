#pragma once
// Internal: mode "cvode" with leaves of density > 0 (docs/time-integration.md), first part: a
// stack whose contact components are held for good, so the contact mode never changes:
// every kept pair bonded (both components held) or frictionless (mu = 0: the normal
// component held, which a unilateral pair allows while it stays compressed; a tension
// above 1e-6 of the force scale at an output is a SolverError: the release event is
// not built yet). The motion lies in the null space of the held rows G_C,
// G_C (z - z_p) = 0, z = z_p + N q with N an orthonormal basis of null(G_C):
//     (N^T M N) q'' + N^T K N q = -N^T K z_p,
// a stiff linear ODE (leaf bending modes up to ~1e5..1e6 rad/s next to the 70 rad/s
// body mode) integrated by CVODE's BDF at order <= 2 (higher orders are unstable on
// the lightly damped oscillatory modes), Newton with a direct solver and the
// analytic (constant) Jacobian [0 I; -B 0], B = (N^T M N)^-1 N^T K N; in the modal
// coordinates of B it is block diagonal (2 x 2 blocks), so the direct solver is a band one
// (half-bandwidths 1, 1).
// Stacks with friction (pairs that may stick or slip) run CvodeModalStepper below;
// called directly with one, this stepper refuses it (InputError naming `mode`).
#include <Eigen/Dense>
#include <memory>
#include <vector>

#include "stackbeam/time/cvode_stepper.hpp"
#include "stackbeam/time/simulation.hpp"
#include "time/step_record.hpp"
#include "stackbeam/time/stepper.hpp"

namespace stackbeam::detail {

class CvodeInertiaStepper final : public Stepper {
public:
    CvodeInertiaStepper(const System& system, const SimulationOptions& options);
    ~CvodeInertiaStepper() override;
    /// Integrates to the next output time (t = i dt_s) and returns its record.
    const StepRecord& advance() override;
    const StepRecord& current() const noexcept override;
    long record_index() const noexcept override;
    /// The pairs at the last output: the held components' forces, relative positions G z.
    std::vector<PairRecord> pairs() const override;
    /// CVODE's steps and counters (no contact iterations, no events: the modes never change).
    RunReport report() const override;
    const CvodeStats& stats() const noexcept;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// Mode "cvode" with leaf inertia on stacks with friction (pairs that stick, slip, open
/// and close): the retained modes of the stack below CvodeOptions::modal_cutoff_rad_per_s
/// carry the inertia, the modes above it respond quasi-statically (residual
/// flexibility), so the contact points are massless and the events are those of the
/// massless cvode mode (cvode_modal.cpp, docs/time-integration.md).
class EventDriver;  // event_driver.hpp

/// The Stepper face of the event-driven steppers with leaf inertia (modal and massive): every
/// call forwards to their EventDriver.
class EventStepper : public Stepper {
public:
    ~EventStepper() override;
    /// Integrates to the next output time (t = i dt_s) and returns its record.
    const StepRecord& advance() override;
    const StepRecord& current() const noexcept override;
    long record_index() const noexcept override;
    /// The pairs at the last output (contact_forces(), relative_positions()).
    std::vector<PairRecord> pairs() const override;
    /// CVODE's steps, the contact iterations and mode factorisations, the stats and the events.
    RunReport report() const override;
    const CvodeStats& stats() const noexcept;
    /// Every mode transition, in time order (cause "start", "root" or "check").
    const std::vector<ContactEvent>& events() const noexcept;
    /// Contact forces p [N] (all rows, conventions.hpp) at the last output.
    const Eigen::VectorXd& contact_forces() const noexcept;
    /// Relative positions s + d [m] (all rows) at the last output.
    const Eigen::VectorXd& relative_positions() const noexcept;

protected:
    explicit EventStepper(std::unique_ptr<EventDriver> driver);
    std::unique_ptr<EventDriver> driver_;
};

class CvodeModalStepper final : public EventStepper {
public:
    CvodeModalStepper(const System& system, const SimulationOptions& options);

private:
    struct Impl;
};

/// Mode "cvode" with leaf inertia on stacks with friction and an elastic layer on every
/// contact row: the whole massive stack in CVODE, BDF with Newton, events on every
/// transition (cvode_massive.cpp, docs/time-integration.md). Refuses a rigid contact row
/// (InputError naming the interface's contact or the clamp's length_m).
class CvodeMassiveStepper final : public EventStepper {
public:
    CvodeMassiveStepper(const System& system, const SimulationOptions& options);

private:
    struct Impl;
};

/// True when a pair of `system` carries friction (it may stick or slip): mode cvode with
/// leaf mass then runs the modal stepper; without friction the held-for-good one.
bool has_mode_changes(const System& system);

/// True when mode cvode runs `system` with leaf inertia (a leaf has density > 0).
bool has_leaf_mass(const System& system);

}  // namespace stackbeam::detail
