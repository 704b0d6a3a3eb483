#pragma once
// Internal: the types and thresholds shared by the units of the sparse contact path
// (lib/contact/sparse/*): the sparse matrices, the stiffness's Cholesky factor, and the
// acceptance threshold of the active-set decisions (the dense exact solver's).
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

namespace stackbeam::detail::sparse {

using SpMat = Eigen::SparseMatrix<double>;
using RowMat = Eigen::SparseMatrix<double, Eigen::RowMajor>;
/// Cholesky factor of the stiffness K (AMD ordering), made once per (K, G).
using KCholesky = Eigen::SimplicialLLT<SpMat, Eigen::Lower, Eigen::AMDOrdering<int>>;

/// Thrown by a linear solve of a set of modes whose saddle-point system is singular
/// (dependent held rows); the solver leaves such a problem to the dense exact solver.
struct SingularModes {};

/// As in the dense solver: a mode is violated beyond kAccept x tolerance [m].
constexpr double kAccept = 1e-3;

}  // namespace stackbeam::detail::sparse
