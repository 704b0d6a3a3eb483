#pragma once
// Internal: the ways of the sparse path to solve a transition (a step whose modes change),
// each behind one signature (TransitionFn), so that SparseContactSolver::solve
// (sparse_solver.cpp) is a sequence of them. Every one ends with the current modes
// (path.modes) those of its answer; the caller confirms them by the active-set passes
// (passes_from_modes) where the method is not itself exact for its modes.
#include <Eigen/Dense>
#include <vector>

#include "contact/sparse/driver/sparse_path.hpp"
#include "contact/sparse/driver/trace.hpp"

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

/// Where the path of path_following starts: the previous solve's data (b0, d0) on the same
/// K, G and pairs, and its final modes (valid there).
struct PathStart {
    const Eigen::VectorXd& b;
    const Eigen::VectorXd& d;
    const std::vector<signed char>& nmode;
    const std::vector<signed char>& tmode;
};

/// The parametric active-set transition (Switches::path_following; path_following.cpp):
/// follows the solution from `start` (the previous step's data and final modes) to `step`
/// along the straight line between their data, switching the pairs whose mode condition
/// fails first at each breakpoint; each set of modes on the way solved as a low-rank change
/// of the base modes' (one factorisation). True when it reached t = 1: the current modes
/// (path.modes) are then the path's end and p its forces (the caller confirms them by the
/// passes). TauRule::current only (else false, end not_applicable). Its limits and repairs
/// are path.switches' path_* fields: path_rebase_rows > 0: when more rows than that differ
/// from the base modes, the current modes become the base (one factorisation); 0: the start
/// modes stay the base (up to 400 changed rows). path_max_start_hits > 0: false (end
/// too_many_start_hits) where more of the start modes' conditions than that fail before t = 1.
bool path_following(SparsePath& path, const Step& step, const PathStart& start, Eigen::VectorXd& p,
                    Eigen::VectorXd& z, SolveResult& r, PathStats& stats);

/// The linear problem of the current modes (path.modes) for `step` on the homotopy's kept base
/// (Switches::path_keep_base, docs/decisions/045; path_following.cpp): where the base's
/// factorisation is still current, the homotopy ran in this solve or the one before, and the modes
/// differ from the base's in at most path_rebase_rows rows C, x = x^ + Y lambda from the base's
/// solution x^ for this data and the columns of C (those missing solved on the base), then
/// iterative refinement against the modes' own saddle-point system (each correction the same
/// bordered solve of its residual) until the held rows' residual is a direct solve's (1e-16 of
/// s's terms). False (nothing changed but the kept columns) where it does not apply, the bordered
/// system is singular or ill-conditioned, or the refinement does not get there: the caller
/// factorises, as without it. No factorisation (counted as an update).
bool solve_on_kept_base(SparsePath& path, const Step& step, Eigen::VectorXd& p, Eigen::VectorXd& z);

/// The covering start of the homotopy (covering_start.cpp; Switches::rest_path_violations): for the
/// current modes M0 (path.modes) and their linear solution (p, z) at `step`'s data, the data
/// (b0, d0) at which M0 holds, its solution there the projection of (p, s) onto M0's
/// conditions; PathStart{b0, d0, M0} then starts path_following toward `step`.
void covering_start(const SparsePath& path, const Step& step, const Eigen::VectorXd& p, const Eigen::VectorXd& z,
                    Eigen::VectorXd& b0, Eigen::VectorXd& d0);

}  // namespace stackbeam::detail::sparse
