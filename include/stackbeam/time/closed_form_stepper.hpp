#pragma once
/// @file closed_form_stepper.hpp
/// Mode closed-form: the paper's step for the rigid body on the massless stack.
///
/// Mode "closed-form" is the paper's reference scheme (section 4): the contact
/// forces vary linearly over a step (eq. 14), so the motion of R has the exact
/// solution (eq. 16)
///     w(t') = k1 sin(omega t') + k2 cos(omega t') + [F(t) + (F(t+dt) - F(t)) (t'-t)/dt] / k,
/// with omega = sqrt(k/m), F = c^T p the force of the contact forces on R. Hence
///     w(t+dt) = w_free + (gamma/k) c^T p(t+dt),   gamma = 1 - sin(omega dt)/(omega dt),
/// and the contact problem at t+dt is s = W p + q with
///     W = C' + (gamma/k) c c^T  (constant for a fixed dt),  q = c w_free - d,
/// which the chosen solver resolves (the paper's 8-step algorithm with the
/// paper solver: steps 3-8 are its iteration on this problem).
#include <memory>
#include <vector>

#include "stackbeam/contact/contact.hpp"
#include "stackbeam/contact/step.hpp"
#include "stackbeam/fe/system.hpp"
#include "stackbeam/time/simulation.hpp"
#include "stackbeam/time/stepper.hpp"

namespace stackbeam {

/// The paper's closed-form stepping (mode "closed-form").
///
/// On the sparse path (ContactPath) the same step is posed on the reduced stiffness
/// instead of on W (SparseContactProblem, K z = b + G^T p, s = G z - d): eq. 16's
/// w(t+dt) = w_free + (gamma/k) c^T p makes the rigid body a spring on w,
///     K_aug = K + k_R e_w e_w^T,  k_R = k (1 - gamma) / gamma,   b = (k/gamma) w_free e_w,
/// which is exact: eliminating z gives W = G K_aug^-1 G^T = C' + (gamma/k) c c^T and
/// q = c w_free - d (the w row reads (k + k_R) w = (k/gamma) w_free + c^T p, and
/// k + k_R = k/gamma). So both paths solve the same problem, to round-off.
///
/// Its Stepper outputs: advance() is one step of dt (SolverError: step, time, residual, when the
/// contact solve fails and options.stop_on_nonconvergence); nodes() are z of the sparse path, or of
/// the forces and w on the dense path (System::reduced_displacements: the massless leaves are in
/// equilibrium with p and w); stresses() of that z and pairs(); report() the steps, and the contact
/// iterations and factorisations summed over the records.
class ClosedFormStepper final : public Stepper {
public:
    /// Checks `options` (SimulationOptions::validate and what the mode takes: InputError) and
    /// starts from the shared initial state (the assembly, gravity, R held at w(0)).
    ClosedFormStepper(const System& system, const SimulationOptions& options);
    ~ClosedFormStepper() override;
    STACKBEAM_STEPPER_OVERRIDES

    /// Contact forces p [N] per component row (paper sign: p_n < 0 compression).
    const Eigen::VectorXd& contact_forces() const noexcept;
    /// Relative surface positions s + d [m] per row (normal: approach, tangential: slip position).
    const Eigen::VectorXd& relative_positions() const noexcept;
    /// Tangential anchors d_t and normal gaps d_n [m] per row.
    const Eigen::VectorXd& anchors() const noexcept;
    /// State of each pair of system().pairs().
    std::vector<PairState> pair_states() const;
    /// The step's contact solve (step.hpp): its last problem in the form solved
    /// (last_dense_problem(), last_sparse_problem()), e.g. to replay a step with another solver.
    const StepContactSolver& contact_solver() const noexcept;
    /// The path this stepper's contact operator took (never automatic): for reports.
    ContactPath contact_path() const noexcept;
    /// Reduced displacements z of the leaves [m, rad] at the current step (w last), on either path.
    Eigen::VectorXd reduced_displacements() const;
    const SolveResult& last_solve() const noexcept;
    const System& system() const noexcept;
    double omega_rad_per_s() const noexcept;

private:
    struct Impl;
    friend struct ClosedFormStepperAccess;  // internal: make_stepper builds it from the set-up stage
    explicit ClosedFormStepper(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace stackbeam
