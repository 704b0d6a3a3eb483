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
    none_ = load_.gravity_m_per_s2 == 0.0 &&
            (load_.kind == LoadingKind::initial_conditions || load_.kind == LoadingKind::prescribed_displacement);
    const Eigen::Index ndof = l_.size();
    Eigen::MatrixXd B = Eigen::MatrixXd::Zero(ndof, 2);
    B.col(0) = l_;
    B(ndof - 1, 1) = 1.0;
    // R B = K^-1 B - Phi Omega^-2 Phi^T B: the quasi-static response of the modes above the cut
    Fq = Phi.transpose() * B;
    RB = Eigen::MatrixXd(kf.solve(B)) - Phi * omega.cwiseProduct(omega).cwiseInverse().asDiagonal() * Fq;
    const Eigen::MatrixXd G(system.contact_rows());
    Hq = G * RB;
    wq = RB.row(ndof - 1).transpose();
    Rqq = B.transpose() * RB;
    Rqq = (0.5 * (Rqq + Rqq.transpose())).eval();
}

ModalLoad::Values ModalLoad::at(double t_s) const {
    Values v;
    if (none_) return v;
    // channel 0: -(g + y_b''); its rates by central differences of y_b'' (TimeFunction gives up to
    // the second derivative; y_b is C2 and smooth between a table's points). The steps balance
    // truncation (h^2 y_b^(5) / 6) against round-off (eps y_b'' / h, eps y_b'' / h^2): at 8 Hz
    // u' to ~1e-9 of itself (it enters the work and the witnesses' rates), u'' to ~1e-6 (only
    // the record's m w'' uses it).
    const bool base = load_.kind == LoadingKind::base_excitation;
    v.u[0] = -load_.gravity_m_per_s2;
    if (base) {
        const TimeFunction& y = load_.displacement_m;
        const double h1 = 1e-6, h2 = 1e-4;  // [s]
        const double a = y.second_derivative(t_s);
        v.u[0] -= a;
        v.ud[0] = -(y.second_derivative(t_s + h1) - y.second_derivative(t_s - h1)) / (2.0 * h1);
        v.udd[0] = -(y.second_derivative(t_s + h2) - 2.0 * a + y.second_derivative(t_s - h2)) / (h2 * h2);
    }
    // channel 1: F(t)/f
    if (load_.kind == LoadingKind::applied_force) {
        const TimeFunction& F = load_.force_n;
        v.u[1] = F.value(t_s) / f_;
        v.ud[1] = F.derivative(t_s) / f_;
        v.udd[1] = F.second_derivative(t_s) / f_;
    }
    return v;
}

}  // namespace stackbeam::detail
