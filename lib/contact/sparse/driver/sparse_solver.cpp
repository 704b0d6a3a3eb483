// The sparse path: the exact solver's active-set method on
//     K z = b + G^T p,  s = G z - d       (SparseContactProblem, contact.hpp)
// without ever forming the dense W = G K^-1 G^T. This file is the orchestration; the
// units are in lib/contact/sparse/, by layer:
//   driver/       this solver, the shared state (sparse_path: modes, pair laws, active-set
//                 passes, natural map), the methods' internal names (switches.hpp: the public
//                 SparsePathMethods) and the observer (trace.hpp)
//   linear/       the linear problem of one set of modes behind ModeSolver (mode_solver), one
//                 file per route: schur (dense Schur complement, column cache, low-rank update),
//                 bordered_lu (sparse LU and its bordered update), fixed_pattern_lu (KLU or
//                 Eigen on one fixed pattern), primal_cholmod; selected_inverse (W's diagonal)
//   transitions/  the transition methods, one signature (transitions.hpp): semismooth_newton,
//                 smoothing_newton, tresca, path_following (with path_base, covering_start)
//   qp/           the box QP of the Tresca fixed point (pivoting, interior point, primal)
//
// Design (why a saddle-point system per set of modes):
//  - For a set of modes the contact conditions are linear: held rows (closed normal,
//    stuck tangential, bonded) impose G_S z = d_S; slipping rows carry a force affine in
//    their pair's normal force, p_t = e_t + D p_n; open / free rows carry p = e = 0.
//    With z and p_S as unknowns this is one sparse system
//        [ K     -G_S^T - G_slip^T D ] [z  ]   [b + G^T e]
//        [ G_S    0                  ] [p_S] = [d_S      ]
//    whose size and fill grow linearly with the number of elements (the contact rows
//    are local: each touches the DOFs of two leaves at one node). It is not symmetric
//    when a slip row is coupled to its normal force, and it is indefinite, so it is
//    factorised by a sparse LU (Eigen::SparseLU, COLAMD ordering: no extra package)
//    when many rows are held (bonded and frictionless runs: thousands).
//  - The factorisation depends only on the modes; it is kept and reused while they
//    stay, like the dense solver's LU. Within one set of modes the solution is affine in
//    the right-hand side; on the closed-form stepper only b (the rigid body's load,
//    one entry) changes from step to step, and e, d_S only when the modes or anchors
//    do. So two back-solves per set of modes ({unit b entry} and {e, d_S}) are cached
//    and a step whose modes stay costs O(n) (a linear combination, one product with G),
//    not a back-solve.
//  - Few held rows (up to SparsePathTuning::schur_max_rows, 400): the same linear
//    problem by the dense Schur complement of the held rows, M p_S = d_S - G_S z0 with
//    M = G_S K^-1 (G_S^T + G_slip^T D), on a Cholesky factor of K made once per (K, G).
//    The columns K^-1 g_i^T are cached per contact row, so a new set of modes costs the
//    solves of the rows new to the cache and a small dense LU (factor_schur); incrementally
//    (Switches::incremental, the default) its Schur complement is copied from the last
//    factorised set's where it stays and solved by a Woodbury update of that LU, slip
//    couplings included, and z comes from one solve with K's factor (factor_schur_update,
//    docs/decisions/020-incremental-mode-solve.md). This is the usual situation of
//    friction runs on identical leaves: most pairs open, the clamps held. A fresh dense LU
//    (no update of the base reaches the set) only up to Switches::schur_fresh_max_rows
//    (200): larger sets take the sparse LU, KLU of the held set's own system ordered by AMD
//    (Switches::fixed_pattern 4; measured on the identical 10 x 400 stack: 13 ms per set
//    against 26 ms for a fresh Schur LU of 370 slip-coupled rows, docs/decisions/038).
//  - Held sets near the last sparse LU's (at most SparsePathTuning::max_border_rows
//    rows differ, no slip coupling, e.g. the box QP's primal active-set iterations, one
//    row per iteration): the LU is bordered by the changed rows (a low-rank update: a
//    back-solve per changed row, cached, and a dense LU of the k x k capacitance
//    matrix; try_border, border_solve) instead of refactorised.
//  - The diagonal of W scales force violations to metres, exactly as in the dense
//    solver (so both take the same decisions). It is computed once per (K, G) from the
//    selected inverse of K (selected_compliance_diagonal: Takahashi's recurrence on the
//    Cholesky factor of K without the rigid body's DOFs, plus a rank-h correction for
//    them), a few milliseconds at 10 leaves x 400 elements (m triangular solves before:
//    0.35-0.65 s).
//  - Mode switching (violations, block principal pivoting, Murty's rule) is the code
//    of the dense solver (active_set.hpp), and so is the handling of transitions: after
//    max_active_set_iterations passes, a Tresca fixed point (friction limits frozen: a
//    box-constrained convex QP) whose working set gives the modes of a final Coulomb
//    solve. The box QP is solved by block principal pivoting (a few factorisations)
//    and, if that stalls (50 passes), by a primal-dual interior-point method (box_qp_ipm:
//    Mehrotra's predictor-corrector, one sparse LDL^T of K + G^T Sigma^-1 G per iteration,
//    15-45 iterations on every box QP measured, however degenerate; its working set is read
//    from the iterate and its bounded forces put on their bounds), and if that fails, by the
//    dense solver's monotone primal active-set method (one working-set change per iteration,
//    cannot cycle), each step a sparse solve.
//    Before that Tresca fixed point (SparsePathTuning::transition = newton, the default):
//    a semismooth Newton method on the natural map of the contact laws (paper eq. 8; the
//    natural map is zero exactly where eq. 10's error vector is), semismooth_newton: each
//    iteration takes the modes of F's generalised Jacobian at the iterate (from p - s / w,
//    forces and gaps together, so many pairs change at once), solves that set of modes's
//    linear problem (one factorisation, update or cached Schur solve, as a pass) and
//    searches along the step on ||F||^2 (s is affine in p: O(m) per trial). From rest it
//    starts from the open modes (set_open_modes). Its final modes are confirmed by the
//    passes, so its answer is the exact solver's. From rest (Switches::rest_path_violations,
//    docs/decisions/041) it hands its iterate over once at most 25 laws are violated, and
//    the homotopy below finishes the step from a covering start (covering_start: the
//    iterate's modes made valid by moving the step's data). Where the Newton method follows, one
//    pass from the previous modes comes first (not max_active_set_iterations), the line
//    search takes the full step where it stays below the last 10 iterates' worst, and a
//    creeping search goes to the smoothing method early (Switches, decision 037: graduated
//    10 x 400 14.4 -> 9.3 mode-set solves per transition step). At 10 leaves x 100 elements it took the
//    friction run from 50-53 to 2.4 factorisations per step; at 10 x 400 its first step
//    alone still does not converge (docs/decisions/003-semismooth-newton-transitions.md).
//    Where the semismooth method stalls (60 iterations, or no decrease of ||F||): the
//    smoothing Newton method (smoothing_newton) from its best iterate: the natural map
//    with every max(0, .) replaced by (y + sqrt(y^2 + 4 e^2)) / 2, so ||F_eps||^2 is
//    differentiable and Armijo's backtracking always finds a step, and a component at its
//    kink enters the Jacobian half held, half free instead of flipping; e falls with the
//    residual. One sparse LU of the Jacobian's saddle-point system per iteration (its
//    ordering made once per run). Measured (docs/decisions/004-smoothing-newton.md): on a graduated 10-leaf
//    spring at 100 elements it settles the transitions that sent the semismooth method
//    to the Tresca fixed point (thousands of factorisations) in ~20 iterations; at 10
//    identical leaves x 400 elements it stalls too (a near-singular Jacobian from the
//    slip coupling), so that size still does not run with friction.
//    Switches::path_following (on by default, docs/decisions/040): between the
//    passes and the Newton method, the homotopy from the last step's data and modes
//    (path_following.cpp, Impl::path_transition), its modes confirmed by the passes.
//    If all that fails, problems of at most kDenseFallbackMaxRows rows are finished by
//    the dense exact solver on to_dense() (reported as fell_back); larger ones fail
//    with a message.
//  - Cost: a step whose modes stay is O(n); a transition costs a factorisation or an
//    update per pass, and the first steps of a friction run on many identical leaves
//    (all pairs closed at rest, most of them opening) are a degenerate contact problem
//    (identical leaves bend alike: forces and gaps ~0). Without the Newton method the box
//    QP's block principal pivoting stalls there and the primal method changes one row per
//    iteration (thousands of passes); with it, tens of Newton iterations (10 x 100), but at
//    10 x 400 the Newton method stalls near the solution (kinks of F next to the iterate:
//    the line search finds no decrease) and the Tresca fixed point still has to finish.
//    That count, not the cost of a pass, is what keeps large friction runs slow.
#include <cstring>
#include <limits>
#include <string>

