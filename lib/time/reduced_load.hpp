#pragma once
// Internal: the loading on the reduced DOFs of a stack whose leaves may have mass.
#include <Eigen/Dense>

#include "stackbeam/fe/system.hpp"
#include "stackbeam/model/loading.hpp"

namespace stackbeam::detail {

/// A loading on the reduced DOFs of a stack whose leaves may have mass (loading.hpp, with the
/// leaves' own inertia): q(t) = e_w F(t)/f - (g + y_b''(t)) l [N, meshed part], with
/// l = System::vertical_inertia_kg() (the leaves' weight and R's; massless leaves: l = m e_w,
/// and e_w^T q = Loading::external_force_n / f). A prescribed displacement adds nothing (the
/// rig's force is a reaction). Seat loads (full model): q += e_theta (M(t) - H(t) h) + e_u H(t).
class ReducedLoad {
public:
    ReducedLoad(const System& system, const Loading& prepared)
        : load_(prepared), l_(system.vertical_inertia_kg()), f_(system.model().whole_spring_factor()),
          theta_(system.seat_rotation_dof()), axial_(system.seat_axial_dof()) {}
    /// q(t) [N, N m per reduced DOF].
    Eigen::VectorXd at(double t_s) const {
        Eigen::VectorXd q = -(load_.gravity_m_per_s2 + base_acceleration(t_s)) * l_;
        if (load_.kind == LoadingKind::applied_force) q[q.size() - 1] += load_.force_n.value(t_s) / f_;
        // seat loads: the full model only (require_loading_fits), so f = 1 and the DOFs exist
        if (load_.has_seat_load() && theta_ >= 0) q[theta_] += load_.seat_moment_n_m_at(t_s);
        if (load_.longitudinal_force_n && axial_ >= 0) q[axial_] += load_.longitudinal_force_n_at(t_s);
        return q;
    }
    /// y_b''(t) [m/s^2] (base excitation), 0 otherwise.
    double base_acceleration(double t_s) const {
        return load_.kind == LoadingKind::base_excitation ? load_.displacement_m.second_derivative(t_s) : 0.0;
    }
    /// Whether q is zero at every t.
    bool none() const {
        return load_.gravity_m_per_s2 == 0.0 && !load_.has_seat_load() &&
               (load_.kind == LoadingKind::initial_conditions || load_.kind == LoadingKind::prescribed_displacement);
    }
    const Eigen::VectorXd& inertia_kg() const { return l_; }

private:
    Loading load_;
    Eigen::VectorXd l_;
    double f_;
    int theta_, axial_;  // the seat's DOFs (-1: none)
};

}  // namespace stackbeam::detail
