#pragma once
// Internal: what the choice of a stepper and its refusals read from the system: leaf mass,
// pairs that may change mode, rigid contact rows.
#include "stackbeam/fe/system.hpp"

namespace stackbeam::detail {

/// True when a pair of `system` carries friction (it may stick or slip): mode cvode with
/// leaf mass then runs the modal stepper; without friction the held-for-good one.
bool has_mode_changes(const System& system);

/// True when mode cvode runs `system` with leaf inertia (a leaf has density > 0).
bool has_leaf_mass(const System& system);

/// The first pair of `system` with a contact row that has no elastic layer (a rigid interface
/// or a point clamp), or -1 when every row has one.
int first_rigid_pair(const System& system);

}  // namespace stackbeam::detail