#include "contact/solvers.hpp"
#include "contact/sparse/driver/trace.hpp"
#include "contact/sparse/transitions/transitions.hpp"
#include "stackbeam/contact/contact.hpp"
#include "stackbeam/errors.hpp"

namespace stackbeam {

using detail::sparse::SpMat;

void SparseContactProblem::validate() const {
    const int n = static_cast<int>(K.rows());
    if (K.cols() != n) throw InputError("problem.K", "must be square");
    if (G.cols() != n)
        throw InputError("problem.G", "has " + std::to_string(G.cols()) + " columns: must match K (" + std::to_string(n) + ")");
    if (G.rows() != d.size())
        throw InputError("problem.G", "has " + std::to_string(G.rows()) + " rows: must match d (" + std::to_string(d.size()) + ")");
    if (b.size() != n) throw InputError("problem.b", "must have one entry per row of K");
    if (!b.allFinite()) throw InputError("problem.b", "has a non-finite entry");
    if (!d.allFinite()) throw InputError("problem.d", "has a non-finite entry");
    if (layer_compliance.size() != 0 && layer_compliance.size() != d.size())
        throw InputError("problem.layer_compliance", "has " + std::to_string(layer_compliance.size()) +
                                                         " entries: must be empty or one per row of G (" +
                                                         std::to_string(d.size()) + ")");
    if (layer_compliance.size() != 0 && !(layer_compliance.allFinite() && layer_compliance.minCoeff() >= 0.0))
        throw InputError("problem.layer_compliance", "has a negative or non-finite entry: must be finite and >= 0 [m/N]");
    detail::validate_laws(pairs, size(), tau_rule, tau_previous_n);
}

ContactProblem SparseContactProblem::to_dense() const {
    Eigen::SimplicialLLT<SpMat> llt(K);
    if (llt.info() != Eigen::Success) throw InputError("problem.K", "is not positive definite");
    ContactProblem pr;
    const Eigen::MatrixXd X = G.rows() > 0 ? Eigen::MatrixXd(llt.solve(Eigen::MatrixXd(G.transpose())))
                                           : Eigen::MatrixXd(G.cols(), 0);  // an empty solve is UB in Eigen
    pr.W = G * X;
    pr.W = 0.5 * (pr.W + pr.W.transpose()).eval();
    pr.q = G * llt.solve(b) - d;
    if (layer_compliance.size() == pr.W.rows()) pr.W.diagonal() += layer_compliance;
    pr.pairs = pairs;
    pr.tau_rule = tau_rule;
    pr.tau_previous_n = tau_previous_n;
    return pr;
}

namespace {
bool same_matrix(const SpMat& a, const SpMat& b) {
    if (a.rows() != b.rows() || a.cols() != b.cols() || a.nonZeros() != b.nonZeros()) return false;
    if (!a.isCompressed() || !b.isCompressed()) return false;
    const auto nnz = static_cast<std::size_t>(a.nonZeros());
    return std::memcmp(a.valuePtr(), b.valuePtr(), nnz * sizeof(double)) == 0 &&
           std::memcmp(a.innerIndexPtr(), b.innerIndexPtr(), nnz * sizeof(int)) == 0 &&
           std::memcmp(a.outerIndexPtr(), b.outerIndexPtr(), (a.outerSize() + 1) * sizeof(int)) == 0;
}


constexpr int kDenseFallbackMaxRows = 4000;  // the dense fallback: m^2 doubles (128 MB at 4000)

bool same_laws(const std::vector<ContactPair>& a, const std::vector<ContactPair>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t k = 0; k < a.size(); ++k)
        if (a[k].kind != b[k].kind || a[k].friction_coefficient != b[k].friction_coefficient ||
            a[k].preload_n != b[k].preload_n || a[k].row_n != b[k].row_n || a[k].row_t != b[k].row_t)
            return false;
    return true;
}
}  // namespace

