#pragma once
// Internal: the rig's reaction on R's DOF in the steppers with leaf mass (the force that
// makes w follow the prescribed motion).
#include <Eigen/Dense>

namespace stackbeam::detail {

/// The rig's reaction on R's DOF (w last): adds lambda u_w to the accelerations a = M^-1 r so that
/// a_w = w_dd [m/s^2], u_w = M^-1 e_w [1/kg]; returns lambda = (w_dd - a_w) / (u_w)_w [N].
inline double prescribe_w_acceleration(Eigen::VectorXd& a, const Eigen::VectorXd& u_w, double w_dd) {
    const Eigen::Index w = a.size() - 1;
    const double lambda = (w_dd - a[w]) / u_w[w];
    a += lambda * u_w;
    return lambda;
}

}  // namespace stackbeam::detail
