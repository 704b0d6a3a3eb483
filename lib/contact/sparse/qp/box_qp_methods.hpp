#pragma once
// Internal: the box-constrained QP of the Tresca fixed point on the sparse path,
//     min 1/2 x^T W x + q^T x   over  lower <= x <= upper,
// W = G K^-1 G^T, q = G K^-1 b - d never formed: its gradient is s = W x + q = G z - d [m]
// with z = K^-1 (b + G^T x). x are contact forces [N]: a unilateral normal in (-inf, 0],
// a tangential component in [-mu tau, mu tau] (friction limits frozen). Three methods
// with one signature (BoxQpFn); each ends at the same optimality test (box_row_violation
// below `tolerance` [m] in every row), so their answers agree to round-off.
#include <Eigen/Dense>
#include <vector>

#include "contact/sparse/driver/sparse_path.hpp"

namespace stackbeam::detail::sparse {

/// One box QP: the step's load and offsets, the bounds [N] (infinite where absent; equal
/// for a box of zero width) and the optimality tolerance [m].
struct BoxQp {
    const Step& step;
    const Eigen::VectorXd& lower;
    const Eigen::VectorXd& upper;
    double tolerance;
};

/// x [N]: start on entry, solution on exit (z = K^-1 (b + G^T x) with it). at_bound: the
/// working set, -1 / +1 for a row held at its lower / upper bound, 0 free; on entry the
/// start (a method may ignore it), on exit the final one. Counts its iterations and
/// factorisations into r. Returns false when it does not settle (x, z, at_bound are then
/// its last iterate; the caller restarts the next method from its own start).
using BoxQpFn = bool (*)(SparsePath& path, const BoxQp& qp, Eigen::VectorXd& x, Eigen::VectorXd& z,
                         std::vector<signed char>& at_bound, SolveResult& r);

/// Block principal pivoting (Judice & Pires), at most 50 passes.
bool box_qp_pivoting(SparsePath& path, const BoxQp& qp, Eigen::VectorXd& x, Eigen::VectorXd& z,
                     std::vector<signed char>& at_bound, SolveResult& r);
/// Primal-dual interior-point method (Mehrotra's predictor-corrector), at most 100 iterations.
bool box_qp_interior_point(SparsePath& path, const BoxQp& qp, Eigen::VectorXd& x, Eigen::VectorXd& z,
                           std::vector<signed char>& at_bound, SolveResult& r);
/// The monotone primal active-set method (box_qp.hpp's, each step a sparse solve): cannot
/// cycle; at most 50 (m + 1) iterations.
bool box_qp_primal(SparsePath& path, const BoxQp& qp, Eigen::VectorXd& x, Eigen::VectorXd& z,
                   std::vector<signed char>& at_bound, SolveResult& r);

/// The box QP's optimality test of row i in metres, for a working set whose held rows
/// (at_bound 0) the solve satisfies exactly (s_i = 0): a held force outside its box
/// (times W_ii [m/N]), or a force at a bound whose gradient s_i pushes it into the box.
/// box_qp_pivoting stops when no row exceeds the tolerance; box_qp_interior_point also
/// checks |s_i| of the held rows, which its iterate satisfies only approximately.
double box_row_violation(int i, const std::vector<signed char>& at_bound, const Eigen::VectorXd& x,
                         const Eigen::VectorXd& s, const Eigen::VectorXd& lower, const Eigen::VectorXd& upper,
                         const Eigen::VectorXd& diag);

}  // namespace stackbeam::detail::sparse