namespace detail::sparse {

/// Builds `layered` from `pr`: K' = diag(K, 1/c_L) over the layer rows, G' = [G  E] with
/// E(r, n + j) = 1 for the j-th layer row r, b' = [b; 0]. Returns false if no row has a layer.
bool layer_structure(const SparseContactProblem& pr, SparseContactProblem& layered) {
    const int n = static_cast<int>(pr.K.rows());
    std::vector<int> rows;
    for (int r = 0; r < pr.layer_compliance.size(); ++r)
        if (pr.layer_compliance[r] > 0.0) rows.push_back(r);
    if (rows.empty()) return false;
    const int ne = static_cast<int>(rows.size());
    std::vector<Eigen::Triplet<double>> kt, gt;
    kt.reserve(static_cast<std::size_t>(pr.K.nonZeros()) + rows.size());
    for (int col = 0; col < pr.K.outerSize(); ++col)
        for (SpMat::InnerIterator it(pr.K, col); it; ++it)
            kt.emplace_back(static_cast<int>(it.row()), static_cast<int>(it.col()), it.value());
    for (int col = 0; col < pr.G.outerSize(); ++col)
        for (SpMat::InnerIterator it(pr.G, col); it; ++it)
            gt.emplace_back(static_cast<int>(it.row()), static_cast<int>(it.col()), it.value());
    for (int j = 0; j < ne; ++j) {
        kt.emplace_back(n + j, n + j, 1.0 / pr.layer_compliance[rows[j]]);
        gt.emplace_back(rows[j], n + j, 1.0);
    }
    layered.K.resize(n + ne, n + ne);
    layered.K.setFromTriplets(kt.begin(), kt.end());
    layered.K.makeCompressed();
    layered.G.resize(pr.G.rows(), n + ne);
    layered.G.setFromTriplets(gt.begin(), gt.end());
    layered.G.makeCompressed();
    layered.b = Eigen::VectorXd::Zero(n + ne);
    layered.layer_compliance.resize(0);
    return true;
}

}  // namespace detail::sparse

struct SparseContactSolver::Impl {
    detail::sparse::SparsePath path;
    int newton_min_rows = 0;
    // the solutions of the last two solves (the semismooth Newton method's start is their
    // linear extrapolation when the caller continues that sequence)
    Eigen::VectorXd previous_p, last_p;
    Eigen::VectorXd previous_s, last_s;  // their s (kept only with an observer, for its prediction)
    // the previous modes' linear solution for this step (the first active-set pass's), kept
    // where the passes did not settle (Switches::first_pass_start)
    Eigen::VectorXd p_first_pass;

    Impl(const SolverOptions& options, const SparsePathTuning& tuning)
        : path(options,
               detail::sparse::ModeSolverTuning{tuning.schur_max_rows, tuning.max_border_rows,
                                                tuning.methods.incremental, tuning.primal_min_rows},
               tuning.methods, tuning.observer),
          newton_min_rows(tuning.newton_min_rows) {}

