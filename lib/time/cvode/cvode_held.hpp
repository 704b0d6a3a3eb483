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
// The event driver (event_driver.hpp) runs it with no contact event hooks (EventStart::events
// null: zero witnesses, no per-step contact check) and SUNDIALS' band solver on the Jacobian
// above (NewtonSolver::band).
// Stacks with friction (pairs that may stick or slip) run CvodeModalStepper (cvode_modal.hpp);
// its row of the registry (stepper_registry.hpp) takes no friction.
#include "stackbeam/time/simulation.hpp"
#include "time/cvode/event_driver.hpp"
#include "time/initial_state.hpp"

namespace stackbeam::detail {

/// Mode "cvode" with leaf inertia on bonded and frictionless stacks (above): the event driver
/// (event_driver.hpp) without contact events, CVODE's BDF with the band direct solver.
class CvodeHeldStepper final : public EventStepper {
public:
    /// From the shared set-up stage's state (initial_state.hpp; the options checked there).
    CvodeHeldStepper(const System& system, const InitialState& start);

private:
    struct Impl;
};

}  // namespace stackbeam::detail
