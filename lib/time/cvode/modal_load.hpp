#pragma once
// Internal: the loadings of the modal leaf-inertia stepper (cvode_modal.cpp): the loading's
// terms of its right-hand side and contact problem, the quasi-static rest of the modes above
// the cut under the loading, the start from the static state, and the event scales
// (docs/decisions/026-loaded-modal-stepper.md).
#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <vector>

#include "stackbeam/contact/contact.hpp"
#include "stackbeam/fe/system.hpp"
#include "stackbeam/model/loading.hpp"
#include "stackbeam/time/simulation.hpp"

namespace stackbeam::detail {

/// A loading with the leaves' own inertia (loading.hpp), q(t) = e_w F(t)/f - (g + y_b''(t)) l on
/// the reduced DOFs plus the seat loads, written as four channels q(t) = B u(t):
///     u_0(t) = -(g + y_b''(t)) [m/s^2]   on  b_0 = l = System::vertical_inertia_kg() [kg]
///     u_1(t) = F(t) / f [N]              on  b_1 = e_w
///     u_2(t) = M(t) - H(t) h [N m]       on  b_2 = e_theta (0 on the half model)
///     u_3(t) = H(t) [N]                  on  b_3 = e_u (0 where the seat does not slide)
/// (gravity on every mass, the base's inertial force in the supports' frame, the force on R, the
/// seat's moment and longitudinal force),
/// projected on the retained modes Phi (mass-normalised, circular frequencies omega) and on the
/// residual flexibility R = K^-1 - Phi Omega^-2 Phi^T of the modes above the cut. With the
/// mode-acceleration split z = Phi eta + R (G^T p + q):
///     eta'' + Omega^2 eta = Phi^T G^T p + Fq u(t)                       Fq = Phi^T B       (r x 4)
///     s = W p + G Phi eta + Hq u(t) - d                                 Hq = G R B         (n x 4)
///     w = Phi_w eta + (R G^T)_w p + wq^T u(t)                          wq = (R B)_w       (4)
/// and the loading's work int q^T dz = [q^T z] - int q'^T z dt with
///     q^T z = u^T (Fq^T eta + Hq^T p + Rqq u),                         Rqq = B^T R B      (4 x 4)
/// so the work needs u' but never p' (the quasi-static rest jumps with p at an event).
/// The rig (a prescribed displacement) is not a channel: see the decision note.
class ModalLoad {
public:
    static constexpr int kChannels = 4;
    using Channels = Eigen::Matrix<double, kChannels, 1>;
    /// The loading `prepared` (Loading::prepare(true)) on `system` with the retained modes Phi,
    /// omega [rad/s] and K's factorisation `kf`.
    ModalLoad(const System& system, const Loading& prepared, const Eigen::MatrixXd& Phi, const Eigen::VectorXd& omega,
              const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>& kf);

    /// The channels' values u(t) and their first and second time derivatives.
    struct Values {
        Channels u = Channels::Zero(), ud = Channels::Zero(), udd = Channels::Zero();
    };
    /// u(t) on the current piece of the loading (enter_piece): between two breaks a table's channel
    /// is one polynomial (the base spline's cubic, the force table's line), evaluated, extrapolated
    /// past its ends, as that polynomial, so CVODE sees a smooth right-hand side up to a break.
    Values at(double t_s) const;
    /// The breaks of the loading in (0, t_end_s) [s]: a table's points, where u or u' is not smooth
    /// (the clamped base spline's y'' jumps from 0 to M_0 at its first point and from M_n to 0 at
    /// its last, its y''' at every point; a force table's slope at every point). Sorted.
    std::vector<double> breaks(double t_end_s) const;
    /// Selects the piece of the loading that holds [t_s, next break) (the run starts on the piece of t = 0).
    void enter_piece(double t_s) { piece_t_s_ = t_s; }
    /// True when q is zero at every t (initial conditions only).
    bool none() const noexcept { return none_; }
    /// The weight of the stack and R on the reduced DOFs, -g l [N per DOF, meshed part] (the static stage's load).
    Eigen::VectorXd weight() const { return -load_.gravity_m_per_s2 * l_; }

    Eigen::MatrixXd Fq;   ///< Phi^T B, r x 4
    Eigen::MatrixXd Hq;   ///< G R B [m per unit u], n x 4
    Channels wq;          ///< (R B)_w [m per unit u]
    Eigen::Matrix<double, kChannels, kChannels> Rqq;  ///< B^T R B
    Eigen::MatrixXd RB;   ///< R B [m per unit u], ndof x 4 (the nodes' quasi-static part)

    /// (B v)^T z at (eta, p, u) [J, meshed part, per unit of v / u], z = Phi eta + R (G^T p + B u):
    /// v = u gives q^T z, v = u' the rate q'^T z of the work's integral.
    double q_dot_z(const Eigen::Ref<const Eigen::VectorXd>& eta, const Eigen::Ref<const Eigen::VectorXd>& p,
                   const Channels& u, const Channels& v) const {
        return v.dot(Fq.transpose() * eta + Hq.transpose() * p + Rqq * u);
    }

private:
    Loading load_;
    Eigen::VectorXd l_;
    double f_ = 1.0;
    bool none_ = true;
    double piece_t_s_ = 0.0;  ///< a time on the current piece's left-closed interval [s]
};

}  // namespace stackbeam::detail