    // The elastic layer (SparseContactProblem::layer_compliance) as extra degrees of freedom:
    // the augmented problem, rebuilt when the caller does not promise the same structure.
    SparseContactProblem layered;
    Eigen::VectorXd z_layered;

    bool layer_structure(const SparseContactProblem& pr) { return detail::sparse::layer_structure(pr, layered); }

    // the homotopy's start (Switches::path_following): the last converged solve's data and modes
    Eigen::VectorXd path_b, path_d;
    std::vector<signed char> path_n, path_t;

    void reset_structure(const SparseContactProblem& pr) {
        path.reset(pr);
        path_d.resize(0);
        previous_p.resize(0);
        last_p.resize(0);
    }

    /// Where a transition method starts (the passes' end: p, z and the modes), put back where
    /// it does not settle, so the next method starts there as without it.
    struct TransitionStart {
        Eigen::VectorXd p, z;
        std::vector<signed char> nmode, tmode;
        TransitionStart(const Eigen::VectorXd& p_, const Eigen::VectorXd& z_, const modes::ModeSet& modes)
            : p(p_), z(z_), nmode(modes.nmode), tmode(modes.tmode) {}
        void restore(Eigen::VectorXd& p_, Eigen::VectorXd& z_, modes::ModeSet& modes) const {
            p_ = p;
            z_ = z;
            modes.nmode = nmode;
            modes.tmode = tmode;
        }
    };

    /// Step 2a, the Newton methods (SparseContactSolver::solve): each
    /// from its start, its answer confirmed by the active-set passes from its modes. True
    /// when one settled; otherwise p, z and the modes are those on entry (the passes' end).
    bool newton_transition(const detail::sparse::Step& step, const Eigen::VectorXd& p_start, Eigen::VectorXd& p,
                           Eigen::VectorXd& z, SolveResult& r) {
        using namespace detail::sparse;
        const int m = static_cast<int>(step.d.size());
        const TransitionMethod tm = path.switches.transition;
        const TransitionStart passes_end(p, z, path.modes);  // the Tresca fixed point starts there
        StepTrace* tr = path.observer ? path.observer->current : nullptr;
        auto confirmed = [&](TransitionFn method, const Eigen::VectorXd& start) {
            p = start;
            path.s = path.stiffness().positions(step.b, step.d, p, z);
            const int smooth0 = r.smoothing_iterations;
            const bool ok = method(path, step, p, z, r);
            if (tr) path.observer->close_phase(method == smoothing_newton ? phase_smoothing : phase_semismooth);
            if (tr && method == smoothing_newton) {
                tr->smoothing_iterations += r.smoothing_iterations - smooth0;
                tr->smoothing_ok = ok;
            }
            if (!ok) return false;
            const int it0 = r.iterations;
            const bool conf = passes_from_modes(path, step, p, z, r);
            if (tr) {
                path.observer->close_phase(phase_confirm);
                tr->confirm_solves += r.iterations - it0;
                if (method == semismooth_newton) tr->newton_confirmed = conf;
            }
            return conf;
        };
        // a start from rest (p = 0, the first step of a run): the smoothing method first
        // (Switches::smoothing_from_rest; graduated 10 x 400 at 2 m/s: 21 iterations where the
        // semismooth method ran its 60 and then the smoothing method's, docs/decisions/037);
        // where it fails, the semismooth method as before
        const bool smoothed_from_start =
            tm == TransitionMethod::newton && path.switches.smoothing_from_rest && p_start.isZero(0.0);
        if (smoothed_from_start && confirmed(smoothing_newton, p_start)) return true;
        if (tm == TransitionMethod::newton) {
            // the start: the previous step's forces extrapolated linearly from the two solves
            // before, when the warm start is the last solve's answer (measured, 10 x 100
            // friction: 14.4 -> 9.5 Newton iterations per step on the graduated spring, 14.2 ->
            // 11.1 on identical leaves, docs/decisions/005-continuation-on-offsets.md); the
            // passes before keep the previous modes (modes read from the extrapolation cost
            // more: 27.7 iterations per step)
            const bool extrapolate = previous_p.size() == m && last_p.size() == m && p_start == last_p;
            // without an extrapolation (the step after the first: one solve before) and not from
            // rest, the first pass's solution, the previous modes' answer to this step's load, not
            // the warm start, the last step's (Switches::first_pass_start; graduated 10 x 400,
            // 100 ms: the second step 92 -> 18 mode-set solves, docs/decisions/037)
            const bool from_first_pass = path.switches.first_pass_start && !extrapolate && p_first_pass.size() == m &&
                                         !p_start.isZero(0.0);
            if (confirmed(semismooth_newton, from_first_pass ? p_first_pass
                                             : extrapolate     ? Eigen::VectorXd(2.0 * last_p - previous_p)
                                                               : p_start))
                return true;
            // from rest: the homotopy from a covering start at the semismooth method's last
            // iterate (Switches::rest_path_violations, docs/decisions/041); where it fails after
            // the hand-over, the semismooth method goes on from that iterate
            if (path.switches.rest_path_violations > 0 && p_start.isZero(0.0) && p.size() == m) {
                const bool handed_over = path.handed_over;
                const Eigen::VectorXd p_newton = p;
                const bool ok = rest_transition(step, p, z, r);
                if (tr) path.observer->close_phase(phase_path);
                if (ok) return true;
                if (handed_over && confirmed(semismooth_newton, p_newton)) return true;
            }
        }
        // the smoothing method from the semismooth method's best iterate (measured on the
        // graduated 10-leaf spring, 10 x 100, 100 steps: 3.2 s instead of 10.2 s from the
        // start, docs/decisions/004-smoothing-newton.md), and if that or the passes after it fail, from the start
        if (tm == TransitionMethod::newton || tm == TransitionMethod::smoothing) {
            if (tm == TransitionMethod::newton && path.best_p.size() == m && confirmed(smoothing_newton, path.best_p))
                return true;
            if (!smoothed_from_start && confirmed(smoothing_newton, p_start)) return true;
        }
        passes_end.restore(p, z, path.modes);
        return false;
    }

