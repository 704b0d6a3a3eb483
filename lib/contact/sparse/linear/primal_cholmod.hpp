#pragma once
// Internal: the linear problem of a set of modes with many held layer rows, in the primal
// form on a CHOLMOD factor (primal_cholmod.cpp; docs/decisions/027-primal-cholmod-route.md).
//
// An elastic interface's row r carries its own layer degree of freedom u_r (stiffness k_r,
// G'(r, u_r) = e_r; SparseContactSolver's layered problem), so a held layer row is a spring,
// not a constraint: eliminating u_r and the row's force p_r = (d_r - g_r z - e_r f_u / k_r)
// / c_r, c_r = e_r^2 / k_r, leaves on the leaves' degrees of freedom z
//     (P + N) z - Gh_R^T q_R = h,   G_R z = d_R,
//     P = K_zz + sum over held layer rows of g_r^T g_r / c_r        (symmetric positive definite)
//     N = sum over slipping pairs with a held layer normal row n of (mu_coef / c_n) g_t^T g_n
// with the held rigid rows R (clamps, rigid interfaces) as multipliers q_R (their columns
// Gh_R^T = G_R^T plus their slip couplings). P is factorised by CHOLMOD (simplicial LDL^T)
// under a fill-reducing ordering computed once per (K, G) on the pattern of K_zz with every
// layer row held; a new held set differs from the factor's by a few rows, which
// cholmod_updown adds or removes (rank k), unless so many changed that a numeric
// refactorisation on the same ordering is cheaper. The rigid rows by a dense Schur
// complement M = G_R P^-1 Gh_R^T (one multi-column solve per set); N by right-preconditioned
// GMRES on the whole system with the exact block factorisation of [P, -Gh^T; G_R, 0] as
// preconditioner (N = 0: the preconditioner is the inverse, and GMRES is iterative
// refinement). The residual is taken with the explicit operator, so a drifting factor costs
// iterations, not accuracy; refresh() refactorises.
#include <Eigen/Dense>
#include <memory>
#include <vector>

#include "contact/active_set.hpp"
#include "contact/sparse/driver/common.hpp"

namespace stackbeam::detail::sparse {

struct SparseStiffness;

/// Whether this build has CHOLMOD (STACKBEAM_HAVE_CHOLMOD): without it the primal route is
/// never taken (held sets above the Schur way's limit take the sparse LU).
bool primal_route_built();

/// CHOLMOD's fill-reducing orderings, computed once per (K, G) (ModeSolverTuning).
enum class PrimalOrdering { amd, metis, nesdis, cholmod_default };

/// Counters of the primal route since its last reset (tests, benchmark).
struct PrimalStats {
    long factorisations = 0;   ///< numeric factorisations of P (on the fixed ordering)
    long updates = 0;          ///< sets reached by cholmod_updown
    long rank = 0;             ///< rows added or removed by cholmod_updown
    long krylov_iterations = 0;  ///< preconditioned GMRES iterations (refinement steps included)
    long solves = 0;           ///< solves of a set's system
    long fallbacks = 0;        ///< sets the route gave back (GMRES did not reach its tolerance)
};

/// The primal route's solver. An interface: its one implementation (CHOLMOD) is compiled
/// only when CMake found CHOLMOD; make_primal_solver() returns null otherwise.
class PrimalSolver {
public:
    virtual ~PrimalSolver() = default;

    /// A new (K', G'): finds the layer rows (a degree of freedom with a diagonal-only column
    /// of K' and one entry in G', in one row), orders and analyses the pattern of P with
    /// every layer row held. Nothing is factorised yet.
    virtual void reset(const SparseStiffness& st) = 0;
    /// Number of contact rows with a layer degree of freedom.
    virtual int layer_rows() const = 0;
    virtual bool is_layer(int row) const = 0;

    /// Makes the factor and the rigid rows' Schur complement for the held set of `lin`
    /// (pos: row -> index in lin.S, or -1). False if the held rigid rows are dependent.
    virtual bool factor(const modes::ModeLinearization& lin, const std::vector<int>& pos) = 0;
    /// Solves the set's linear problem for the load f = b + G'^T e (n' entries) and the held
    /// rows' offsets dS (lin.S order) into their forces pS and z (n' entries). False if the
    /// Krylov iteration did not reach its tolerance (the caller then solves another way).
    virtual bool solve(const modes::ModeLinearization& lin, const std::vector<int>& pos, const Eigen::VectorXd& f,
                       const Eigen::VectorXd& dS, Eigen::VectorXd& pS, Eigen::VectorXd& z) = 0;
    /// Refactorises P from scratch for the current held set if it was reached by updates
    /// (the caller's accepted step), so updates never accumulate over a run.
    virtual void refresh() = 0;
    /// Refactorises P from scratch for every next set (tests: the reference solves).
    virtual void set_always_refactorise(bool on) = 0;

    virtual const PrimalStats& stats() const = 0;
    virtual void reset_stats() = 0;
};

/// A new primal solver with this ordering, or null in a build without CHOLMOD.
std::shared_ptr<PrimalSolver> make_primal_solver(PrimalOrdering ordering);

}  // namespace stackbeam::detail::sparse
