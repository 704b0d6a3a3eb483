#pragma once
// Internal: the diagonal of the contact compliance W = G K^-1 G^T [m/N] from the selected
// inverse of K's Cholesky factor, without forming W (selected_inverse.cpp).
#include <Eigen/Dense>

#include "contact/sparse/driver/common.hpp"

namespace stackbeam::detail::sparse {

/// diag(G K^-1 G^T) [m/N], the compliance of each contact row alone (it scales force
/// violations to metres). K: n x n stiffness [N/m, N, N m per unit DOF], symmetric positive
/// definite, both triangles stored, compressed; G: m x n contact rows [-]; k_llt: K's
/// Cholesky factor (used only for rows whose entries of K^-1 lie off the selected pattern).
/// Exact to round-off. Throws InputError("problem.K") if K without its hub DOFs is not
/// positive definite.
Eigen::VectorXd selected_compliance_diagonal(const SpMat& K, const SpMat& G, const KCholesky& k_llt);

}  // namespace stackbeam::detail::sparse