    /// Step 1b, the homotopy (Switches::path_following, docs/decisions/040): from the last
    /// converged solve's data and modes to this step's (path_following), its modes confirmed
    /// by the passes. True when settled; otherwise p, z and the modes are those on entry (the
    /// passes' end), and the caller goes on as without it.
    bool path_transition(const detail::sparse::Step& step, Eigen::VectorXd& p, Eigen::VectorXd& z, SolveResult& r) {
        using namespace detail::sparse;
        if (path_d.size() != step.d.size() || path_b.size() != step.b.size()) return false;
        const TransitionStart passes_end(p, z, path.modes);
        if (follow_path(step, PathStart{path_b, path_d, path_n, path_t}, p, z, r)) return true;
        passes_end.restore(p, z, path.modes);
        return false;
    }

    /// path_following from `start` to this step's data, its end modes confirmed by the passes
    /// (a singular set of modes among them: not settled), the homotopy's statistics into the
    /// trace. True when settled.
    bool follow_path(const detail::sparse::Step& step, const detail::sparse::PathStart& start, Eigen::VectorXd& p,
                     Eigen::VectorXd& z, SolveResult& r) {
        using namespace detail::sparse;
        PathStats ps;
        bool settled = false;
        int confirm = 0;
        if (path_following(path, step, start, p, z, r, ps)) {
            const int it0 = r.iterations;
            try {
                settled = passes_from_modes(path, step, p, z, r);
            } catch (const SingularModes&) {
                path.solver.forget();  // the caller's next method, as without the homotopy
            }
            confirm = r.iterations - it0;
        }
        if (StepTrace* tr = path.observer ? path.observer->current : nullptr) {
            tr->path = ps;
            tr->path_confirmed = settled;
            tr->path_confirm_solves = confirm;
        }
        return settled;
    }

    /// Step 2a', from rest (Switches::rest_path_violations, docs/decisions/041): the homotopy
    /// from a covering start at p (the semismooth method's last iterate, z = K^-1 (b + G^T p)):
    /// the modes of the natural map's Jacobian there (the Newton method's next set) and their
    /// linear solution x1 (one solve), this step's data moved so that those modes hold at t = 0
    /// (covering_start), path_following to this step's data, its end modes confirmed by the
    /// passes. True when settled; otherwise p, z and the modes are where it stopped.
    bool rest_transition(const detail::sparse::Step& step, Eigen::VectorXd& p, Eigen::VectorXd& z,
                         SolveResult& r) {
        using namespace detail::sparse;
        if (path.laws.tau_rule != TauRule::current) return false;  // path_following's rule
        try {
            Eigen::VectorXd F;
            path.natural_residual(p, path.stiffness().Grow * z - step.d, F, true);
            ++r.iterations;
            r.factorizations += path.solve_modes(step, p, z);
            Eigen::VectorXd b0, d0;
            covering_start(path, step, p, z, b0, d0);
            const std::vector<signed char> n0 = path.modes.nmode, t0 = path.modes.tmode;
            return follow_path(step, PathStart{b0, d0, n0, t0}, p, z, r);
        } catch (const SingularModes&) {
            path.solver.forget();
        }
        return false;
    }

    /// Step 2b, the Tresca fixed point, then the coupled Coulomb problem from its modes; if
    /// that polish fails, the settled fixed point (Coulomb to within kAccept x tolerance) is
    /// taken and flagged, as in the dense solver.
    bool tresca_transition(const detail::sparse::Step& step, Eigen::VectorXd& p, Eigen::VectorXd& z, SolveResult& r) {
        using namespace detail::sparse;
        const bool settled = tresca_fixed_point(path, step, p, z, r);
        if (!settled) path.modes.init(path.laws, p, path.stiffness().positions(step.b, step.d, p, z));
        const Eigen::VectorXd p_tresca = p;
        if (passes_from_modes(path, step, p, z, r)) return true;
        if (!settled) return false;
        p = p_tresca;
        path.s = path.stiffness().positions(step.b, step.d, p, z);
        r.fell_back = true;
        return true;
    }

    /// The observer's record of one solve (trace.hpp): the start modes, the modes at the last
    /// two steps' (p, s) extrapolated, the modes the passes from the previous modes ended with.
    struct StepRecord {
        detail::sparse::StepTrace* tr = nullptr;  // the observer's current step (nullptr: none attached)
        std::vector<signed char> start_n, start_t, pred_n, pred_t, passes_n, passes_t;
    };

