// Natural frequencies of the stack with the leaves' mass (modal.hpp).
#include "stackbeam/fe/modal.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <cmath>
#include <string>

#include "stackbeam/errors.hpp"

namespace stackbeam {

ModalResult modal_analysis(const System& system, ModalTie tie, int count) {
    const int nz = system.num_reduced_dofs();
    const Eigen::MatrixXd K = Eigen::MatrixXd(system.stiffness_reduced());
    const Eigen::MatrixXd M = Eigen::MatrixXd(system.mass_reduced());
    // rows held
    std::vector<int> rows;
    for (const auto& cp : system.pairs()) {
        if (tie == ModalTie::none) break;
        if (cp.row_n >= 0) rows.push_back(cp.row_n);
        if (tie == ModalTie::all && cp.row_t >= 0) rows.push_back(cp.row_t);
    }
    const Eigen::MatrixXd G = Eigen::MatrixXd(system.contact_rows());
    Eigen::MatrixXd GS(static_cast<Eigen::Index>(rows.size()), nz);
    for (std::size_t i = 0; i < rows.size(); ++i) GS.row(static_cast<Eigen::Index>(i)) = G.row(rows[i]);
    // null space of G_S: the trailing columns of Q in G_S^T = Q R (rank from the QR)
    Eigen::MatrixXd N;
    if (GS.rows() == 0) {
        N = Eigen::MatrixXd::Identity(nz, nz);
    } else {
        Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(GS.transpose());
        qr.setThreshold(1e-12);
        const Eigen::Index rank = qr.rank();
        const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(nz, nz);
        N = Q.rightCols(nz - rank);
    }
    const Eigen::MatrixXd KN = N.transpose() * K * N;
    const Eigen::MatrixXd MN = N.transpose() * M * N;
    Eigen::LLT<Eigen::MatrixXd> mass_llt(MN);
    if (mass_llt.info() != Eigen::Success)
        throw InputError("leaves[].density_kg_per_m3",
                         "the modal analysis needs mass in every direction the tied stack can move: give the leaves "
                         "a density > 0 (a massless stack has one mode, the body on the condensed stiffness)");
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (KN + KN.transpose()), 0.5 * (MN + MN.transpose()));
    if (es.info() != Eigen::Success) throw SolverError("modal analysis: the eigen-solve failed", 0, 0.0, 0.0);
    const Eigen::Index m = count > 0 ? std::min<Eigen::Index>(count, es.eigenvalues().size()) : es.eigenvalues().size();
    ModalResult r;
    r.omega_rad_per_s.resize(m);
    for (Eigen::Index i = 0; i < m; ++i) r.omega_rad_per_s[i] = std::sqrt(std::max(0.0, es.eigenvalues()[i]));
    r.shapes = N * es.eigenvectors().leftCols(m);
    r.w_amplitude = r.shapes.row(nz - 1).transpose();
    return r;
}

}  // namespace stackbeam
