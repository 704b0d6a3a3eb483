#pragma once
// Internal: the ways of the sparse path to solve a transition (a step whose modes change),
// each behind one signature (TransitionFn), so that SparseContactSolver::solve
// (sparse_solver.cpp) is a sequence of them. Every one ends with the current modes
// (path.modes) those of its answer; the caller confirms them by the active-set passes
// (passes_from_modes) where the method is not itself exact for its modes.
#include <Eigen/Dense>

#include "contact/sparse/sparse_path.hpp"

namespace stackbeam::detail::sparse {

/// p [N]: start on entry, answer on exit; z the displacements with it (on entry
/// K^-1 (b + G^T p) where a method says so). Counts iterations and factorisations into r.
/// Returns true when it settled.
using TransitionFn = bool (*)(SparsePath& path, const Step& step, Eigen::VectorXd& p, Eigen::VectorXd& z,
                              SolveResult& r);

/// The active-set passes from the current modes (options.max_active_set_iterations of
/// them, block principal pivoting with Murty's rule; active_set.hpp): exact when it settles.
bool passes_from_modes(SparsePath& path, const Step& step, Eigen::VectorXd& p, Eigen::VectorXd& z, SolveResult& r);

/// Semismooth Newton method on the natural map (semismooth_newton.cpp). On entry z must be
/// K^-1 (b + G^T p). Leaves its iterate of smallest ||F|| in path.best_p.
bool semismooth_newton(SparsePath& path, const Step& step, Eigen::VectorXd& p, Eigen::VectorXd& z, SolveResult& r);

/// Smoothing Newton method on the natural map (smoothing_newton.cpp). On entry z must be
/// K^-1 (b + G^T p).
bool smoothing_newton(SparsePath& path, const Step& step, Eigen::VectorXd& p, Eigen::VectorXd& z, SolveResult& r);


/// The Tresca fixed point on the friction limits, each pass a box QP (tresca.cpp;
/// path.switches.box_qp chooses the box-QP methods); on success its working set gives
/// the modes. It starts from the current modes and p.
bool tresca_fixed_point(SparsePath& path, const Step& step, Eigen::VectorXd& p, Eigen::VectorXd& z, SolveResult& r);

}  // namespace stackbeam::detail::sparse