    /// A new step in the observer's record (where one is attached): the start modes and a prediction.
    void open_record(int m, StepRecord& rec) {
        using namespace detail::sparse;
        TransitionTrace* const trace = path.observer;
        if (!trace) return;
        rec.tr = &trace->new_step();
        rec.start_n = path.modes.nmode;
        rec.start_t = path.modes.tmode;
        trace->begin(rec.start_n, rec.start_t);
        if (previous_p.size() == m && last_p.size() == m && previous_s.size() == m && last_s.size() == m) {
            Eigen::VectorXd F;
            path.natural_residual(2.0 * last_p - previous_p, 2.0 * last_s - previous_s, F, true);
            rec.pred_n = path.modes.nmode;
            rec.pred_t = path.modes.tmode;
            path.modes.nmode = rec.start_n;
            path.modes.tmode = rec.start_t;
        }
        trace->open_phase();
    }

    /// Step 1, the active-set passes from the previous step's modes: most steps end here in one
    /// pass. Where a Newton method follows, SparsePathMethods::newton_passes of them (1: its start
    /// is not the passes' answer, and further passes switch every violated row and move away from
    /// the step's answer, docs/decisions/036 / 037), else max_active_set_iterations. From rest in
    /// the run's first solve (no converged solve before on this structure), none
    /// (SparsePathMethods::rest_first_pass, docs/decisions/046): the Newton methods start from p = 0,
    /// not from the pass's solution; z = K^-1 b and s as the passes would leave them.
    void first_passes(const detail::sparse::Step& step, const Eigen::VectorXd& p_start, bool newton_follows,
                      Eigen::VectorXd& p, Eigen::VectorXd& z, SolveResult& r) {
        const auto& sw = path.switches;
        const int m = static_cast<int>(step.d.size());
        const int max_passes =
            newton_follows && sw.newton_passes > 0 ? sw.newton_passes : path.options.max_active_set_iterations;
        const bool rest_pass =
            sw.rest_first_pass || !newton_follows || !p_start.isZero(0.0) || last_p.size() == static_cast<Eigen::Index>(m);
        if (!rest_pass && !sw.newton_first) {
            path.s = path.stiffness().positions(step.b, step.d, p, z);
        } else if (!sw.newton_first && max_passes > 4) {
            r.converged = path.passes(step, p, z, max_passes, r);
        } else if (!sw.newton_first) {
            // the first pass alone, then the rest: the same sequence (the passes' budget before
            // Murty's rule, 3 passes without fewer violations, cannot run out within 4)
            r.converged = path.passes(step, p, z, 1, r);
            if (!r.converged) {
                p_first_pass = p;
                if (max_passes > 1) r.converged = path.passes(step, p, z, max_passes - 1, r);
            }
        }
    }

    /// Steps 1 to 2b: the passes, then (where they do not settle) the transition methods in turn.
    /// Throws SingularModes.
    void settle(const detail::sparse::Step& step, const Eigen::VectorXd& p_start, Eigen::VectorXd& p,
                Eigen::VectorXd& z, SolveResult& r, StepRecord& rec) {
        using namespace detail::sparse;
        const auto& sw = path.switches;
        const int m = static_cast<int>(step.d.size());
        TransitionTrace* const trace = path.observer;
        const bool newton_follows = sw.transition != TransitionMethod::tresca && m >= newton_min_rows;
        first_passes(step, p_start, newton_follows, p, z, r);
        if (rec.tr) {
            trace->close_phase(phase_passes);
            rec.tr->pass_solves = r.iterations;
            rec.tr->passes_settled = r.converged;
            rec.passes_n = path.modes.nmode;
            rec.passes_t = path.modes.tmode;
        }
        // 1b. The homotopy from the last step's data and modes (SparsePathMethods::path_following),
        //     where a Newton method would follow (the same problems, the same confirmation)
        if (!r.converged && newton_follows && sw.path_following != 0 && !sw.newton_first) {
            r.converged = path_transition(step, p, z, r);
            if (rec.tr) trace->close_phase(phase_path);
        }
        // 2a. A transition the passes do not settle: the semismooth Newton method on the
        //     natural map from the previous step's forces, extrapolated (for the first
        //     step: the stepper's start), then the active-set passes from its modes
        //     (one pass, normally: they re-solve its last set of modes and find no violation,
        //     so the answer is the exact solver's linear solution of those modes). If it
        //     fails, the smoothing Newton method from its best iterate (then from the step's
        //     start), then the passes from its modes.
        if (!r.converged && sw.transition != TransitionMethod::tresca && (m >= newton_min_rows || sw.newton_first))
            r.converged = newton_transition(step, p_start, p, z, r);
        // 2b. Otherwise (or if it failed): the Tresca fixed point.
        if (!r.converged) {
            r.converged = tresca_transition(step, p, z, r);
            if (rec.tr) trace->close_phase(phase_tresca);
        }
    }

