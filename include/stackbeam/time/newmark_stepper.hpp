#pragma once
/// @file newmark_stepper.hpp
/// Mode "newmark": the leaves' inertia (consistent mass matrices, System::mass_reduced())
/// integrated by the implicit average-acceleration Newmark rule (beta = 1/4, gamma = 1/2)
/// with the paper's contact problem solved at every step: the natural extension of the
/// paper's scheme (section 4) to massive leaves, and the fixed-step reference of the
/// inertia mode (docs/time-integration.md).
///
/// On the reduced DOFs z = [z_r; w] (system.hpp: K = stiffness_reduced(), M = mass_reduced(),
/// G = contact_rows(), s = G z - d), the equations of motion are M z'' + K z = G^T p, and
///     z1 = z0 + dt/2 (v0 + v1),   M (v1 - v0) = dt [ -K (z0 + z1)/2 + G^T pbar ],
/// i.e. the average-acceleration rule for the elastic forces. The contact force over the
/// step, pbar, is taken two ways:
///
///  - massive leaves (every density > 0): pbar = p1, the contact impulse over the step is
///    dt p1 (implicit, as in Moreau's time stepping), and after the step the relative
///    velocity of every held component (closed normal, sticking tangential, bonded) is set
///    to zero by the mass-weighted projection v <- v - M^-1 G_C^T l, G_C v = 0: the impact
///    law with restitution 0. Why not pbar = (p0 + p1)/2 (Newmark as printed): with massive
///    contact points the position-level contact then gives back at every opening the work
///    (p0 Delta s)/2 of a force it no longer carries; on the friction case at dt = 0.1 ms
///    the leaves chatter and the energy grows without bound (measured: 1e25 J by t = 0.03 s).
///    With pbar = p1 the normal work p1_n Delta s_n is <= 0 (p1_n < 0 only on a closed pair,
///    which cannot have moved apart) and the friction work p1_t Delta s_t = -beta p1_t^2 <= 0:
///    the step can only lose energy through the contact, and conserves it otherwise.
///  - massless leaves (every density 0): pbar = (p0 + p1)/2 with a0 from M a0 = G^T p0 - K z0,
///    Newmark as printed; the leaf DOFs have no mass and are condensed statically at each
///    step (K z1 = G^T p1 on their rows) as in the paper, only the body is integrated (by the
///    trapezoidal rule instead of eq. 16's exact step: they agree to O(dt^2)). No impacts.
///  A mix of massive and massless leaves is refused (InputError).
///
/// Per step, with K_eff = K + 4 M / dt^2 and kappa = 1 (massless) or 2 (massive):
///     K_eff z1 = r + kappa G^T p1,
///     r = M (4/dt^2 z0 + 4/dt v0) - K z0   (massive),   r = M (4/dt^2 z0 + 4/dt v0 + a0)   (massless),
/// so the contact problem at t + dt is the paper's s = W p + q (eq. 6) with
///     W = kappa G K_eff^-1 G^T  (constant for a fixed dt: one sparse Cholesky of K_eff),
///     q = G K_eff^-1 r - d,
/// solved by the chosen ContactSolver (the sparse path: SparseContactProblem with
/// K = K_eff/kappa, b = r/kappa). Anchors are re-set as in the closed-form mode (section 5).
///
/// Energy: the step satisfies exactly (to round-off)
///     E(t+dt) - E(t) = pbar^T G (z1 - z0) - (projection loss),   E = 1/2 v^T M v + 1/2 z^T K z.
/// The tangential part of the contact work is the friction work (dissipated_energy_j);
/// the normal part plus the projection's loss is StepRecord::impact_loss_j (zero while
/// pairs stay closed or stay open). So the balance
///     E0 = kinetic + strain + dissipated + impact_loss
/// closes to round-off whatever the contact solver returns.
///
/// Loadings (loading.hpp): q(t) on the right-hand side, by the trapezoidal rule with massive
/// leaves (r gains q0 + q1, the step's work is (q0 + q1)^T (z1 - z0) / 2, exact in the balance)
/// and at t1 with massless ones. Gravity starts from the static equilibrium of the whole stack
/// under its weight (the shared set-up stage's static step). The rig (massive leaves, elastic interfaces): the
/// step solves z_r with w1 = w_p(t1) given; its mean force over the step follows from R's row of
/// the step's momentum balance (its work closes the balance), its force at t1 from
/// M a1 = G^T p1 - K z1 + q1 + lambda1 e_w with a1_w = w_p''(t1).
///
/// Structural damping (SimulationOptions::damping, massive leaves): the damping force by the
/// same rule, -C (v0 + v1)/2 = -C (z1 - z0)/dt, so K_eff gains (2/dt) C and the step loses
/// (z1 - z0)^T C (z1 - z0)/dt (StepRecord::damping_energy_j), exactly in the balance.
///
/// Initial state: w(0), w'(0) from the rigid body; the leaves at the static shape for w(0)
/// (contact state with R held at w(0), as in the closed-form mode), their velocity w'(0)
/// times the static shape per unit w with the closed contact components tied (every
/// bilateral one; unilateral ones with a closed gap; their tangential component too when it
/// carries friction or is bonded): the stack moves with the body, no initial impact.
#include <Eigen/Dense>
#include <memory>
#include <vector>

#include "stackbeam/contact/contact.hpp"
#include "stackbeam/contact/step.hpp"
#include "stackbeam/time/simulation.hpp"
#include "stackbeam/time/stepper.hpp"
#include "stackbeam/fe/system.hpp"

namespace stackbeam {

/// Its Stepper outputs: advance() is one step of dt (SolverError: step, time, residual, when the
/// contact solve fails and options.stop_on_nonconvergence); nodes() and stresses() are of
/// displacements() (and pairs()); report() the steps, and the contact iterations and
/// factorisations summed over the records.
class NewmarkStepper final : public Stepper {
public:
    /// Throws InputError for bad options (SimulationOptions::validate and what the mode takes with
    /// the stack's leaf mass; on the sparse path a solver other than exact); starts from the
    /// shared initial state (the assembly, gravity, R held at w(0)).
    NewmarkStepper(const System& system, const SimulationOptions& options);
    ~NewmarkStepper() override;
    STACKBEAM_STEPPER_OVERRIDES

    /// Reduced displacements z [m, rad] (w last), velocities [m/s, rad/s], accelerations [m/s^2, rad/s^2].
    const Eigen::VectorXd& displacements() const noexcept;
    const Eigen::VectorXd& velocities() const noexcept;
    const Eigen::VectorXd& accelerations() const noexcept;
    /// Contact forces p [N] per component row (paper sign: p_n < 0 compression).
    const Eigen::VectorXd& contact_forces() const noexcept;
    /// Tangential anchors d_t and normal gaps d_n [m] per row.
    const Eigen::VectorXd& anchors() const noexcept;
    const SolveResult& last_solve() const noexcept;
    /// The path this stepper's contact operator took (never automatic).
    ContactPath contact_path() const noexcept;

private:
    struct Impl;
    friend struct NewmarkStepperAccess;  // internal: make_stepper builds it from the set-up stage
    explicit NewmarkStepper(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace stackbeam
