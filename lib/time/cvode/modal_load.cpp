// The loadings of the modal leaf-inertia stepper (modal_load.hpp).
#include "time/cvode/modal_load.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "fe/tied_shape.hpp"
#include "stackbeam/errors.hpp"
#include "time/contact_state.hpp"
#include "time/static_stages.hpp"

namespace stackbeam::detail {

ModalLoad::ModalLoad(const System& system, const Loading& prepared, const Eigen::MatrixXd& Phi,
                     const Eigen::VectorXd& omega, const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>& kf)
    : load_(prepared), l_(system.vertical_inertia_kg()), f_(system.model().whole_spring_factor()) {
    none_ = load_.gravity_m_per_s2 == 0.0 && !load_.has_seat_load() &&
            (load_.kind == LoadingKind::initial_conditions || load_.kind == LoadingKind::prescribed_displacement);
    const Eigen::Index ndof = l_.size();
    Eigen::MatrixXd B = Eigen::MatrixXd::Zero(ndof, kChannels);
    B.col(0) = l_;
    B(ndof - 1, 1) = 1.0;
    if (system.seat_rotation_dof() >= 0) B(system.seat_rotation_dof(), 2) = 1.0;
    if (system.seat_axial_dof() >= 0) B(system.seat_axial_dof(), 3) = 1.0;
    // R B = K^-1 B - Phi Omega^-2 Phi^T B: the quasi-static response of the modes above the cut
    Fq = Phi.transpose() * B;
    RB = Eigen::MatrixXd(kf.solve(B)) - Phi * omega.cwiseProduct(omega).cwiseInverse().asDiagonal() * Fq;
    const Eigen::MatrixXd G(system.contact_rows());
    Hq = G * RB;
    wq = RB.row(ndof - 1).transpose();
    Rqq = B.transpose() * RB;
    Rqq = (0.5 * (Rqq + Rqq.transpose())).eval();
}

namespace {

/// The piece of table `ts` that holds [t_s, next point): -1 before the first point, i on
/// [t_i, t_i+1), n - 1 (the last index) from the last point on.
long table_piece(const std::vector<double>& ts, double t_s) {
    return static_cast<long>(std::upper_bound(ts.begin(), ts.end(), t_s) - ts.begin()) - 1;
}

}  // namespace

std::vector<double> ModalLoad::breaks(double t_end_s) const {
    std::vector<double> b;
    if (none_) return b;
    auto add = [&](const TimeFunction& F) {
        if (F.shape != TimeFunction::Shape::table) return;
        for (double t : F.times_s)
            if (t > 0.0 && t < t_end_s) b.push_back(t);
    };
    if (load_.kind == LoadingKind::base_excitation) add(load_.displacement_m);
    if (load_.kind == LoadingKind::applied_force) add(load_.force_n);
    if (load_.seat_moment_n_m) add(*load_.seat_moment_n_m);
    if (load_.longitudinal_force_n) add(*load_.longitudinal_force_n);
    std::sort(b.begin(), b.end());
    b.erase(std::unique(b.begin(), b.end()), b.end());
    return b;
}

ModalLoad::Values ModalLoad::at(double t_s) const {
    Values v;
    if (none_) return v;
    v.u[0] = -load_.gravity_m_per_s2;
    if (load_.kind == LoadingKind::base_excitation) {
        const TimeFunction& y = load_.displacement_m;
        if (y.shape == TimeFunction::Shape::table) {
            // channel 0 on the current piece: the clamped spline's y'' is linear on [t_i, t_i+1]
            // (M_i, M_i+1 at its ends), y''' its slope, y'''' = 0; 0 before the first point and
            // from the last on (y is constant there)
            const std::vector<double>& ts = y.times_s;
            const long i = table_piece(ts, piece_t_s_);
            if (i >= 0 && i + 1 < static_cast<long>(ts.size())) {
                const std::size_t k = static_cast<std::size_t>(i);
                const double h = ts[k + 1] - ts[k], Mi = y.spline_m2[k], Mj = y.spline_m2[k + 1];
                v.u[0] -= (Mi * (ts[k + 1] - t_s) + Mj * (t_s - ts[k])) / h;
                v.ud[0] = -(Mj - Mi) / h;
            }
        } else {
            // a harmonic (or constant) base: its rates by central differences of y_b''
            // (TimeFunction gives up to the second derivative). The steps balance truncation
            // (h^2 y_b^(5) / 6) against round-off (eps y_b'' / h, eps y_b'' / h^2): at 8 Hz u' to
            // ~1e-9 of itself (it enters the work and the witnesses' rates), u'' to ~1e-6 (only
            // the record's m w'' uses it).
            const double h1 = 1e-6, h2 = 1e-4;  // [s]
            const double a = y.second_derivative(t_s);
            v.u[0] -= a;
            v.ud[0] = -(y.second_derivative(t_s + h1) - y.second_derivative(t_s - h1)) / (2.0 * h1);
            v.udd[0] = -(y.second_derivative(t_s + h2) - 2.0 * a + y.second_derivative(t_s - h2)) / (h2 * h2);
        }
    }
    // a force's channel: scale F(t) and its rates added to channel c; a table (piecewise linear) as the
    // line of the current piece
    auto add_force = [&](const TimeFunction& F, double scale, int c) {
        if (F.shape == TimeFunction::Shape::table) {
            const std::vector<double>& ts = F.times_s;
            const long i = table_piece(ts, piece_t_s_);
            if (i < 0) {
                v.u[c] += scale * F.values.front();
            } else if (i + 1 >= static_cast<long>(ts.size())) {
                v.u[c] += scale * F.values.back();
            } else {
                const std::size_t k = static_cast<std::size_t>(i);
                const double slope = (F.values[k + 1] - F.values[k]) / (ts[k + 1] - ts[k]);
                v.u[c] += scale * (F.values[k] + slope * (t_s - ts[k]));
                v.ud[c] += scale * slope;
            }
        } else {
            v.u[c] += scale * F.value(t_s);
            v.ud[c] += scale * F.derivative(t_s);
            v.udd[c] += scale * F.second_derivative(t_s);
        }
    };
    // channel 1: F(t)/f; channels 2 and 3: the seat's M(t) - H(t) h and H(t) (full model: f = 1)
    if (load_.kind == LoadingKind::applied_force) add_force(load_.force_n, 1.0 / f_, 1);
    if (load_.seat_moment_n_m) add_force(*load_.seat_moment_n_m, 1.0, 2);
    if (load_.longitudinal_force_n) {
        add_force(*load_.longitudinal_force_n, -load_.longitudinal_force_height_m, 2);
        add_force(*load_.longitudinal_force_n, 1.0, 3);
    }
    return v;
}

}  // namespace stackbeam::detail