    /// Step 3, the last resort for problems small enough: the dense problem and the dense exact
    /// solver (Tresca fixed point, Gauss-Seidel). O(m^2) memory; reported. False (p back to
    /// p_start, the message and residual in r) where the problem is too large for it.
    bool dense_fallback(const SparseContactProblem& problem, const Eigen::VectorXd& p_start, bool singular,
                        Eigen::VectorXd& p, Eigen::VectorXd& z, SolveResult& r) {
        const int m = problem.size();
        const detail::sparse::SparseStiffness& st = path.stiffness();
        if (m > kDenseFallbackMaxRows) {
            p = p_start;
            r.message = std::string("sparse path: the active-set passes ") +
                        (singular ? "met a singular set of modes" : "and the Tresca fixed point did not settle") +
                        "; the dense fallback is not tried for " + std::to_string(m) + " > " +
                        std::to_string(kDenseFallbackMaxRows) + " contact rows";
            path.s = st.positions(problem.b, problem.d, p, z);
            r.residual_m = error_vector(path.laws, p, path.s).norm();
            return false;
        }
        const ContactProblem dense = problem.to_dense();
        SolveResult d = make_solver(path.options)->solve(dense, p);
        r.iterations += d.iterations;
        r.factorizations += d.factorizations;
        r.tresca_iterations += d.tresca_iterations;
        r.fell_back = true;
        r.converged = d.converged;
        if (!d.converged)
            r.message = std::string("sparse path: the active-set passes ") +
                        (singular ? "met a singular set of modes" : "did not settle") +
                        " and the dense fallback failed: " + d.message;
        path.s = st.positions(problem.b, problem.d, p, z);
        path.modes.init(path.laws, p, path.s);
        return true;
    }

    /// After a solve: its residuals checked against the tolerance, the homotopy's next start
    /// (the converged solve's data and modes), the accepted modes and the last answers kept.
    void conclude(const SparseContactProblem& problem, const Eigen::VectorXd& p, SolveResult& r) {
        r.updates = path.solver.updates();
        detail::residual_norms(path.laws, path.diag(), p, path.s, r.residual_m, r.natural_residual_m);
        if (r.converged && !(r.residual_m < path.options.tolerance_m)) {
            r.converged = false;
            r.message = "sparse path (active set) ended with ||v|| = " + format_value(r.residual_m) +
                        " m above the tolerance " + format_value(path.options.tolerance_m) + " m (natural-map residual " +
                        format_value(r.natural_residual_m) + " m)";
        }
        if (path.switches.path_following != 0) {  // the homotopy's next start
            if (r.converged) {
                path_b = problem.b;
                path_d = problem.d;
                path_n = path.modes.nmode;
                path_t = path.modes.tmode;
            } else {
                path_d.resize(0);
            }
        }
        if (r.converged) {
            path.solver.accept();  // the accepted modes: the base of the next step's updates
            previous_p = last_p;
            last_p = p;
            if (path.observer) {
                previous_s = last_s;
                last_s = path.s;
            }
        }
    }

    /// The observer's record of the solve closed: its counts, and the distances of the start,
    /// predicted, passes' and first Newton modes to the final ones.
    void close_record(const SolveResult& r, StepRecord& rec) {
        using namespace detail::sparse;
        StepTrace* const tr = rec.tr;
        if (!tr) return;
        TransitionTrace* const trace = path.observer;
        tr->solves = r.factorizations + r.updates;
        tr->factorizations = r.factorizations;
        for (const auto& c : path.laws.pairs) tr->pairs += c.row_n >= 0 || c.row_t >= 0;
        for (const int c : trace->changes) {
            tr->pairs_changed += c > 0;
            tr->max_changes_per_pair = std::max(tr->max_changes_per_pair, c);
        }
        if (r.converged) {
            const auto& fn = path.modes.nmode;
            const auto& ft = path.modes.tmode;
            TransitionTrace::distance(rec.start_n, rec.start_t, fn, ft, tr->start_n, tr->start_t);
            if (!rec.pred_n.empty()) TransitionTrace::distance(rec.pred_n, rec.pred_t, fn, ft, tr->pred_n, tr->pred_t);
            if (!rec.passes_n.empty())
                TransitionTrace::distance(rec.passes_n, rec.passes_t, fn, ft, tr->passes_n, tr->passes_t);
            if (!trace->first_n.empty())
                TransitionTrace::distance(trace->first_n, trace->first_t, fn, ft, tr->first_n, tr->first_t);
        }
        trace->first_n.clear();
        trace->current = nullptr;
    }
};

namespace {
/// Throws InputError naming `tuning.<field>` unless lo <= value <= hi.
void check_range(const char* field, int value, int lo, int hi, const char* allowed) {
    if (value < lo || value > hi)
        throw InputError(std::string("tuning.") + field, "value " + std::to_string(value) + " must be " + allowed);
}

/// The methods' integer fields (sparse_methods.hpp: each field's note says what its values mean).
void validate_methods(const SparsePathMethods& m) {
    constexpr int big = std::numeric_limits<int>::max();
    check_range("methods.fixed_pattern", m.fixed_pattern, 0, 4, "0, 1, 2, 3 or 4");
    check_range("methods.fixed_border_rows", m.fixed_border_rows, -1, big, ">= -1 (-1: max_border_rows alone)");
    check_range("methods.newton_passes", m.newton_passes, 0, big, ">= 0");
    check_range("methods.creep_limit", m.creep_limit, 0, big, ">= 0 (0: never)");
    check_range("methods.nonmonotone_memory", m.nonmonotone_memory, 0, big, ">= 0 (0: monotone)");
    check_range("methods.schur_fresh_max_rows", m.schur_fresh_max_rows, -1, big, ">= -1 (-1: no limit)");
    check_range("methods.path_following", m.path_following, 0, 1, "0 (off) or 1 (on)");
    check_range("methods.path_rebase_rows", m.path_rebase_rows, 0, big, ">= 0 (0: never)");
    check_range("methods.path_max_start_hits", m.path_max_start_hits, 0, big, ">= 0 (0: no limit)");
    check_range("methods.rest_path_violations", m.rest_path_violations, 0, big, ">= 0 (0: off)");
    check_range("methods.path_max_pair_switches", m.path_max_pair_switches, 0, big, ">= 0 (0: no limit)");
    check_range("methods.path_keep_base", m.path_keep_base, 0, big, ">= 0 (0: off)");
}
}  // namespace

