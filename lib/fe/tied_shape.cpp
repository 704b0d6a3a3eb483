// The static shape of the stack with contact components tied (tied_shape.hpp).
#include "fe/tied_shape.hpp"

#include <Eigen/SparseLU>

#include "stackbeam/errors.hpp"
#include "stackbeam/fe/system.hpp"

namespace stackbeam::detail {

Eigen::VectorXd tied_shape(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& G,
                           const std::vector<int>& tied, double w, const Eigen::VectorXd& d) {
    const int n = static_cast<int>(K.rows());
    const int nr = n - 1;
    const int ns = static_cast<int>(tied.size());
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(static_cast<std::size_t>(K.nonZeros() + 2 * G.nonZeros()));
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(nr + ns);
    for (int col = 0; col < K.outerSize(); ++col)
        for (Eigen::SparseMatrix<double>::InnerIterator it(K, col); it; ++it) {
            if (it.row() < nr && it.col() < nr) t.emplace_back(static_cast<int>(it.row()), static_cast<int>(it.col()), it.value());
            else if (it.row() < nr && it.col() == nr) rhs[it.row()] -= it.value() * w;
        }
    const Eigen::SparseMatrix<double, Eigen::RowMajor> Gr = G;
    for (int i = 0; i < ns; ++i) rhs[nr + i] = d[tied[i]];
    for (int i = 0; i < ns; ++i)
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(Gr, tied[i]); it; ++it) {
            const int col = static_cast<int>(it.col());
            if (col < nr) {
                t.emplace_back(nr + i, col, it.value());
                t.emplace_back(col, nr + i, it.value());
            } else {
                rhs[nr + i] -= it.value() * w;
            }
        }
    Eigen::SparseMatrix<double> A(nr + ns, nr + ns);
    A.setFromTriplets(t.begin(), t.end());
    A.makeCompressed();
    Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
    lu.compute(A);
    if (lu.info() != Eigen::Success)
        throw SolverError("the static shape with the contact components "
                          "tied (initial state of the inertia modes) is singular: " + lu.lastErrorMessage(), 0, 0.0, 0.0);
    const Eigen::VectorXd x = lu.solve(rhs);
    Eigen::VectorXd z(n);
    z.head(nr) = x.head(nr);
    z[nr] = w;
    return z;
}

}  // namespace stackbeam::detail
