#pragma once
// Internal: the one set-up stage of every stepper (stepper_registry.hpp): the options checked
// against the chosen stepper's row, the loading prepared, and the state before t = 0 computed
// once (the assembly, gravity's static step, the contact state with R held at w(0) or the
// rig's w_p(0), and under the windup rig theta_R held at theta_R(0) as well, the anchors, the
// leaves' initial velocity). A stepper's constructor starts
// from it and builds its own operators only.
#include <Eigen/Dense>

#include "stackbeam/contact/contact.hpp"
#include "stackbeam/fe/system.hpp"
#include "stackbeam/time/simulation.hpp"
#include "time/stepper_registry.hpp"

namespace stackbeam::detail {

struct InitialState {
    SimulationOptions options;  ///< as given, the loading prepared for the stepper (Loading::prepare)
    ContactPath path = ContactPath::dense;  ///< the contact path (never automatic; mode cvode: dense)
    ContactLaws laws;           ///< the pairs, the tau rule and zero previous-step limits
    Eigen::VectorXd p;          ///< contact forces at t = 0 [N] (paper sign)
    Eigen::VectorXd d;          ///< gaps and anchors at t = 0 [m] (the offsets, re-anchored by the static steps)
    /// Reduced displacements at t = 0 [m, rad] (w last): the whole stack's starts and the sparse
    /// path; empty on the massless stack's dense path (R's w0_m and p give the state there).
    Eigen::VectorXd z;
    Eigen::VectorXd v0;         ///< whole stack: reduced velocities at t = 0 [m/s, rad/s] (else empty)
    double w_static_m = 0.0;    ///< R after the static steps (assembly, gravity) [m]
    double w0_m = 0.0;          ///< R at t = 0 [m]: w_static + the body's w(0), or the rig's w_p(0)
    /// R's velocity at t = 0 [m/s]: the body's w'(0) relative to the supports (base excitation),
    /// or the rig's w_p'(0)
    double wd0_m_per_s = 0.0;
    bool rig = false;           ///< R's motion prescribed (LoadingKind::prescribed_displacement)
    bool pre_stressed = false;  ///< a static step ran (assembly or gravity)
    SolveResult solve;          ///< the last contact solve of the stage (converged when none ran)
    /// Event steppers: locate transitions by CVODE's root-finding (the method). false, for tests
    /// only (no option or scenario key): the per-step contact check alone finds them, by bisection
    /// on the dense output, to test that safety net (tests/test_cvode.cpp).
    bool root_finding = true;
};

/// The stage for `stepper`: check_capabilities, then the state before t = 0 by the row's
/// StartKind. Throws InputError (check_capabilities, Loading::prepare) or SolverError naming the
/// stage whose contact solve failed.
InitialState initial_state(const StepperCapabilities& stepper, const System& system, const SimulationOptions& options);

/// As above for the row named `name` after options.validate(): the public stepper classes'
/// constructors from (System, SimulationOptions) start here.
InitialState initial_state(const char* name, const System& system, const SimulationOptions& options);

}  // namespace stackbeam::detail
