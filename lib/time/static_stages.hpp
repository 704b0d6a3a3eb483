#pragma once
// Internal: the quasi-static solves before t = 0: the stack under a load with R free or held
// (sparse path), the assembly and gravity stages of the steppers with leaf mass, and the
// massless stack's static equilibrium under a force on R (on the run's path).
#include <Eigen/Dense>
#include <string>

#include "stackbeam/contact/contact.hpp"
#include "stackbeam/contact/step.hpp"
#include "stackbeam/fe/system.hpp"
#include "stackbeam/time/simulation.hpp"

namespace stackbeam::detail {

/// The contact problem of the massless stack with R held at w [m], the load parameter u = [w],
/// in both forms (step.hpp; the operator takes one): dense W = C', q = c w - d; sparse (on z_r)
/// K_rr z_r = -K_rw w + G_r^T p, s = G_r z_r + c_L p - (d - G_w w). The rig's steps of mode
/// closed-form and the contact state at t = 0 with R held at w(0) pose it.
StepSystem held_body_system(const System& system);

/// The quasi-static state of the stack under a load b on the reduced DOFs [N, N m per DOF]
/// (w last), one load step with friction from the warm start p with `laws`' pairs and tau rule
/// and the offsets d: with R free (w_held_m NaN) K z = G^T p + b on every DOF; with R held at
/// w_held_m [m] the rows of z_r only (z_w = w_held_m). Sparse path with the exact solver and
/// options' tuning, whatever the model's size (a one-off solve). On exit p holds the forces [N]
/// and d is re-anchored (reanchor). Returns z [m, rad]; throws SolverError naming `what` if the
/// solve fails; `result` (optional) receives the solve.
Eigen::VectorXd static_state(const System& system, const ContactLaws& laws, const Eigen::VectorXd& b, double w_held_m,
                             const SimulationOptions& options, Eigen::VectorXd& p, Eigen::VectorXd& d,
                             const std::string& what, SolveResult* result = nullptr);

/// The stack before t = 0 in the steppers with leaf mass (mode newmark, the massive cvode
/// stack), each stage a static_state with R free: the assembly of free camber, clips and
/// interference (needs_assembly; no load: the interference of the offsets d resolved with friction; simulation.hpp
/// "assembly"), then the static equilibrium under `weight` [N per reduced DOF] when it is not
/// zero (gravity: -g l). Returns whether a stage ran; z [m, rad], p [N] and d (re-anchored)
/// hold the state, `result` the last solve.
bool static_stages(const System& system, const ContactLaws& laws, const Eigen::VectorXd& weight,
                   const SimulationOptions& options, Eigen::VectorXd& z, Eigen::VectorXd& p, Eigen::VectorXd& d,
                   SolveResult* result = nullptr);

/// The static equilibrium of the massless stack under a force `force_n` [N] on R (meshed
/// part), as one quasi-static load step from the state with anchors d, R free: K z = F e_w + G^T p,
/// s = G z + c_L p - d, on the form `path` resolves to (dense: R's balance k w - c^T p = F
/// eliminated, W = C' + c c^T/k, q = c F/k - d). `laws` gives the pairs and tau rule, `p` the warm
/// start and the forces on exit; d's non-stuck pairs are re-anchored. `solver` is shared by the
/// stages (the dense exact solver keeps its modes over them). Returns w [m], z and the solve;
/// throws SolverError (naming `what`) if the contact solve fails.
struct StaticState {
    double w_m = 0.0;
    Eigen::VectorXd z;  ///< [m, rad], w last
    SolveResult solve;
};
StaticState massless_static_state(const System& system, const ContactLaws& laws, double force_n, ContactPath path,
                                  StepContactSolver& solver, Eigen::VectorXd& p, Eigen::VectorXd& d,
                                  const std::string& what);

}  // namespace stackbeam::detail