SparseContactSolver::SparseContactSolver(const SolverOptions& options, const SparsePathTuning& tuning) {
    make_solver(options);  // validates the options
    validate_methods(tuning.methods);
    if (tuning.schur_max_rows < 0)
        throw InputError("tuning.schur_max_rows", "value " + std::to_string(tuning.schur_max_rows) + " must be >= 0");
    if (tuning.newton_min_rows < 0)
        throw InputError("tuning.newton_min_rows", "value " + std::to_string(tuning.newton_min_rows) + " must be >= 0");
    if (tuning.max_border_rows < 0)
        throw InputError("tuning.max_border_rows", "value " + std::to_string(tuning.max_border_rows) + " must be >= 0");
    if (tuning.primal_min_rows < 0)
        throw InputError("tuning.primal_min_rows", "value " + std::to_string(tuning.primal_min_rows) + " must be >= 0");
    if (options.kind != SolverKind::exact)
        throw InputError("solver.kind", std::string("value '") + to_string(options.kind) +
                                            "' is not available on the sparse contact path: it has the exact "
                                            "(active-set) solver only");
    impl_ = std::make_unique<Impl>(options, tuning);
}

SparseContactSolver::~SparseContactSolver() = default;

const Eigen::VectorXd& SparseContactSolver::relative_positions() const { return impl_->path.s; }
const Eigen::VectorXd& SparseContactSolver::compliance_diagonal() const { return impl_->path.diag(); }

SolveResult SparseContactSolver::solve(const SparseContactProblem& problem, Eigen::VectorXd& p, Eigen::VectorXd& z,
                                       bool structure_unchanged) {
    Impl& im = *impl_;
    if (problem.layer_compliance.size() > 0) {
        // The elastic layer: the same problem on the augmented stiffness (Impl::layer_structure).
        const int n = static_cast<int>(problem.K.rows());
        const bool have = im.layered.K.rows() > n && im.layered.G.rows() == problem.G.rows();
        if (!structure_unchanged || !have) {
            problem.validate();
            if (!im.layer_structure(problem)) {
                SparseContactProblem rigid = problem;  // every entry 0: rigid contact
                rigid.layer_compliance.resize(0);
                return solve(rigid, p, z, false);
            }
        }
        SparseContactProblem& lp = im.layered;
        if (problem.b.size() != n) problem.validate();
        lp.b.head(n) = problem.b;
        lp.d = problem.d;
        lp.pairs = problem.pairs;
        lp.tau_rule = problem.tau_rule;
        lp.tau_previous_n = problem.tau_previous_n;
        const SolveResult r = solve(lp, p, im.z_layered, structure_unchanged && have);
        z = im.z_layered.head(n);
        return r;
    }
    using namespace detail::sparse;
    SparsePath& path = im.path;
    const SparseStiffness& st = path.stiffness();
    const int m = problem.size();
    const int np = static_cast<int>(problem.pairs.size());
    const bool known = path.laws.q.size() == m && static_cast<int>(path.laws.pairs.size()) == np &&
                       st.K.rows() == problem.K.rows() && st.G.rows() == problem.G.rows() &&
                       st.G.cols() == problem.G.cols();
    if (!known || (!structure_unchanged && (!same_matrix(problem.K, st.K) || !same_matrix(problem.G, st.G) ||
                                            !same_laws(path.laws.pairs, problem.pairs))))
        im.reset_structure(problem);
    else if (problem.b.size() != problem.K.rows() || problem.d.size() != m)
        problem.validate();  // throws InputError naming the field
    path.laws.tau_rule = problem.tau_rule;
    path.laws.tau_previous_n = problem.tau_previous_n;
    if (static_cast<int>(path.modes.nmode.size()) != np) {
        if (p.size() != m) p = Eigen::VectorXd::Zero(m);
        path.modes.init(path.laws, p, st.positions(problem.b, problem.d, p, z));
    }
    SolveResult r;
    path.solver.reset_updates();
    ++path.solves_since_path;  // (the homotopy's kept base serves the path's step and the next)
    bool singular = false;
    const Eigen::VectorXd p_start = p;
    const Step step{problem.b, problem.d};
    Impl::StepRecord rec;  // the observer's record (SparsePathTuning::observer, trace.hpp)
    im.open_record(m, rec);
    im.p_first_pass.resize(0);
    try {
        im.settle(step, p_start, p, z, r, rec);
    } catch (const SingularModes&) {
        singular = true;  // a set of modes with dependent held rows: leave it to the dense solver
        path.solver.forget();
    }
    if (!r.converged && !im.dense_fallback(problem, p_start, singular, p, z, r)) return r;
    im.conclude(problem, p, r);
    im.close_record(r, rec);
    return r;
}

}  // namespace stackbeam
