#pragma once
/// @file stepper.hpp
/// The one interface of every mode's integrator, and the factory that picks it.
///
/// A Stepper starts at the initial state (record 0, t = 0) and advances one record at a
/// time on the grid t_i = i dt_s (SimulationOptions::dt_s): a step of the fixed-step modes
/// (closed-form, newmark), an output time of the event-driven mode cvode. simulate() is a
/// loop over one (simulation.hpp). The modes' physics: closed_form_stepper.hpp,
/// newmark_stepper.hpp, cvode_stepper.hpp, docs/time-integration.md.
#include <memory>
#include <vector>

#include "stackbeam/fe/system.hpp"
#include "stackbeam/post/stresses.hpp"
#include "stackbeam/time/run_report.hpp"
#include "stackbeam/time/simulation.hpp"

namespace stackbeam {

class Stepper {
public:
    virtual ~Stepper() = default;
    Stepper() = default;
    Stepper(const Stepper&) = delete;
    Stepper& operator=(const Stepper&) = delete;

    /// Advances to the next record time t = (i+1) dt_s and returns its record. Throws
    /// SolverError (step, time, residual) when the mode's solve fails.
    virtual const StepRecord& advance() = 0;
    /// The record at the current record time (the initial state before the first advance()).
    virtual const StepRecord& current() const noexcept = 0;
    /// Index i of the current record (t = i dt_s; 0 before the first advance()).
    virtual long record_index() const noexcept = 0;
    /// The contact state at the current record: one PairRecord per System::pairs(), in
    /// that order (meshed part, signs of conventions.hpp).
    virtual std::vector<PairRecord> pairs() const = 0;
    /// Every leaf's deflected axis at the current record: per leaf its nodes' x [m], transverse
    /// displacement v [m] and rotation [rad], whole leaves (the half model mirrored),
    /// System::leaf_nodes. The node at R's attachment on a tied leaf moves by the record's w_m.
    virtual std::vector<LeafNodes> nodes() const = 0;
    /// Every leaf's stress resultants and fibre stresses and every pair's pressure at the current
    /// record (compute_stresses of the z that nodes() uses and of pairs(); stresses.hpp): computed
    /// on each call, so a run that does not ask pays nothing.
    virtual Stresses stresses() const = 0;
    /// The counters so far (steps, contact iterations, factorisations; mode cvode: its
    /// CvodeStats and event log).
    virtual RunReport report() const = 0;
};

/// Declares, in a concrete stepper's class body (public), its override of each output above:
///     class MyStepper final : public Stepper {
///     public:
///         STACKBEAM_STEPPER_OVERRIDES
///         // the stepper's own accessors
///     };
/// Stepper's comments are the contract of each; a stepper says in its class comment what its own
/// outputs are made of. An output added to every stepper: its pure virtual and comment in Stepper,
/// its line here, its definition in each stepper's .cpp (the linker names a stepper that lacks one).
#define STACKBEAM_STEPPER_OVERRIDES                      \
    const StepRecord& advance() override;                \
    const StepRecord& current() const noexcept override; \
    long record_index() const noexcept override;         \
    std::vector<PairRecord> pairs() const override;      \
    std::vector<LeafNodes> nodes() const override;       \
    Stresses stresses() const override;                  \
    RunReport report() const override;

/// The stepper of options.mode for `system`, the choice made once: closed-form ->
/// ClosedFormStepper; newmark -> NewmarkStepper; cvode -> CvodeStepper with massless
/// leaves, and with leaf mass (a density > 0) the leaf-inertia variants (docs/time-integration.md):
/// held-for-good contact on bonded and frictionless stacks, modal inertia with events
/// when a pair has friction, the whole massive stack on elastic interfaces. Validates `options`
/// (SimulationOptions::validate) and throws InputError for what the chosen stepper does not take,
/// naming the field, its value and the steppers that take it (one check against the stepper's
/// capabilities: lib/time/stepper_registry.hpp, docs/time-integration.md).
std::unique_ptr<Stepper> make_stepper(const System& system, const SimulationOptions& options);

}  // namespace stackbeam
