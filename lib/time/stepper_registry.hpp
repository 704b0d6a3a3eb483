#pragma once
// Internal: the steppers make_stepper can build, each with what it takes as data (one row of
// the registry), the choice of the row for a system and options, and the one check that
// refuses what the chosen row does not take. Adding a stepper: write its class (a constructor
// from the System and the InitialState, initial_state.hpp), add a row here (stepper_registry.cpp)
// and, if the mode's choice needs it, a case in choose_stepper; the refusals, the initial state
// and the contract suite (tests/test_stepper_contract.cpp) follow from the row.
#include <memory>
#include <string>
#include <vector>

#include "stackbeam/fe/system.hpp"
#include "stackbeam/time/simulation.hpp"
#include "stackbeam/time/stepper.hpp"

namespace stackbeam::detail {

struct InitialState;  // initial_state.hpp

/// How the shared set-up stage (initial_state.hpp) starts a stepper.
enum class StartKind {
    /// R on the massless stack: the assembly and R's weight as static steps on the dense
    /// compliance C' (dense path) or the sparse stack (sparse path), then the contact state
    /// with R held at w(0) (the rig: w_p(0)).
    massless_stack,
    /// The whole stack with leaf mass: the assembly and the weight of everything (-g l) as
    /// static steps on the sparse stack, then R held at w(0) with the weight on (a static step
    /// when pre-stressed, else the contact state on C'), the leaves moving with R in the tied
    /// shape of the closed rows times w'(0).
    whole_stack,
    /// As whole_stack, R held at w(0) always by a static step (exact, re-anchored).
    whole_stack_static,
    /// None: the stepper starts its leaves in its own tied shape at w(0) (the held-for-good
    /// stepper, which takes initial conditions only).
    tied_shape,
};

/// What one stepper takes, as data. A false field is refused by check_capabilities with an
/// InputError naming the field as the user wrote it and the steppers whose rows take it.
struct StepperCapabilities {
    const char* name;         ///< short name ("cvode-massive"): tests and messages
    const char* description;  ///< as in the messages: "mode cvode with the whole massive stack"
    Mode mode;
    bool massive_leaves;      ///< every leaf with density > 0 (false: every leaf massless)
    // loadings (initial conditions: every stepper)
    bool applied_force, base_excitation, gravity, rig;
    bool rig_on_rigid_contact;  ///< the rig with a contact row that has no elastic layer
    bool seat_loads;            ///< a seat moment, a longitudinal force (Loading::has_seat_load)
    bool seat_loads_with_rig;   ///< seat loads together with the vertical rig (kind prescribed-displacement)
    bool pitch_inertia;         ///< the axle's pitch inertia J > 0 on theta_R (RigidBodySpec::pitch_inertia_kg_m2)
    bool windup_rig;            ///< theta_R prescribed (Loading::seat_rotation_rad), w held by the vertical rig or free
    bool windup_rig_on_rigid_contact;  ///< the windup rig with a contact row that has no elastic layer
    bool assembly;              ///< free camber, clips, interference (needs_assembly)
    bool damping;               ///< structural (Rayleigh) damping
    bool layer_damping;         ///< the elastic layer's normal dashpots (damping.layer_normal_time_s)
    bool restitution;           ///< the impact law's restitution > 0
    bool previous_step_tau;     ///< TauRule::previous_step
    // contact laws and rows
    bool friction;              ///< pairs that may stick or slip (Coulomb or clamp with mu > 0)
    bool rigid_rows;            ///< contact rows without an elastic layer (rigid interface, point clamp)
    bool elastic_layer;         ///< contact rows with an elastic layer
    // outputs beyond the record's common columns
    bool leaf_kinetic_energy;   ///< StepRecord::leaf_kinetic_energy_j (leaves with inertia)
    bool impact_loss;           ///< StepRecord::impact_loss_j (impacts of massive contact points)
    bool cvode_stats;           ///< RunReport::cvode and the event log
    // the set-up
    StartKind start;
    /// The shared stage's static and held solves by the exact solver (mode cvode decides its modes
    /// with it) instead of the configured one.
    bool exact_start;
    std::unique_ptr<Stepper> (*build)(const System& system, const InitialState& start);
};

/// Every stepper make_stepper can build, one row each.
const std::vector<StepperCapabilities>& stepper_registry();

/// The row named `name` (StepperCapabilities::name); throws std::out_of_range if none.
const StepperCapabilities& registered_stepper(const std::string& name);

/// The row of mode newmark for `system`: by leaves[0]'s density (a mix of massive and massless
/// leaves is refused by either row's check).
const StepperCapabilities& newmark_row(const System& system);

/// The row of the stepper for options.mode and `system` (make_stepper's choice, stepper.hpp).
const StepperCapabilities& choose_stepper(const System& system, const SimulationOptions& options);

/// Throws InputError for the first thing `system` or `options` asks that `stepper` does not take,
/// naming the field as the user wrote it, its value and the steppers of the registry that take it.
void check_capabilities(const StepperCapabilities& stepper, const System& system, const SimulationOptions& options);

}  // namespace stackbeam::detail
