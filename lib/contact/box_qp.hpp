#pragma once
// Internal: a primal active-set solver for the box-constrained convex QP
//     min 1/2 x^T W x + q^T x   subject to  lower <= x <= upper   (W SPD),
// whose optimality conditions with s = W x + q are: s_i = 0 inside the box,
// s_i >= 0 at a lower bound, s_i <= 0 at an upper bound. For a fixed friction
// limit (Tresca) this is exactly the incremental contact problem: a unilateral
// normal has bounds (-inf, 0], a tangential component [-mu tau, mu tau].
// The objective falls monotonically, so the method cannot cycle (Nocedal &
// Wright, Algorithm 16.3, specialised to bounds).
#include <Eigen/Dense>
#include <vector>

namespace stackbeam::detail {

struct BoxQpResult {
    bool converged = false;
    int iterations = 0;
    int factorizations = 0;
};

/// The feasible start of the box QP: x projected onto [lower, upper]; components at a
/// finite bound are held there (at_bound -1 / +1, resized to x's size), a given hold at
/// an infinite bound is dropped, and a box of zero width is held (+1).
void project_onto_box(const Eigen::VectorXd& lower, const Eigen::VectorXd& upper, Eigen::VectorXd& x,
                      std::vector<signed char>& at_bound);

/// x: start on entry (projected onto the box), solution on exit. `at_bound` on entry:
/// -1 / +1 for components to hold at their lower / upper bound (the working set), 0
/// free; on exit the final working set. `tolerance` is the multiplier tolerance [same
/// units as s].
BoxQpResult solve_box_qp(const Eigen::MatrixXd& W, const Eigen::VectorXd& q, const Eigen::VectorXd& lower,
                         const Eigen::VectorXd& upper, Eigen::VectorXd& x, std::vector<signed char>& at_bound,
                         double tolerance, int max_iterations);

}  // namespace stackbeam::detail
