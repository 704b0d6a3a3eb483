// The impulse projection of an impact on the form of the step's operator (step.hpp).
#include <Eigen/SparseLU>

#include "stackbeam/contact/step.hpp"
#include "stackbeam/errors.hpp"

namespace stackbeam {

struct ImpactProjection::Impl {
    const Eigen::SparseMatrix<double>& M;
    const Eigen::SparseMatrix<double>& G;
    bool dense = false;
    Eigen::MatrixXd Z, A;                        // dense: M^-1 G^T and G M^-1 G^T
    std::vector<int> held;                       // the held rows of the last projection
    Eigen::LDLT<Eigen::MatrixXd> held_factor;    // dense: A restricted to them
    Eigen::SparseLU<Eigen::SparseMatrix<double>> saddle;  // sparse: [M G_C^T; G_C 0]
};

ImpactProjection::ImpactProjection(const Eigen::SparseMatrix<double>& M,
                                   const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>& mass,
                                   const Eigen::SparseMatrix<double>& G, const ContactOperator& op)
    : impl_(new Impl{M, G}) {
    // dense where the step's operator is dense (m^2 doubles are affordable there)
    impl_->dense = op.path() == ContactPath::dense;
    if (!impl_->dense) return;
    impl_->Z = G.rows() > 0 ? Eigen::MatrixXd(mass.solve(Eigen::MatrixXd(G.transpose())))
                            : Eigen::MatrixXd(G.cols(), 0);  // no contact rows: an empty solve is UB in Eigen
    const Eigen::MatrixXd A = G * impl_->Z;
    impl_->A = 0.5 * (A + A.transpose());
}

ImpactProjection::~ImpactProjection() = default;

double ImpactProjection::project(const std::vector<int>& held, const Eigen::VectorXd& b, bool elastic, double factor,
                                 long step, double t_s, Eigen::VectorXd& v) {
    Impl& im = *impl_;
    const int nh = static_cast<int>(held.size());
    if (!im.dense) {
        // M v+ + G_C^T l = M v,  G_C v+ = 0: one sparse LU per held set
        const Eigen::SparseMatrix<double>& M_ = im.M;
        const int n = static_cast<int>(v.size());
        if (held != im.held) {
            std::vector<Eigen::Triplet<double>> t;
            for (int col = 0; col < M_.outerSize(); ++col)
                for (Eigen::SparseMatrix<double>::InnerIterator it(M_, col); it; ++it)
                    t.emplace_back(static_cast<int>(it.row()), static_cast<int>(it.col()), it.value());
            const Eigen::SparseMatrix<double, Eigen::RowMajor> Gr = im.G;
            for (int i = 0; i < nh; ++i)
                for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(Gr, held[i]); it; ++it) {
                    t.emplace_back(n + i, static_cast<int>(it.col()), it.value());
                    t.emplace_back(static_cast<int>(it.col()), n + i, it.value());
                }
            Eigen::SparseMatrix<double> S(n + nh, n + nh);
            S.setFromTriplets(t.begin(), t.end());
            S.makeCompressed();
            im.saddle.compute(S);
            if (im.saddle.info() != Eigen::Success)
                throw SolverError("newmark: the impact projection's matrix is singular at step " + std::to_string(step),
                                  step, t_s, 0.0);
            im.held = held;
        }
        Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n + nh);
        rhs.head(n) = M_ * v;
        rhs.tail(nh) = b;
        const Eigen::VectorXd x = im.saddle.solve(rhs);
        const Eigen::VectorXd dv = v - x.head(n);
        v = x.head(n);
        if (!elastic) return 0.5 * factor * dv.dot(M_ * dv);
        // M dv = G_C^T l: l^T (G_C v + b) = dv^T M (2 v - dv) = dv^T M v + ... (kinetic energy change)
        const Eigen::VectorXd vold = v + dv;
        return 0.5 * factor * (vold.dot(M_ * vold) - v.dot(M_ * v));
    }
    const Eigen::VectorXd gv = im.G * v;
    if (held != im.held) {  // factorise A_hh once per held set
        Eigen::MatrixXd Ahh(nh, nh);
        for (int i = 0; i < nh; ++i)
            for (int k = 0; k < nh; ++k) Ahh(i, k) = im.A(held[i], held[k]);
        im.held_factor.compute(Ahh);
        im.held = held;
    }
    Eigen::VectorXd rhs(nh);
    for (int i = 0; i < nh; ++i) rhs[i] = gv[held[i]];
    const Eigen::VectorXd l = im.held_factor.solve(Eigen::VectorXd(rhs - b));
    Eigen::VectorXd dv = Eigen::VectorXd::Zero(v.size());
    for (int i = 0; i < nh; ++i) dv += im.Z.col(held[i]) * l[i];
    v -= dv;
    // 1/2 l^T (G_C v + b) (= 1/2 dv^T M dv = 1/2 l^T A_hh l when b = 0; dv = M^-1 G_C^T l)
    return 0.5 * factor * l.dot(rhs + b);
}

}  // namespace stackbeam
