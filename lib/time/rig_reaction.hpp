#pragma once
// Internal: the rig's reaction on R's DOF in the steppers with leaf mass (the force that
// makes w follow the prescribed motion).
#include <Eigen/Dense>
#include <vector>

namespace stackbeam::detail {

/// The rig's reaction on R's DOF (w last): adds lambda u_w to the accelerations a = M^-1 r so that
/// a_w = w_dd [m/s^2], u_w = M^-1 e_w [1/kg]; returns lambda = (w_dd - a_w) / (u_w)_w [N].
inline double prescribe_w_acceleration(Eigen::VectorXd& a, const Eigen::VectorXd& u_w, double w_dd) {
    const Eigen::Index w = a.size() - 1;
    const double lambda = (w_dd - a[w]) / u_w[w];
    a += lambda * u_w;
    return lambda;
}

/// The rigs' reactions on several prescribed DOFs H (the vertical rig's w, the windup rig's theta_R):
/// adds U lambda to a = M^-1 r so that a_H = zdd_H, U = M^-1 E_H (n x |H|); solves
/// U_HH lambda = zdd_H - a_H and returns lambda [N, N m].
inline Eigen::VectorXd prescribe_accelerations(Eigen::VectorXd& a, const Eigen::MatrixXd& U, const std::vector<int>& held,
                                               const Eigen::VectorXd& zdd) {
    const Eigen::Index nh = static_cast<Eigen::Index>(held.size());
    Eigen::MatrixXd Uhh(nh, nh);
    Eigen::VectorXd rhs(nh);
    for (Eigen::Index i = 0; i < nh; ++i) {
        for (Eigen::Index j = 0; j < nh; ++j) Uhh(i, j) = U(held[i], j);
        rhs[i] = zdd[i] - a[held[i]];
    }
    const Eigen::VectorXd lambda = Uhh.partialPivLu().solve(rhs);
    a += U * lambda;
    return lambda;
}

}  // namespace stackbeam::detail
