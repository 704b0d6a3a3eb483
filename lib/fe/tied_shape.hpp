#pragma once
// Internal: the static shape of the stack with some contact components held, used for
// the initial state of the modes with leaf inertia (newmark_stepper.cpp, cvode_held.cpp).
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <vector>

namespace stackbeam {
class System;
}

namespace stackbeam::detail {

/// Reduced displacements z (w last) of the static stack with R at w [m] and the contact
/// rows `tied` held at G_S z = d_S [m] (K: reduced stiffness, G: contact rows):
///     [K_rr  G_Sr^T] [z_r]   [-K_rw w       ]
///     [G_Sr  0     ] [ l ] = [d_S - G_Sw w  ],   z_w = w,
/// one sparse LU of the saddle-point matrix. With d = 0 and w = 1: the velocity shape per
/// unit w'. Throws SolverError if the matrix is singular.
Eigen::VectorXd tied_shape(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& G,
                           const std::vector<int>& tied, double w, const Eigen::VectorXd& d);

}  // namespace stackbeam::detail
