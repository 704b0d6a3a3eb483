// The sparse contact path: the exact solver's active-set method on
//     K z = b + G^T p,  s = G z - d       (SparseContactProblem, contact.hpp)
// without ever forming the dense W = G K^-1 G^T.
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
//    solves of the rows new to the cache and a small dense LU (solve_held, factor_schur).
//    This is the usual situation of friction runs on identical leaves: most pairs open,
//    the clamps held.
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
//    passes, so its answer is the exact solver's. At 10 leaves x 100 elements it took the
//    friction run from 50-53 to 2.4 factorisations per step (BENCHMARKS.md); at 10 x 400
//    its first step still does not converge (BENCHMARKS.md: where it stalls).
//    Where the semismooth method stalls (60 iterations, or no decrease of ||F||): the
//    smoothing Newton method (smoothing_newton) from its best iterate: the natural map
//    with every max(0, .) replaced by (y + sqrt(y^2 + 4 e^2)) / 2, so ||F_eps||^2 is
//    differentiable and Armijo's backtracking always finds a step, and a component at its
//    kink enters the Jacobian half held, half free instead of flipping; e falls with the
//    residual. One sparse LU of the Jacobian's saddle-point system per iteration (its
//    ordering made once per run). Measured (BENCHMARKS.md): on a graduated 10-leaf
//    spring at 100 elements it settles the transitions that sent the semismooth method
//    to the Tresca fixed point (thousands of factorisations) in ~20 iterations; at 10
//    identical leaves x 400 elements it stalls too (a near-singular Jacobian from the
//    slip coupling), so that size still does not run with friction.
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
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "contact/active_set.hpp"
#include "contact/box_qp.hpp"
#include "contact/solvers.hpp"
#include "stackbeam/contact/contact.hpp"
#include "stackbeam/errors.hpp"

namespace stackbeam {

using SpMat = Eigen::SparseMatrix<double>;
using RowMat = Eigen::SparseMatrix<double, Eigen::RowMajor>;

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
    detail::validate_laws(pairs, size(), tau_rule, tau_previous_n);
}

ContactProblem SparseContactProblem::to_dense() const {
    Eigen::SimplicialLLT<SpMat> llt(K);
    if (llt.info() != Eigen::Success) throw InputError("problem.K", "is not positive definite");
    ContactProblem pr;
    const Eigen::MatrixXd X = llt.solve(Eigen::MatrixXd(G.transpose()));
    pr.W = G * X;
    pr.W = 0.5 * (pr.W + pr.W.transpose()).eval();
    pr.q = G * llt.solve(b) - d;
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

constexpr int kTrescaIterations = 100;  // as in the dense solver
constexpr int kBoxPasses = 50;          // block principal pivoting passes per box QP
// passes without fewer violations before the box QP turns to Murty's single switches:
// 8 halves the factorisations of friction steps on 10 leaves against 3 (measured:
// 18 -> 8 per step at 342 rows, 290 -> 150 at 1,782); the primal method still backs it up
constexpr int kBoxBudget = 8;
constexpr int kDenseFallbackMaxRows = 4000;  // the dense fallback: m^2 doubles (128 MB at 4000)
constexpr int kBudget = 3;          // as in the dense solver
// semismooth Newton (Impl::semismooth_newton): iteration limit, line-search grid (octaves of a),
// full steps taken although they raise the merit function
constexpr int kNewtonIterations = 60;
constexpr int kLineSearchOctaves = 12;
constexpr int kNewtonNonmonotone = 5;
// smoothing Newton (Impl::smoothing_newton): iteration limit, first smoothing as a fraction
// of the natural residual, the smoothing kept at most this fraction of the natural residual,
// Armijo's constant and the smallest step length tried
constexpr int kSmoothIterations = 80;
constexpr double kSmoothStart = 0.1;
constexpr double kSmoothTrack = 0.2;
constexpr double kArmijo = 1e-4;
constexpr int kSmoothHalvings = 40;
constexpr int kContinuationPasses = 6;        // active-set passes per continuation sub-step
constexpr double kContinuationMinStep = 1.0 / 256;  // smallest continuation sub-step (of the step's change)
constexpr int kSmoothStall = 15;  // iterations without a 10 % fall of the natural residual
// cached columns K^-1 g_i^T: at most this many doubles (80 MB)
constexpr double kColumnCacheDoubles = 1e7;
// interior-point method on the box QP (Impl::box_qp_ipm): iteration limit; proximal Sigma of
// rows without bounds and floor of every Sigma, as a fraction of W_ii (the Newton systems stay
// within ~1e8 of K's conditioning; s is recomputed exactly, so this only slows convergence)
constexpr int kIpmIterations = 100;
constexpr double kIpmRegularisation = 1e-8;
constexpr double kAccept = 1e-3;    // as in the dense solver: threshold kAccept x tolerance

/// diag(G K^-1 G^T) [m/N], the compliance of each contact row alone (it scales force
/// violations to metres). Each row g_i of G touches a few DOFs (two leaves at one
/// node), so W_ii = sum_{a,b} g_ia g_ib (K^-1)_ab needs a few entries of K^-1 only:
///  - The leaves are coupled in K only through the rigid body's DOFs ("hubs": w, and
///    the seat rotation on the full model), which tie the attachment node of every tied
///    leaf. With K = [A B; B^T C] (C: the hubs, at most kMaxHubs DOFs of degree above
///    kHubDegree), K^-1 = [A^-1 + X S^-1 X^T, -X S^-1; -S^-1 X^T, S^-1] with
///    X = A^-1 B and S = C - B^T X, so
///        W_ii = g_A^T A^-1 g_A + t^T S^-1 t,   t = X^T g_A - g_C.
///  - A^-1 is needed on pairs of DOFs within one cross-section of one leaf: taken from
///    the selected inverse of A (the entries of A^-1 on the pattern of its Cholesky
///    factor L, L L^T = P A P^T), by Takahashi's recurrence from the last column back,
///        Z_ij = (delta_ij / L_jj - sum_{k > j} Z_ik L_kj) / L_jj,  i in struct(L_:j) + {j},
///    which only reads entries of the pattern (a column's structure is a clique of the
///    filled graph); cost sum_j |L_:j|^2, about that of the factorisation. An entry
///    between different connected components of A (different leaves) is exactly 0.
///  - A row that needs an entry of A^-1 off the pattern within one component (not met
///    with the models here) is computed directly from K's factor as ||L_K^-1 P_K g_i||^2.
/// All of it is exact to round-off (test: sparse_compliance_diagonal_is_exact). Before,
/// the whole diagonal was m dense triangular solves: 0.35-0.65 s at 10 leaves x 400
/// elements, now a few milliseconds.
template <class LLT>
Eigen::VectorXd selected_compliance_diagonal(const SpMat& K, const SpMat& G, const LLT& k_llt) {
    using RowMat = Eigen::SparseMatrix<double, Eigen::RowMajor>;
    constexpr int kHubDegree = 12;  // a beam DOF couples to at most 9 (its node and the two neighbours)
    constexpr int kMaxHubs = 8;
    const int n = static_cast<int>(K.rows()), m = static_cast<int>(G.rows());
    std::vector<int> hubs;
    for (int j = 0; j < n; ++j)
        if (K.outerIndexPtr()[j + 1] - K.outerIndexPtr()[j] > kHubDegree) hubs.push_back(j);
    if (static_cast<int>(hubs.size()) > kMaxHubs || static_cast<int>(hubs.size()) >= n) hubs.clear();
    const int h = static_cast<int>(hubs.size()), na = n - h;
    std::vector<int> index(static_cast<std::size_t>(n));  // DOF -> index in A (>= 0) or -1 - index in C
    {
        int ia = 0, ic = 0;
        for (int j = 0; j < n; ++j) {
            const bool hub = std::binary_search(hubs.begin(), hubs.end(), j);
            index[static_cast<std::size_t>(j)] = hub ? -1 - ic++ : ia++;
        }
    }
    std::vector<Eigen::Triplet<double>> ta, tb;
    Eigen::MatrixXd C = Eigen::MatrixXd::Zero(h, h);
    for (int j = 0; j < n; ++j)
        for (SpMat::InnerIterator it(K, j); it; ++it) {
            const int r = index[static_cast<std::size_t>(it.row())], c = index[static_cast<std::size_t>(j)];
            if (r >= 0 && c >= 0) ta.emplace_back(r, c, it.value());
            else if (r >= 0) tb.emplace_back(r, -1 - c, it.value());
            else if (c < 0) C(-1 - r, -1 - c) = it.value();
        }
    SpMat A(na, na), B(na, h);
    A.setFromTriplets(ta.begin(), ta.end());
    B.setFromTriplets(tb.begin(), tb.end());
    Eigen::SimplicialLLT<SpMat, Eigen::Lower, Eigen::AMDOrdering<int>> llt(A);
    if (llt.info() != Eigen::Success) throw InputError("problem.K", "is not positive definite");
    const Eigen::MatrixXd X = h > 0 ? Eigen::MatrixXd(llt.solve(Eigen::MatrixXd(B))) : Eigen::MatrixXd(na, 0);
    const Eigen::LLT<Eigen::MatrixXd> s_llt(C - B.transpose() * X);
    // selected inverse of A
    const SpMat& L = llt.matrixL().nestedExpression();  // column-major, diagonal first, rows ascending
    const int* Lp = L.outerIndexPtr();
    const int* Li = L.innerIndexPtr();
    const double* Lx = L.valuePtr();
    std::vector<double> Z(static_cast<std::size_t>(L.nonZeros()), 0.0);
    auto find = [&](int i, int k) -> long {  // position of (i, k), i != k, in the pattern, or -1
        const int c = std::min(i, k), r = std::max(i, k);
        const int* e = Li + Lp[c + 1];
        const int* f = std::lower_bound(Li + Lp[c] + 1, e, r);
        return (f != e && *f == r) ? static_cast<long>(f - Li) : -1L;
    };
    auto at = [&](long pos) -> double& { return Z[static_cast<std::size_t>(pos)]; };
    for (int j = na - 1; j >= 0; --j) {
        const int p0 = Lp[j], p1 = Lp[j + 1];
        const double ljj = Lx[p0];
        for (int pi = p0 + 1; pi < p1; ++pi) {
            const int i = Li[pi];
            double sum = 0.0;
            for (int pk = p0 + 1; pk < p1; ++pk) {
                const int k = Li[pk];
                sum += (k == i ? at(Lp[i]) : at(find(i, k))) * Lx[pk];
            }
            at(pi) = -sum / ljj;
        }
        double sum = 0.0;
        for (int pk = p0 + 1; pk < p1; ++pk) sum += at(pk) * Lx[pk];
        at(p0) = (1.0 / ljj - sum) / ljj;
    }
    // connected components of A's graph (union-find, path halving)
    std::vector<int> parent(static_cast<std::size_t>(na));
    for (int i = 0; i < na; ++i) parent[static_cast<std::size_t>(i)] = i;
    auto root = [&](int i) {
        while (parent[static_cast<std::size_t>(i)] != i) {
            parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
            i = parent[static_cast<std::size_t>(i)];
        }
        return i;
    };
    for (int j = 0; j < na; ++j)
        for (SpMat::InnerIterator it(A, j); it; ++it) {
            const int a = root(static_cast<int>(it.row())), b = root(j);
            if (a != b) parent[static_cast<std::size_t>(a)] = b;
        }
    const auto& perm = llt.permutationP().indices();
    const RowMat Grow = G;  // the rows of G
    Eigen::VectorXd diag(m), t(h);
    std::vector<int> direct;
    for (int r = 0; r < m; ++r) {
        double w = 0.0;
        bool ok = true;
        t.setZero();
        for (RowMat::InnerIterator a(Grow, r); a && ok; ++a) {
            const int ia = index[static_cast<std::size_t>(a.col())];
            if (ia < 0) {
                t[-1 - ia] -= a.value();
                continue;
            }
            t += a.value() * X.row(ia).transpose();
            for (RowMat::InnerIterator b(Grow, r); b; ++b) {
                const int ib = index[static_cast<std::size_t>(b.col())];
                if (ib < 0) continue;
                const int pa = perm[ia], pb = perm[ib];
                double z = 0.0;
                if (pa == pb) {
                    z = at(Lp[pa]);
                } else if (root(ia) == root(ib)) {
                    const long f = find(pa, pb);
                    if (f < 0) {
                        ok = false;
                        break;
                    }
                    z = at(f);
                }
                w += a.value() * b.value() * z;
            }
        }
        if (!ok) {
            direct.push_back(r);
            continue;
        }
        diag[r] = h > 0 ? w + t.dot(s_llt.solve(t)) : w;
    }
    // rows off the pattern: column norms of L_K^-1 P_K g_i, in blocks of columns
    if (!direct.empty()) {
        const SpMat Gt = SpMat(G.transpose());
        const auto& kperm = k_llt.permutationP().indices();
        constexpr int kBlock = 64;
        for (std::size_t j0 = 0; j0 < direct.size(); j0 += kBlock) {
            const int nb = static_cast<int>(std::min<std::size_t>(kBlock, direct.size() - j0));
            Eigen::MatrixXd Y = Eigen::MatrixXd::Zero(n, nb);
            for (int c = 0; c < nb; ++c)
                for (SpMat::InnerIterator it(Gt, direct[j0 + static_cast<std::size_t>(c)]); it; ++it)
                    Y(kperm[it.row()], c) = it.value();
            k_llt.matrixL().solveInPlace(Y);
            for (int c = 0; c < nb; ++c) diag[direct[j0 + static_cast<std::size_t>(c)]] = Y.col(c).squaredNorm();
        }
    }
    return diag;
}

struct SingularModes {};            // a set of modes whose saddle-point system is singular

bool same_laws(const std::vector<ContactPair>& a, const std::vector<ContactPair>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t k = 0; k < a.size(); ++k)
        if (a[k].kind != b[k].kind || a[k].friction_coefficient != b[k].friction_coefficient ||
            a[k].preload_n != b[k].preload_n || a[k].row_n != b[k].row_n || a[k].row_t != b[k].row_t)
            return false;
    return true;
}
}  // namespace

struct SparseContactSolver::Impl {
    SolverOptions options;
    SparsePathTuning tuning;
    int updates = 0;                     // bordered solves (low-rank updates) in the current solve()
    // structure of the last problem
    SpMat K, G;
    Eigen::SimplicialLLT<SpMat, Eigen::Lower, Eigen::AMDOrdering<int>> k_llt;
    Eigen::VectorXd diag;                // diagonal of W
    double g_norm_inf = 0.0;             // max row sum of |G|
    ContactProblem laws;                 // pairs and tau rule; W empty, q zero (sizes only)
    detail::ModeSet modes;
    detail::ModeLinearization lin;
    // the modes `lin` was made from (solve_modes keeps it while they stay)
    bool lin_ok = false;
    std::vector<signed char> lin_nmode, lin_tmode, lin_key;
    TauRule lin_tau_rule = TauRule::current;
    // factorisation of the current modes
    std::vector<signed char> lu_key;
    Eigen::SparseLU<SpMat, Eigen::COLAMDOrdering<int>> lu;
    bool lu_ok = false;
    std::vector<int> pos;                // row -> index in lin.S, or -1
    Eigen::VectorXd dz;                  // column scaling of z: diag(K)^-1/2
    SpMat Gt_scaled;                     // Dz G^T: column r is contact row r, scaled
    Eigen::VectorXd row_scale;           // scaling of the held rows (1/||G_i Dz||)
    SpMat A;                             // the scaled saddle-point matrix of the current modes
    // cached back-solves of the current factorisation
    int unit_dof = -1;                   // (zu, pu) are for a unit load on this DOF
    Eigen::VectorXd const_e, const_dS;   // (zc, pc) are for these e, d_S
    bool const_ok = false;
    Eigen::VectorXd s, x, rhs;
    // the affine map of the load for the current factorisation: (z, p_S) = (zc, pc) + b_w (zu, pu)
    Eigen::VectorXd zc, pc, zu, pu;
    // Schur-complement way (solve_held): the held rows' dense LU and the cached columns K^-1 g_i^T
    bool lu_schur = false;
    // low-rank updates of the sparse LU (try_border): the base's held set and the border
    bool base_valid = false;
    std::vector<int> base_S, base_pos;
    bool border_active = false;
    std::vector<int> border_rows;        // the freed base rows first (border_nr of them), then the added rows
    int border_nr = 0;
    std::vector<Eigen::VectorXd> bcol;   // per contact row: A0^-1 U_j, or empty
    std::size_t bcol_count = 0;          // non-empty entries of bcol
    int key_uses = 0;                    // solves with the current factorisation
    Eigen::MatrixXd Mschur;              // the Schur complement (for refinement)
    Eigen::PartialPivLU<Eigen::MatrixXd> dlu;
    std::vector<Eigen::VectorXd> xcol;  // per contact row; empty = not computed
    std::size_t xcol_count = 0;
    SpMat Gt;                            // G^T (columns: contact rows)
    RowMat Grow;                         // G, row-major
    // smoothing Newton (smoothing_newton): the Jacobian's saddle-point matrix and its LU
    SpMat Js;
    Eigen::SparseLU<SpMat, Eigen::COLAMDOrdering<int>> js_lu;
    bool js_analysed = false;            // js_lu's ordering is for the current (K, G)
    Eigen::VectorXd row_h;               // ||G_i Dz|| per contact row (1 for an empty row): the row scaling
                                         // of the saddle-point systems (solve_held, try_border, smoothing)
    Eigen::VectorXd best_p;              // semismooth_newton's iterate of smallest ||F||
    // the solutions of the last two solves (the semismooth Newton method's start is their
    // linear extrapolation when the caller continues that sequence)
    Eigen::VectorXd previous_p, last_p;
    // interior-point method on the box QP (box_qp_ipm): LDL^T of K + G^T Sigma^-1 G, its
    // ordering made once per (K, G)
    Eigen::SimplicialLDLT<SpMat, Eigen::Lower, Eigen::AMDOrdering<int>> ipm_ldlt;
    bool ipm_analysed = false;
    Eigen::Index ipm_nnz = 0;

    void reset_structure(const SparseContactProblem& pr) {
        pr.validate();
        K = pr.K;
        G = pr.G;
        K.makeCompressed();
        G.makeCompressed();
        k_llt.compute(K);
        if (k_llt.info() != Eigen::Success) throw InputError("problem.K", "is not positive definite");
        ipm_analysed = false;
        const int m = pr.size();
        diag = selected_compliance_diagonal(K, G, k_llt);
        g_norm_inf = 0.0;
        const SpMat absG = G.cwiseAbs();
        const Eigen::VectorXd rows = absG * Eigen::VectorXd::Ones(G.cols());
        if (m > 0) g_norm_inf = rows.maxCoeff();
        dz = K.diagonal().cwiseSqrt().cwiseInverse();
        Gt_scaled = dz.asDiagonal() * SpMat(G.transpose());
        Gt_scaled.makeCompressed();
        laws.W.resize(0, 0);
        laws.q = Eigen::VectorXd::Zero(m);
        laws.pairs = pr.pairs;
        lu_key.clear();
        lu_ok = false;
        const_ok = false;
        unit_dof = -1;
        modes.nmode.clear();
        lin_ok = false;
        Gt = SpMat(G.transpose());
        Grow = G;
        xcol.assign(static_cast<std::size_t>(m), Eigen::VectorXd());
        bcol.assign(static_cast<std::size_t>(m), Eigen::VectorXd());
        bcol_count = 0;
        base_valid = false;
        border_active = false;
        xcol_count = 0;
        js_analysed = false;
        previous_p.resize(0);
        last_p.resize(0);
        row_h.resize(m);
        for (int i = 0; i < m; ++i) {
            const double h = Gt_scaled.col(i).norm();
            row_h[i] = h > 0.0 ? h : 1.0;
        }
    }

    /// Appends Dz K Dz (the stiffness block of both saddle-point systems, scaled by
    /// Dz = diag(K)^-1/2) to t.
    void append_scaled_K(std::vector<Eigen::Triplet<double>>& t) const {
        for (int j = 0; j < K.outerSize(); ++j)
            for (SpMat::InnerIterator it(K, j); it; ++it)
                t.emplace_back(it.row(), it.col(), it.value() * dz[it.row()] * dz[it.col()]);
    }

    /// s = G z - d for z = K^-1 (b + G^T p).
    Eigen::VectorXd positions(const Eigen::VectorXd& b, const Eigen::VectorXd& d, const Eigen::VectorXd& p,
                              Eigen::VectorXd& z) {
        z = k_llt.solve(b + Gt * p);
        return Grow * z - d;
    }
    Eigen::VectorXd positions_of(const SparseContactProblem& pr, const Eigen::VectorXd& p, Eigen::VectorXd& z) {
        return positions(pr.b, pr.d, p, z);
    }

    /// Solves the linear problem of the current modes for load b and offsets d into p and
    /// z; returns 1 if it factorised. The saddle-point system is scaled symmetrically
    /// (z = Dz y with Dz = diag(K)^-1/2, held row i by 1/||G_i Dz||): K mixes axial
    /// (EA/L ~ 1e8), bending (EI/L^3 ~ 1e7) and rotational (EI/L ~ 1e3) entries and G is
    /// O(1), and unscaled the LU's pivoting would lose digits. Each cached solve gets one
    /// step of iterative refinement, so held rows come out at s = 0 to round-off.
    int solve_modes(const Eigen::VectorXd& b, const Eigen::VectorXd& d, Eigen::VectorXd& p, Eigen::VectorXd& z) {
        // the linearisation depends on the modes and the tau rule (and, with the previous
        // step's rule, on tau_previous_n): kept while they stay (a step whose modes stay
        // makes none)
        const bool same = lin_ok && laws.tau_rule == TauRule::current && lin_tau_rule == laws.tau_rule &&
                          lin_nmode == modes.nmode && lin_tmode == modes.tmode;
        if (!same) {
            modes.linearize(laws, lin);
            lin_key = modes.key();
            lin_key.push_back(static_cast<signed char>(laws.tau_rule));  // the slip coupling depends on it
            lin_nmode = modes.nmode;
            lin_tmode = modes.tmode;
            lin_tau_rule = laws.tau_rule;
            lin_ok = true;
        }
        std::vector<signed char> key = lin_key == lu_key ? std::vector<signed char>() : lin_key;
        const int f = solve_held(lin, key, b, d, p, z, lin_key == lu_key);
        modes.put_slip_forces(laws, p);  // p_t = e_t + D p_n, written with the friction-limit formula
        return f;
    }

    /// The linear problem of `lin` (held rows S with s = 0, fixed forces e, slip coupling),
    /// factorised unless `key` names the current factorisation. Two ways, by the number of
    /// held rows:
    ///  - up to tuning.schur_max_rows: the Schur complement on the held rows, M p_S = d_S - G_S z0,
    ///    M = G_S K^-1 (G_S^T + G_slip^T D) (dense, ms x ms, LU with partial pivoting, as the
    ///    dense solver's W_SS), z = z0 + K^-1 G^T (E p_S), z0 = K^-1 (b + G^T e). K is
    ///    factorised once per run (k_llt) and the columns K^-1 g_i^T are cached per row, so
    ///    a change of the held set costs the solves of the rows new to the cache and a small
    ///    dense LU, not a sparse factorisation of the whole saddle-point system. This is
    ///    the friction case's usual situation: most pairs of identical leaves open, the
    ///    clamps held (tens of rows out of thousands).
    ///  - more held rows (bonded, frictionless, the first passes of a large transition):
    ///    the sparse saddle-point LU below.
    /// Both cache the affine map of the load: (z, p_S) = (zc, pc) + b_w (zu, pu).
    int solve_held(const detail::ModeLinearization& lin, std::vector<signed char>& key, const Eigen::VectorXd& b,
                   const Eigen::VectorXd& d, Eigen::VectorXd& p, Eigen::VectorXd& z, bool key_is_current = false) {
        const int n = static_cast<int>(K.rows()), m = static_cast<int>(d.size());
        const auto& S = lin.S;
        const int ms = static_cast<int>(S.size());
        pos.assign(m, -1);
        for (int i = 0; i < ms; ++i) pos[S[i]] = i;
        int factorised = 0;
        if (!key_is_current && key != lu_key && try_border(lin)) {
            ++updates;
            lu_key = std::move(key);
            key_uses = 0;
            const_ok = false;
            unit_dof = -1;
        } else if (!key_is_current && key != lu_key) {
            border_active = false;
            lu_schur = ms <= tuning.schur_max_rows;
            if (lu_schur) {
                factor_schur(lin);
            } else {
                row_scale.resize(ms);
                for (int i = 0; i < ms; ++i) row_scale[i] = 1.0 / row_h[S[i]];
                // [Dz K Dz, -Dz (G_S^T + G_slip^T D) R; R G_S Dz, 0]
                std::vector<Eigen::Triplet<double>> t;
                t.reserve(static_cast<std::size_t>(K.nonZeros() + 4 * G.nonZeros()));
                append_scaled_K(t);
                for (int i = 0; i < ms; ++i)
                    for (SpMat::InnerIterator it(Gt_scaled, S[i]); it; ++it) {
                        t.emplace_back(it.row(), n + i, -it.value() * row_scale[i]);
                        t.emplace_back(n + i, it.row(), it.value() * row_scale[i]);
                    }
                for (std::size_t a = 0; a < lin.coupled.size(); ++a) {
                    const int col = pos[lin.coupled[a].second];
                    if (col < 0) continue;  // the normal row is not held: its force is fixed (e)
                    for (SpMat::InnerIterator it(Gt_scaled, lin.coupled[a].first); it; ++it)
                        t.emplace_back(it.row(), n + col, -lin.coef[a] * it.value() * row_scale[col]);
                }
                A.resize(n + ms, n + ms);
                A.setFromTriplets(t.begin(), t.end());
                A.makeCompressed();
                lu.compute(A);
                lu_ok = lu.info() == Eigen::Success;
                base_valid = lu_ok && lin.coupled.empty();
                base_S = S;
                base_pos = pos;
                for (auto& c : bcol) c.resize(0);
                bcol_count = 0;
            }
            lu_key = std::move(key);
            key_uses = 0;
            const_ok = false;
            unit_dof = -1;
            factorised = 1;
        }
        if (!lu_ok) throw SingularModes{};
        Eigen::VectorXd dS(ms);
        for (int i = 0; i < ms; ++i) dS[i] = d[S[i]];
        Eigen::VectorXd pS;
        if (border_active) {
            border_solve(lin, b, d, p, z);
            return factorised;
        }
        if (++key_uses == 1) {
            // first use of a factorisation (most active-set passes use it once): one solve
            // with the whole load; the affine caches are made if it is used again
            const Eigen::VectorXd f = b + G.transpose() * lin.e;
            if (lu_schur) {
                schur_solve(lin, k_llt.solve(f), dS, pS, z);
            } else {
                rhs.resize(n + ms);
                rhs.head(n) = dz.cwiseProduct(f);
                rhs.tail(ms) = row_scale.cwiseProduct(dS);
                x = refined_solve(rhs);
                z = dz.cwiseProduct(x.head(n));
                pS = row_scale.cwiseProduct(x.tail(ms));
            }
            p = lin.e;
            for (int i = 0; i < ms; ++i) p[S[i]] = pS[i];
            for (std::size_t a = 0; a < lin.coupled.size(); ++a)
                p[lin.coupled[a].first] += lin.coef[a] * p[lin.coupled[a].second];
            return factorised;
        }
        if (!const_ok || const_e != lin.e || const_dS != dS) {
            if (lu_schur) {
                schur_solve(lin, k_llt.solve(G.transpose() * lin.e), dS, pc, zc);
            } else {  // right-hand side [Dz G^T e; R d_S]
                rhs.resize(n + ms);
                rhs.head(n) = dz.cwiseProduct(G.transpose() * lin.e);
                rhs.tail(ms) = row_scale.cwiseProduct(dS);
                x = refined_solve(rhs);
                zc = dz.cwiseProduct(x.head(n));
                pc = row_scale.cwiseProduct(x.tail(ms));
            }
            const_e = lin.e;
            const_dS = dS;
            const_ok = true;
        }
        // b: one nonzero entry (the closed-form stepper's load on the rigid body) is a
        // multiple of a cached unit solve; anything else is solved directly.
        int nz = -1, count = 0;
        for (int i = 0; i < n; ++i)
            if (b[i] != 0.0) {
                nz = i;
                ++count;
            }
        if (count == 0) {
            z = zc;
            pS = pc;
        } else if (count == 1) {
            if (unit_dof != nz) {
                load_solve(lin, Eigen::VectorXd::Unit(n, nz), pu, zu);
                unit_dof = nz;
            }
            z = zc + b[nz] * zu;
            pS = pc + b[nz] * pu;
        } else {
            Eigen::VectorXd pb, zb;
            load_solve(lin, b, pb, zb);
            z = zc + zb;
            pS = pc + pb;
        }
        p = lin.e;
        for (int i = 0; i < ms; ++i) p[S[i]] = pS[i];
        for (std::size_t a = 0; a < lin.coupled.size(); ++a)
            p[lin.coupled[a].first] += lin.coef[a] * p[lin.coupled[a].second];
        return factorised;
    }

    /// Low-rank updates of the sparse saddle-point LU (the "base", held set S0, no slip
    /// coupling) for a held set S near S0, without refactorising: the system of S is the
    /// base system bordered by one row and column per changed row,
    ///     [A0 U; W^T 0] [x; y] = [f; g],
    ///  - a row of S0 no longer held (its force fixed at e_i): U = the unit column of its
    ///    multiplier's equation (y_i is the slack that frees that equation), W^T x picks
    ///    its force unknown, g = e_i (scaled);
    ///  - a held row not in S0: U = [-g_a Dz s_a; 0], W^T = [s_a g_a Dz, 0], g = s_a d_a,
    ///    y its force (scaled by s_a = 1/||g_a Dz||).
    /// With Z = A0^-1 U (one base solve per changed row, cached while the base stays) the
    /// capacitance matrix C = -W^T Z (k x k, dense LU) gives y = C^-1 (g - W^T A0^-1 f)
    /// and x = A0^-1 f - Z y; one step of iterative refinement on the whole bordered
    /// system follows. This is what the box QP's primal active-set method needs: it
    /// changes one row per iteration (hundreds of iterations per box QP on 10 leaves x 400
    /// elements, each a 0.15-0.5 s sparse LU before). The base is refactorised when more
    /// than tuning.max_border_rows rows differ.
    bool try_border(const detail::ModeLinearization& lin) {
        const auto& S = lin.S;
        if (tuning.max_border_rows == 0 || !base_valid || !lin.coupled.empty() ||
            static_cast<int>(S.size()) <= tuning.schur_max_rows)
            return false;
        std::vector<int> rows;
        for (int i : base_S)
            if (pos[i] < 0) rows.push_back(i);
        const int nr = static_cast<int>(rows.size());
        if (nr > tuning.max_border_rows) return false;
        for (int i : S)
            if (base_pos[i] < 0) rows.push_back(i);
        if (static_cast<int>(rows.size()) > tuning.max_border_rows) return false;
        border_rows = std::move(rows);
        border_nr = nr;
        border_active = true;
        lu_schur = false;
        lu_ok = true;
        return true;
    }

    /// Bordered solve of the current held set (see try_border) for load b and offsets d.
    void border_solve(const detail::ModeLinearization& lin, const Eigen::VectorXd& b, const Eigen::VectorXd& d,
                      Eigen::VectorXd& p, Eigen::VectorXd& z) {
        const int n = static_cast<int>(K.rows());
        const int ms0 = static_cast<int>(base_S.size());
        const int k = static_cast<int>(border_rows.size());
        auto scale_of = [&](int a) { return 1.0 / row_h[a]; };
        // U y added to v
        auto add_U = [&](const Eigen::VectorXd& y, Eigen::VectorXd& v) {
            for (int j = 0; j < k; ++j) {
                const int i = border_rows[static_cast<std::size_t>(j)];
                if (j < border_nr) v[n + base_pos[i]] += y[j];
                else v.head(n) -= (scale_of(i) * y[j]) * Gt_scaled.col(i);
            }
        };
        auto apply_Wt = [&](const Eigen::VectorXd& v) {
            Eigen::VectorXd out(k);
            for (int j = 0; j < k; ++j) {
                const int i = border_rows[static_cast<std::size_t>(j)];
                out[j] = j < border_nr ? v[n + base_pos[i]] : scale_of(i) * Gt_scaled.col(i).dot(v.head(n));
            }
            return out;
        };
        // columns A0^-1 U_j (cached per row while the base stays; at most 4 x max_border_rows
        // of them, (n + ms0) doubles each: the cache is dropped past that)
        if (bcol_count > 4 * static_cast<std::size_t>(tuning.max_border_rows)) {
            for (auto& c : bcol) c.resize(0);
            bcol_count = 0;
        }
        Eigen::MatrixXd C(k, k);
        for (int j = 0; j < k; ++j) {
            const int i = border_rows[static_cast<std::size_t>(j)];
            Eigen::VectorXd& col = bcol[static_cast<std::size_t>(i)];
            if (col.size() == 0) {
                Eigen::VectorXd u = Eigen::VectorXd::Zero(n + ms0);
                if (j < border_nr) u[n + base_pos[i]] = 1.0;
                else u.head(n) = -scale_of(i) * Gt_scaled.col(i);
                col = refined_solve(u);
                ++bcol_count;
            }
            C.col(j) = -apply_Wt(col);
        }
        const Eigen::PartialPivLU<Eigen::MatrixXd> clu(C);
        // right-hand side: forces of the freed base rows are unknowns held by the border
        Eigen::VectorXd ep = lin.e;
        for (int j = 0; j < border_nr; ++j) ep[border_rows[static_cast<std::size_t>(j)]] = 0.0;
        Eigen::VectorXd f(n + ms0), g(k);
        f.head(n) = dz.cwiseProduct(b + G.transpose() * ep);
        for (int i = 0; i < ms0; ++i) f[n + i] = row_scale[i] * d[base_S[static_cast<std::size_t>(i)]];
        for (int j = 0; j < k; ++j) {
            const int i = border_rows[static_cast<std::size_t>(j)];
            g[j] = j < border_nr ? lin.e[i] / row_scale[base_pos[i]] : scale_of(i) * d[i];
        }
        auto solve_bordered = [&](const Eigen::VectorXd& ff, const Eigen::VectorXd& gg, Eigen::VectorXd& xx,
                                  Eigen::VectorXd& yy) {
            const Eigen::VectorXd h = refined_solve(ff);
            yy = k > 0 ? Eigen::VectorXd(clu.solve(gg - apply_Wt(h))) : Eigen::VectorXd();
            xx = h;
            for (int j = 0; j < k; ++j) xx -= yy[j] * bcol[static_cast<std::size_t>(border_rows[static_cast<std::size_t>(j)])];
        };
        Eigen::VectorXd xx, yy, dx, dy;
        solve_bordered(f, g, xx, yy);
        {  // one step of iterative refinement on the bordered system
            Eigen::VectorXd rf = f - A * xx;
            Eigen::VectorXd uy = Eigen::VectorXd::Zero(n + ms0);
            add_U(yy, uy);
            rf -= uy;
            const Eigen::VectorXd rg = g - apply_Wt(xx);
            solve_bordered(rf, rg, dx, dy);
            xx += dx;
            yy += dy;
        }
        z = dz.cwiseProduct(xx.head(n));
        p = lin.e;
        for (int i = 0; i < ms0; ++i) {
            const int r = base_S[static_cast<std::size_t>(i)];
            if (pos[r] >= 0) p[r] = row_scale[i] * xx[n + i];
        }
        for (int j = border_nr; j < k; ++j) {
            const int i = border_rows[static_cast<std::size_t>(j)];
            p[i] = scale_of(i) * yy[j];
        }
    }

    /// (p_S, z) for load `f` alone (e = 0, d_S = 0) with the current factorisation.
    void load_solve(const detail::ModeLinearization& lin, const Eigen::VectorXd& f, Eigen::VectorXd& pS,
                    Eigen::VectorXd& zf) {
        const int n = static_cast<int>(K.rows()), ms = static_cast<int>(lin.S.size());
        if (lu_schur) {
            schur_solve(lin, k_llt.solve(f), Eigen::VectorXd::Zero(ms), pS, zf);
        } else {
            rhs.setZero(n + ms);
            rhs.head(n) = dz.cwiseProduct(f);
            x = refined_solve(rhs);
            zf = dz.cwiseProduct(x.head(n));
            pS = row_scale.cwiseProduct(x.tail(ms));
        }
    }

    /// Column K^-1 g_i^T of contact row i [m/N per unit force], cached (solved in blocks
    /// for the rows in `rows` not cached yet; the cache is dropped when it would exceed
    /// kColumnCacheDoubles).
    void ensure_columns(const std::vector<int>& rows) {
        const int n = static_cast<int>(K.rows());
        std::vector<int> missing;
        for (int r : rows)
            if (xcol[static_cast<std::size_t>(r)].size() == 0) missing.push_back(r);
        if (missing.empty()) return;
        if (static_cast<double>(xcol_count + missing.size()) * n > kColumnCacheDoubles) {
            for (auto& c : xcol) c.resize(0);
            xcol_count = 0;
            missing.clear();
            for (int r : rows) missing.push_back(r);
        }
        constexpr int kBlock = 32;
        Eigen::MatrixXd Y;
        for (std::size_t j0 = 0; j0 < missing.size(); j0 += kBlock) {
            const int nb = static_cast<int>(std::min<std::size_t>(kBlock, missing.size() - j0));
            Y.setZero(n, nb);
            for (int c = 0; c < nb; ++c)
                for (SpMat::InnerIterator it(Gt, missing[j0 + static_cast<std::size_t>(c)]); it; ++it)
                    Y(it.row(), c) = it.value();
            Y = k_llt.solve(Y).eval();
            for (int c = 0; c < nb; ++c) {
                xcol[static_cast<std::size_t>(missing[j0 + static_cast<std::size_t>(c)])] = Y.col(c);
                ++xcol_count;
            }
        }
    }

    /// g_r . v for a contact row r and a vector v of n entries.
    double row_dot(int r, const Eigen::VectorXd& v) const {
        double sum = 0.0;
        for (RowMat::InnerIterator it(Grow, r); it; ++it) sum += it.value() * v[it.col()];
        return sum;
    }

    /// The Schur complement M = G_S K^-1 (G_S^T + G_slip^T D) of the held rows, LU-factorised.
    void factor_schur(const detail::ModeLinearization& lin) {
        const auto& S = lin.S;
        const int ms = static_cast<int>(S.size());
        std::vector<int> rows(S);
        for (std::size_t a = 0; a < lin.coupled.size(); ++a)
            if (pos[lin.coupled[a].second] >= 0) rows.push_back(lin.coupled[a].first);
        ensure_columns(rows);
        Eigen::MatrixXd M(ms, ms);
        for (int c = 0; c < ms; ++c) {
            const Eigen::VectorXd& xc = xcol[static_cast<std::size_t>(S[c])];
            for (int r = 0; r < ms; ++r) M(r, c) = row_dot(S[r], xc);
        }
        for (std::size_t a = 0; a < lin.coupled.size(); ++a) {
            const int c = pos[lin.coupled[a].second];
            if (c < 0) continue;
            const Eigen::VectorXd& xt = xcol[static_cast<std::size_t>(lin.coupled[a].first)];
            for (int r = 0; r < ms; ++r) M(r, c) += lin.coef[a] * row_dot(S[r], xt);
        }
        dlu.compute(M);
        // a singular set of modes (dependent held rows) is left to the caller, as with the sparse LU
        lu_ok = ms == 0 || (M.allFinite() && dlu.rcond() > 1e-14);
        Mschur = std::move(M);
    }

    /// Held-row solve with the Schur complement: p_S from M p_S = target - G_S z0 (one
    /// step of iterative refinement with M, as the sparse LU's solves get) and
    /// z = z0 + sum_S (p_S,c K^-1 g_c^T + coef p_S,c K^-1 g_t^T).
    void schur_solve(const detail::ModeLinearization& lin, const Eigen::VectorXd& z0, const Eigen::VectorXd& target,
                     Eigen::VectorXd& pS, Eigen::VectorXd& zout) {
        const auto& S = lin.S;
        const int ms = static_cast<int>(S.size());
        zout = z0;
        pS.setZero(ms);
        if (ms == 0) return;
        Eigen::VectorXd res(ms);
        for (int r = 0; r < ms; ++r) res[r] = target[r] - row_dot(S[r], z0);
        pS = dlu.solve(res);
        pS += dlu.solve(res - Mschur * pS);
        for (int c = 0; c < ms; ++c) zout += pS[c] * xcol[static_cast<std::size_t>(S[c])];
        for (std::size_t a = 0; a < lin.coupled.size(); ++a) {
            const int c = pos[lin.coupled[a].second];
            if (c >= 0) zout += (lin.coef[a] * pS[c]) * xcol[static_cast<std::size_t>(lin.coupled[a].first)];
        }
    }

    /// The box-constrained QP min 1/2 x^T W x + q^T x, lower <= x <= upper, by the monotone
    /// primal active-set method of box_qp.hpp (the dense solver's), each equality-constrained
    /// step one sparse solve of the held (free) rows with the bound ones fixed: the
    /// objective falls at every iteration, so it cannot cycle. x = p, and z follows it.
    bool box_qp(const Eigen::VectorXd& b, const Eigen::VectorXd& d, const Eigen::VectorXd& lower,
                const Eigen::VectorXd& upper, Eigen::VectorXd& x, Eigen::VectorXd& z,
                std::vector<signed char>& at_bound, double tolerance, int max_iterations, SolveResult& r) {
        const int m = static_cast<int>(x.size());
        detail::project_onto_box(lower, upper, x, at_bound);
        z = k_llt.solve(b + G.transpose() * x);
        detail::ModeLinearization qp;
        Eigen::VectorXd y, zy;
        struct Blocking { int row; double t; signed char side; };
        std::vector<Blocking> blocking_rows;
        std::vector<int> wrong_rows;
        bool single = false;  // release one bound per iteration (after a zero step)
        int released = 0;     // bounds released by the last release
        for (int iter = 0; iter < max_iterations; ++iter) {
            ++r.iterations;
            qp.S.clear();
            qp.e = x;
            for (int i = 0; i < m; ++i)
                if (at_bound[i] == 0) {
                    qp.S.push_back(i);
                    qp.e[i] = 0.0;
                }
            std::vector<signed char> key(at_bound);
            key.push_back(100);  // a box-QP working set, not a set of modes
            r.factorizations += solve_held(qp, key, b, d, y, zy);
            // step towards y up to the first bound; every row that reaches its bound at that
            // step length (ties: in degenerate problems many rows sit at a bound with a zero
            // step) joins the bounds at once. The iterate stays feasible and the objective
            // does not rise (y minimises it on the subspace, which holds x).
            double alpha = 1.0;
            blocking_rows.clear();
            for (int i : qp.S) {
                const double dd = y[i] - x[i];
                double t = 2.0;
                signed char side = 0;
                if (dd < 0.0 && y[i] < lower[i]) { t = (lower[i] - x[i]) / dd; side = -1; }
                else if (dd > 0.0 && y[i] > upper[i]) { t = (upper[i] - x[i]) / dd; side = +1; }
                if (side == 0) continue;
                t = std::max(t, 0.0);
                alpha = std::min(alpha, t);
                blocking_rows.push_back({i, t, side});
            }
            x += alpha * (y - x);
            z += alpha * (zy - z);
            bool blocked = false;
            for (const auto& c : blocking_rows)
                if (c.t <= alpha + 1e-14) {
                    at_bound[c.row] = c.side;
                    x[c.row] = c.side < 0 ? lower[c.row] : upper[c.row];
                    blocked = true;
                }
            if (blocked) {
                // a zero step right after releasing several rows: release one at a time from
                // now on (the classical rule, which cannot cycle)
                if (alpha == 0.0 && released > 1) single = true;
                released = 0;
                continue;
            }
            // release the bounds whose multiplier has the wrong sign: all of them (the step to
            // the new subspace minimiser still lowers the objective), or the worst one only
            const Eigen::VectorXd sx = Grow * z - d;
            int worst = -1;
            double worst_size = tolerance;
            wrong_rows.clear();
            for (int i = 0; i < m; ++i) {
                if (at_bound[i] == 0 || lower[i] == upper[i]) continue;
                const double wrong = at_bound[i] < 0 ? -sx[i] : sx[i];
                if (wrong > tolerance) wrong_rows.push_back(i);
                if (wrong > worst_size) { worst_size = wrong; worst = i; }
            }
            if (worst < 0) return true;
            if (single) {
                at_bound[worst] = 0;
                released = 1;
            } else {
                for (int i : wrong_rows) at_bound[i] = 0;
                released = static_cast<int>(wrong_rows.size());
            }
        }
        return false;
    }

    Eigen::VectorXd refined_solve(const Eigen::VectorXd& r) {
        Eigen::VectorXd y = lu.solve(r);
        const Eigen::VectorXd res = r - A * y;
        y += lu.solve(res);
        return y;
    }

    int count_violations(const Eigen::VectorXd& d, const Eigen::VectorXd& p, const Eigen::VectorXd& z) {
        s = Grow * z - d;  // row-major: a gather per row, the same sums as G * z
        const double roundoff = 1e-13 * (d.lpNorm<Eigen::Infinity>() + g_norm_inf * z.lpNorm<Eigen::Infinity>());
        return modes.count_violations(laws, p, s, diag, std::max(kAccept * options.tolerance_m, roundoff));
    }

    /// Active-set passes at load b and offsets d from the current modes.
    bool passes(const Eigen::VectorXd& b, const Eigen::VectorXd& d, Eigen::VectorXd& p, Eigen::VectorXd& z,
                int max_passes, SolveResult& r) {
        return detail::active_set_passes(
            modes, laws, p, max_passes, kBudget, r, [&](Eigen::VectorXd& x) { return solve_modes(b, d, x, z); },
            [&](const Eigen::VectorXd& x) { return count_violations(d, x, z); });
    }

    /// The box QP's optimality test of row i in metres, for a working set whose held rows
    /// (at_bound 0) the solve satisfies exactly (s_i = 0): a held force outside its box
    /// (times W_ii), or a force at a bound whose gradient s_i pushes it into the box.
    /// box_qp_bpp stops when no row exceeds its tolerance; box_qp_ipm also checks |s_i| of
    /// the held rows, which its iterate satisfies only approximately.
    double box_row_violation(int i, const std::vector<signed char>& at_bound, const Eigen::VectorXd& x,
                             const Eigen::VectorXd& s, const Eigen::VectorXd& lower, const Eigen::VectorXd& upper) const {
        if (at_bound[i] == 0) return std::max(lower[i] - x[i], x[i] - upper[i]) * diag[i];
        if (lower[i] < upper[i]) return at_bound[i] < 0 ? -s[i] : s[i];
        return 0.0;
    }

    /// The box QP of box_qp_bpp by a primal-dual interior-point method (Mehrotra's
    /// predictor-corrector): its iteration count hardly depends on how many bounds change
    /// or how degenerate they are (pairs with force and gap both ~0), where block principal
    /// pivoting and the primal method may need one factorisation per working-set change.
    ///   min 1/2 x^T W x + q^T x,  lower <= x <= upper,  W = G K^-1 G^T, q = G K^-1 b - d;
    /// the gradient is s = W x + q = G z - d [m], z = K^-1 (b + G^T x). KKT conditions with
    /// multipliers yl, yu >= 0 [m] and gaps gl = x - lower, gu = upper - x [N]:
    ///   s - yl + yu = 0,   gl yl = 0,   gu yu = 0.
    /// Each iteration solves the Newton system (W + Sigma) dx = h, Sigma = yl / gl + yu / gu
    /// [m/N], without W:  (K + G^T Sigma^-1 G) dz = G^T Sigma^-1 h,  dx = Sigma^-1 (h - G dz)
    /// (one sparse LDL^T of the same pattern each iteration; the predictor and corrector
    /// share it). s is recomputed exactly from z at every iterate, so the Newton systems'
    /// round-off (Sigma spans many decades near the end) only slows it, never biases it.
    /// Rows without bounds (bilateral) carry a proximal Sigma = kIpmRegularisation x W_ii.
    /// End: the working set read from the iterate (at a bound where the multiplier exceeds
    /// the gap, both in metres), the bounded variables put exactly on their bounds, z and s
    /// recomputed, and the box QP's natural residual (in metres, as box_qp_bpp's test) below
    /// `tolerance` in every row: the answer is then the QP's to the same test as the
    /// pivoting methods'. Returns false after kIpmIterations or on a failed factorisation.
    bool box_qp_ipm(const Eigen::VectorXd& b, const Eigen::VectorXd& d, const Eigen::VectorXd& lower,
                    const Eigen::VectorXd& upper, Eigen::VectorXd& x, Eigen::VectorXd& z,
                    std::vector<signed char>& at_bound, double tolerance, SolveResult& r) {
        const int m = static_cast<int>(x.size());
        std::vector<signed char> kind(m);  // 0 free, 1 lower only, 2 upper only, 3 both, 4 fixed
        double fscale = 0.0;               // force scale [N]
        for (int i = 0; i < m; ++i) {
            const bool hl = std::isfinite(lower[i]), hu = std::isfinite(upper[i]);
            kind[i] = hl && hu ? (lower[i] == upper[i] ? 4 : 3) : hl ? 1 : hu ? 2 : 0;
            if (hl) fscale = std::max(fscale, std::abs(lower[i]));
            if (hu) fscale = std::max(fscale, std::abs(upper[i]));
            fscale = std::max(fscale, std::abs(x[i]));
        }
        if (!(fscale > 0.0)) fscale = 1.0;
        // start: x strictly inside its box, multipliers from s at that x (at least a floor)
        for (int i = 0; i < m; ++i) {
            switch (kind[i]) {
                case 4: x[i] = lower[i]; break;
                case 3: {
                    const double w = upper[i] - lower[i];
                    x[i] = std::clamp(x[i], lower[i] + 0.1 * w, upper[i] - 0.1 * w);
                    break;
                }
                case 1: x[i] = std::max(x[i], lower[i] + 1e-2 * fscale); break;
                case 2: x[i] = std::min(x[i], upper[i] - 1e-2 * fscale); break;
                default: break;
            }
        }
        auto bounded = [&](int i, bool up) { return up ? (kind[i] == 2 || kind[i] == 3) : (kind[i] == 1 || kind[i] == 3); };
        Eigen::VectorXd sx = positions(b, d, x, z);
        const double yfloor = std::max(1e-2 * sx.lpNorm<Eigen::Infinity>(), tolerance);
        // multipliers yl, yu and gaps gl, gu; the gaps are iterated themselves (not x - bound:
        // that cancels to 0 or below near a bound)
        Eigen::VectorXd yl = Eigen::VectorXd::Zero(m), yu = Eigen::VectorXd::Zero(m);
        Eigen::VectorXd gl = Eigen::VectorXd::Zero(m), gu = Eigen::VectorXd::Zero(m);
        for (int i = 0; i < m; ++i) {
            if (bounded(i, false)) {
                yl[i] = std::max(sx[i], yfloor);
                gl[i] = x[i] - lower[i];
            }
            if (bounded(i, true)) {
                yu[i] = std::max(-sx[i], yfloor);
                gu[i] = upper[i] - x[i];
            }
        }
        Eigen::VectorXd rd(m), winv(m), h(m), dx(m), dyl(m), dyu(m), dxa(m), dyla(m), dyua(m), zc;
        // the Newton system on the stiffness's pattern plus G^T G (every row, so the pattern
        // stays and its ordering is made once per call)
        auto newton = [&](const Eigen::VectorXd& hh, Eigen::VectorXd& ddx) {
            ddx = winv.cwiseProduct(hh - Grow * ipm_ldlt.solve(Gt * winv.cwiseProduct(hh)));
        };
        // largest step keeping the gaps and multipliers positive (fraction to the boundary)
        auto max_step = [&](const Eigen::VectorXd& ddx, const Eigen::VectorXd& ddl, const Eigen::VectorXd& ddu) {
            double a = 1.0;
            for (int i = 0; i < m; ++i) {
                if (bounded(i, false)) {
                    if (ddx[i] < 0.0) a = std::min(a, -gl[i] / ddx[i]);
                    if (ddl[i] < 0.0) a = std::min(a, -yl[i] / ddl[i]);
                }
                if (bounded(i, true)) {
                    if (ddx[i] > 0.0) a = std::min(a, gu[i] / ddx[i]);
                    if (ddu[i] < 0.0) a = std::min(a, -yu[i] / ddu[i]);
                }
            }
            return a;
        };
        // the multipliers' changes for a given dx and complementarity targets rl, ru
        auto multipliers = [&](const Eigen::VectorXd& ddx, const Eigen::VectorXd& rl, const Eigen::VectorXd& ru,
                               Eigen::VectorXd& ddl, Eigen::VectorXd& ddu) {
            ddl.setZero(m);
            ddu.setZero(m);
            for (int i = 0; i < m; ++i) {
                if (bounded(i, false)) ddl[i] = (rl[i] - yl[i] * ddx[i]) / gl[i];
                if (bounded(i, true)) ddu[i] = (ru[i] + yu[i] * ddx[i]) / gu[i];
            }
        };
        Eigen::VectorXd rl(m), ru(m);
        // the Newton system's right-hand side h = -rd + rl / gl - ru / gu for complementarity targets rl, ru
        auto newton_rhs = [&] {
            for (int i = 0; i < m; ++i)
                h[i] = kind[i] == 4 ? 0.0 : -rd[i] + (bounded(i, false) ? rl[i] / gl[i] : 0.0) -
                                                (bounded(i, true) ? ru[i] / gu[i] : 0.0);
        };
        for (int it = 0; it < kIpmIterations; ++it) {
            // residuals: stationarity [m], complementarity [m^2] (gap x W_ii x multiplier)
            rd = sx - yl + yu;
            double comp = 0.0, comp_max = 0.0, rd_max = 0.0;
            int nb = 0;
            for (int i = 0; i < m; ++i) {
                if (kind[i] == 4) {
                    rd[i] = 0.0;
                    continue;
                }
                rd_max = std::max(rd_max, std::abs(rd[i]));
                if (bounded(i, false)) {
                    comp += gl[i] * yl[i];
                    comp_max = std::max(comp_max, gl[i] * yl[i] * diag[i]);
                    ++nb;
                }
                if (bounded(i, true)) {
                    comp += gu[i] * yu[i];
                    comp_max = std::max(comp_max, gu[i] * yu[i] * diag[i]);
                    ++nb;
                }
            }
            // close enough to try the working set it points at (each row's error ~ sqrt(gap W y))
            if (rd_max < 0.1 * tolerance && comp_max < 1e-2 * tolerance * tolerance) {
                at_bound.assign(m, 0);
                Eigen::VectorXd xs = x;
                for (int i = 0; i < m; ++i) {
                    if (kind[i] == 4) at_bound[i] = +1;
                    else if (bounded(i, false) && yl[i] > diag[i] * gl[i]) at_bound[i] = -1;
                    else if (bounded(i, true) && yu[i] > diag[i] * gu[i]) at_bound[i] = +1;
                    if (at_bound[i] != 0) xs[i] = at_bound[i] < 0 ? lower[i] : upper[i];
                }
                const Eigen::VectorXd ss = positions(b, d, xs, zc);
                double worst = 0.0;
                for (int i = 0; i < m; ++i) {
                    const double v = box_row_violation(i, at_bound, xs, ss, lower, upper);
                    worst = std::max(worst, at_bound[i] == 0 ? std::max(std::abs(ss[i]), v) : v);
                }
                if (worst <= tolerance && xs.allFinite()) {
                    x = xs;
                    z = zc;
                    return true;
                }
            }
            ++r.iterations;
            ++r.factorizations;
            const double mu = nb > 0 ? comp / nb : 0.0;
            for (int i = 0; i < m; ++i) {
                double si = 0.0;
                if (bounded(i, false)) si += yl[i] / gl[i];
                if (bounded(i, true)) si += yu[i] / gu[i];  // free rows: 0, raised to the proximal floor
                winv[i] = kind[i] == 4 ? 0.0 : 1.0 / std::max(si, kIpmRegularisation * diag[i]);
            }
            SpMat M = K + SpMat(Gt * winv.asDiagonal() * Grow);
            if (!ipm_analysed || M.nonZeros() != ipm_nnz) {
                ipm_ldlt.analyzePattern(M);
                ipm_analysed = true;
                ipm_nnz = M.nonZeros();
            }
            ipm_ldlt.factorize(M);
            if (ipm_ldlt.info() != Eigen::Success) return false;
            // predictor (affine scaling: complementarity targets 0)
            for (int i = 0; i < m; ++i) {
                rl[i] = bounded(i, false) ? -gl[i] * yl[i] : 0.0;
                ru[i] = bounded(i, true) ? -gu[i] * yu[i] : 0.0;
            }
            newton_rhs();
            newton(h, dxa);
            multipliers(dxa, rl, ru, dyla, dyua);
            const double aa = max_step(dxa, dyla, dyua);
            double comp_aff = 0.0;
            for (int i = 0; i < m; ++i) {
                if (bounded(i, false)) comp_aff += (gl[i] + aa * dxa[i]) * (yl[i] + aa * dyla[i]);
                if (bounded(i, true)) comp_aff += (gu[i] - aa * dxa[i]) * (yu[i] + aa * dyua[i]);
            }
            const double mu_aff = nb > 0 ? comp_aff / nb : 0.0;
            const double sigma = mu > 0.0 ? std::pow(std::clamp(mu_aff / mu, 0.0, 1.0), 3) : 0.0;
            // corrector: centring sigma mu and the predictor's second-order term
            for (int i = 0; i < m; ++i) {
                rl[i] = bounded(i, false) ? sigma * mu - gl[i] * yl[i] - dxa[i] * dyla[i] : 0.0;
                ru[i] = bounded(i, true) ? sigma * mu - gu[i] * yu[i] + dxa[i] * dyua[i] : 0.0;
            }
            newton_rhs();
            newton(h, dx);
            multipliers(dx, rl, ru, dyl, dyu);
            const double a = std::min(1.0, 0.995 * max_step(dx, dyl, dyu));
            if (!(a > 0.0) || !dx.allFinite()) return false;
            x += a * dx;
            gl += a * dx;
            gu -= a * dx;
            yl += a * dyl;
            yu += a * dyu;
            for (int i = 0; i < m; ++i) {  // multipliers stay >= 0 (round-off of the step)
                if (bounded(i, false)) yl[i] = std::max(yl[i], 0.0);
                if (bounded(i, true)) yu[i] = std::max(yu[i], 0.0);
            }
            sx = positions(b, d, x, z);
        }
        return false;
    }

    /// The same box-constrained QP by block principal pivoting (Judice & Pires): every
    /// violated bound or multiplier switches at once while their number falls, then
    /// Murty's least-index rule (finite: the QP's matrix W is symmetric positive definite).
    /// A few factorisations where the primal method needs one per working-set change
    /// (hundreds per step on a 10-leaf stack). Returns false after max_passes.
    bool box_qp_bpp(const Eigen::VectorXd& b, const Eigen::VectorXd& d, const Eigen::VectorXd& lower,
                    const Eigen::VectorXd& upper, Eigen::VectorXd& x, Eigen::VectorXd& z,
                    std::vector<signed char>& at_bound, double tolerance, int max_passes, SolveResult& r) {
        const int m = static_cast<int>(x.size());
        at_bound.resize(m, 0);
        for (int i = 0; i < m; ++i) {
            if (lower[i] == upper[i]) at_bound[i] = +1;
            if (at_bound[i] == -1 && !std::isfinite(lower[i])) at_bound[i] = 0;
            if (at_bound[i] == +1 && !std::isfinite(upper[i])) at_bound[i] = 0;
        }
        detail::ModeLinearization qp;
        std::vector<int> viol;
        int best = std::numeric_limits<int>::max(), budget = kBoxBudget;
        for (int pass = 0; pass < max_passes; ++pass) {
            ++r.iterations;
            qp.S.clear();
            qp.e.setZero(m);
            for (int i = 0; i < m; ++i) {
                if (at_bound[i] == 0) qp.S.push_back(i);
                else qp.e[i] = at_bound[i] < 0 ? lower[i] : upper[i];
            }
            std::vector<signed char> key(at_bound);
            key.push_back(100);  // a box-QP working set, not a set of modes
            r.factorizations += solve_held(qp, key, b, d, x, z);
            const Eigen::VectorXd sx = Grow * z - d;
            viol.clear();
            for (int i = 0; i < m; ++i)
                if (box_row_violation(i, at_bound, x, sx, lower, upper) > tolerance) viol.push_back(i);
            const int nv = static_cast<int>(viol.size());
            if (nv == 0) return true;
            bool single = false;
            if (nv < best) {
                best = nv;
                budget = kBoxBudget;
            } else if (budget > 0) {
                --budget;
            } else {
                single = true;
            }
            if (single) viol.resize(1);
            for (int i : viol) {
                if (at_bound[i] != 0) at_bound[i] = 0;
                else at_bound[i] = x[i] < lower[i] ? -1 : +1;
            }
        }
        return false;
    }

    /// Fixed point on the friction limits, as in the dense solver (contact/exact.cpp): each
    /// pass solves the problem with the limits frozen (Tresca), a box-constrained convex QP
    /// (box_qp, which cannot cycle); the limits are updated from its normal forces until they
    /// settle to kAccept x tolerance (in metres); its final working set gives the modes.
    bool tresca_fixed_point(const Eigen::VectorXd& b, const Eigen::VectorXd& d, Eigen::VectorXd& p,
                            Eigen::VectorXd& z, SolveResult& r) {
        const int n = static_cast<int>(d.size());
        const double accept = kAccept * options.tolerance_m;
        bool s_current = false;  // s = G z - d of the final z, made once when needed
        const bool settled = detail::tresca_fixed_point(
            modes, laws, n, p, accept, kTrescaIterations, options.tresca_anderson_depth,
            [&](const Eigen::VectorXd& lower, const Eigen::VectorXd& upper, std::vector<signed char>& at_bound) {
                // block principal pivoting first (few factorisations where it settles: the
                // small problems); if it does not settle in kBoxPasses passes, the interior-point
                // method (15-45 iterations on every box QP measured, however degenerate; 10
                // identical leaves x 100 from rest: 34 instead of 50 factorisations per step with
                // the Tresca fixed point alone, BENCHMARKS.md); the
                // monotone primal method (one factorisation per working-set change, cannot cycle)
                // if neither does
                ++r.tresca_iterations;
                const std::vector<signed char> start = at_bound;
                const Eigen::VectorXd p_start = p;
                auto restart = [&] {
                    at_bound = start;
                    p = p_start;
                };
                if (tuning.box_qp == BoxQpMethod::interior_point) {
                    if (box_qp_ipm(b, d, lower, upper, p, z, at_bound, accept, r)) return true;
                    restart();
                }
                if (box_qp_bpp(b, d, lower, upper, p, z, at_bound, accept, kBoxPasses, r)) return true;
                restart();
                if (tuning.box_qp == BoxQpMethod::pivoting) {
                    if (box_qp_ipm(b, d, lower, upper, p, z, at_bound, accept, r)) return true;
                    restart();
                }
                return box_qp(b, d, lower, upper, p, z, at_bound, accept, 50 * (n + 1), r);
            },
            [&](int row) { return diag[row]; },
            [&](int row) {
                if (!s_current) s = Grow * z - d;
                s_current = true;
                return s[row];
            });
        if (settled && !s_current) s = Grow * z - d;
        return settled;
    }

    /// The natural map F(p, s) of the contact laws (paper eq. 8; zero exactly where eq. 10's
    /// error vector is), per component in metres (contact.hpp, natural_map), into `F`, and
    /// optionally the modes of its generalised Jacobian at (p, s) into `modes`:
    ///   unilateral normal  F = w (p_n - min(0, p_n - s_n / w)):  closed (F = s_n) where
    ///                      p_n - s_n / w < 0, else open (F = w p_n);
    ///   tangential         F = w (p_t - clamp(a, -mu tau, mu tau)), a = p_t - s_t / w: stick
    ///                      (F = s_t) inside the limit, slip with sigma = sign(a) (F = w (p_t -
    ///                      sigma mu tau(p_n)), tau linearised as in ModeSet::linearize) outside,
    ///                      free (F = w p_t) where the pair is open or tau cannot be positive;
    ///   bilateral, bonded  F = s (held).
    /// With w = W_kk (diag) both parts of each component are in metres, so the Newton step
    /// of the modes (the linear problem solve_modes solves) zeroes F for those modes.
    void natural_residual(const Eigen::VectorXd& p, const Eigen::VectorXd& s, Eigen::VectorXd& F,
                          bool set_modes) {
        F = s;
        const bool prev = laws.tau_rule == TauRule::previous_step;
        for (int k = 0; k < static_cast<int>(laws.pairs.size()); ++k) {
            const auto& c = laws.pairs[k];
            bool closed = true;
            if (c.row_n >= 0 && c.kind == PairKind::coulomb) {
                const double w = diag[c.row_n], pn = p[c.row_n];
                const double a = pn - s[c.row_n] / w;
                F[c.row_n] = w * (pn - std::min(0.0, a));
                closed = a < 0.0;
                if (set_modes) modes.nmode[k] = closed ? detail::CLOSED : detail::OPEN;
            } else if (c.kind == PairKind::coulomb) {
                closed = false;  // no normal row: the unilateral pair has no normal force
            }
            if (c.row_t < 0) continue;
            if (c.kind == PairKind::bonded) {
                if (set_modes) modes.tmode[k] = detail::STICK;
                continue;
            }
            const double w = diag[c.row_t], pt = p[c.row_t];
            const double limit = c.friction_coefficient * friction_normal_force(laws, k, p);
            const double a = pt - s[c.row_t] / w;
            F[c.row_t] = w * (pt - std::clamp(a, -limit, limit));
            if (!set_modes) continue;
            // can the friction limit be positive in the Newton step's linearisation?
            bool carries = c.friction_coefficient > 0.0;
            if (c.kind == PairKind::coulomb) carries = carries && closed && (!prev || limit > 0.0);
            else if (c.kind == PairKind::clamp) carries = carries && (prev ? limit > 0.0 : c.preload_n - (c.row_n >= 0 ? p[c.row_n] : 0.0) > 0.0);
            signed char mode = detail::FREE;
            if (carries) {
                if (std::abs(a) < limit || a == 0.0) mode = detail::STICK;
                else mode = a > 0.0 ? detail::SLIP_POS : detail::SLIP_NEG;
            }
            modes.tmode[k] = mode;
            modes.make_consistent(laws, k);
        }
    }

    /// The modes of a start from rest: every unilateral pair open, only the bilateral rows
    /// held (clamps sticking, bonds). On identical leaves most pairs open in the first steps
    /// (measured: 850 of 891 pairs at 10 leaves x 100 elements), where "all closed" (the
    /// stepper's modes at rest) is the worst start.
    void set_open_modes() {
        for (int k = 0; k < static_cast<int>(laws.pairs.size()); ++k) {
            const auto& c = laws.pairs[k];
            if (c.row_n >= 0) modes.nmode[k] = detail::ModeSet::unilateral(c) ? detail::OPEN : detail::CLOSED;
            if (c.row_t >= 0) modes.tmode[k] = detail::STICK;
            modes.make_consistent(laws, k);
        }
    }

    /// Semismooth Newton method on the natural map (Alart-Curnier / Pang's natural-map
    /// Newton, planar: the tangential direction is a scalar), for transitions where nearly
    /// every pair changes mode (identical leaves starting from rest: forces and gaps ~0).
    /// Each iteration:
    ///  1. the modes of the generalised Jacobian of F at the iterate (natural_residual): which
    ///     part of each min / clamp is active there;
    ///  2. the Newton step: the linear problem of those modes, s_S = 0, fixed and slip forces
    ///     (solve_modes: the sparse saddle-point system, its low-rank update or the Schur
    ///     complement, as for the active-set passes), giving (p1, z1); F is piecewise linear
    ///     in p, so this is the full Newton step p1 - p;
    ///  3. a line search on theta = ||F||^2 along it: s is affine in p, so
    ///     s(p + a (p1 - p)) = s + a (s1 - s) and a trial costs O(m), no solve. Where no trial
    ///     decreases theta the full step is taken (a non-monotone step; at most
    ///     kNewtonNonmonotone of them) rather than stalling.
    /// From rest (p = 0) it starts from the open modes' solution (set_open_modes).
    /// Unlike block principal pivoting, the modes come from p - s / w (forces and gaps
    /// together), and a damped step moves every component part of the way, so many pairs
    /// change per iteration without the ping-pong of full switches. Stops when every
    /// component of F is within `accept` [m] (half the active-set threshold, so the passes
    /// that follow see no violated mode); returns false after kNewtonIterations or on a
    /// singular set of modes (p and z are then the last iterate). On entry z must be
    /// K^-1 (b + G^T p).
    bool semismooth_newton(const Eigen::VectorXd& b, const Eigen::VectorXd& d, Eigen::VectorXd& p,
                           Eigen::VectorXd& z, SolveResult& r) {
        const int m = static_cast<int>(d.size());
        best_p.resize(0);
        if (m > 0 && p.isZero(0.0)) {
            // a start from rest (no force anywhere, the first step of a run): the linear problem
            // of the open modes (set_open_modes) instead of the natural map's modes at p = 0, where
            // every closed pair sits on the kink of its friction limit (tau = 0)
            set_open_modes();
            ++r.iterations;
            ++r.newton_iterations;
            try {
                r.factorizations += solve_modes(b, d, p, z);
            } catch (const SingularModes&) {
                lu_key.clear();
                return false;
            }
        }
        Eigen::VectorXd sk = Grow * z - d, F, F1, pa, sa, p1, z1, s1;
        natural_residual(p, sk, F, false);
        double theta = F.squaredNorm();
        int nonmonotone = 0;
        // the iterate of smallest ||F|| (where the smoothing method starts when this one fails)
        best_p = p;
        double best_theta = theta;
        bool full_step = false;  // p is the linear solution of the current modes
        for (int it = 0; it < kNewtonIterations; ++it) {
            const double roundoff =
                1e-13 * (d.lpNorm<Eigen::Infinity>() + g_norm_inf * z.lpNorm<Eigen::Infinity>());
            const double accept = std::max(0.5 * kAccept * options.tolerance_m, roundoff);
            if (m == 0 || F.lpNorm<Eigen::Infinity>() <= accept) {
                // the modes for the passes that follow: those of the last full step (its linear
                // problem gave p, so the passes reuse its factorisation), else those at p
                if (!full_step) natural_residual(p, sk, F, true);
                return true;
            }
            ++r.iterations;
            ++r.newton_iterations;
            natural_residual(p, sk, F, true);
            p1 = p;
            try {
                r.factorizations += solve_modes(b, d, p1, z1);
            } catch (const SingularModes&) {
                lu_key.clear();
                return false;
            }
            s1 = Grow * z1 - d;
            // line search: the smallest theta on the grid a = 2^(-j/4), j = 0 .. 4 kLineSearchOctaves
            // (each trial O(m)); theta is piecewise quadratic along the step with many kinks
            // (every component that changes branch), so the grid's best point is taken rather
            // than the first that passes Armijo's test (measured: 26 instead of 48 iterations
            // on the first step of 10 leaves x 100 elements). Where no trial lowers theta, the
            // full step is taken (non-monotone; at most kNewtonNonmonotone times).
            double a = 1.0, grid_theta = std::numeric_limits<double>::infinity();
            for (int j = 0; j <= 4 * kLineSearchOctaves; ++j) {
                const double aj = std::pow(2.0, -0.25 * j);
                pa = p + aj * (p1 - p);
                sa = sk + aj * (s1 - sk);
                natural_residual(pa, sa, F1, false);
                const double tj = F1.squaredNorm();
                if (tj < grid_theta) {
                    grid_theta = tj;
                    a = aj;
                }
            }
            if (!(grid_theta < theta)) {
                if (++nonmonotone > kNewtonNonmonotone) break;
                a = 1.0;
            }
            full_step = a == 1.0;
            if (full_step) {
                p = p1;
                z = z1;
                sk = s1;
            } else {
                p += a * (p1 - p);
                z += a * (z1 - z);
                sk += a * (s1 - sk);
            }
            natural_residual(p, sk, F, false);
            theta = F.squaredNorm();
            if (theta < best_theta) {
                best_theta = theta;
                best_p = p;
            }
        }
        return false;
    }

    // ---- smoothing Newton method --------------------------------------------------------
    // Chen-Harker-Kanzow-Smale smoothing of max(0, y): smax(y, e) = (y + sqrt(y^2 + 4 e^2)) / 2,
    // smooth for e > 0, within e of max(0, y), and equal to it for e = 0.
    static double smax(double y, double e) { return 0.5 * (y + std::sqrt(y * y + 4.0 * e * e)); }
    static double dsmax(double y, double e) {
        const double r = std::sqrt(y * y + 4.0 * e * e);
        return r > 0.0 ? 0.5 * (1.0 + y / r) : 0.5;
    }
    /// One row of the smoothed map's Jacobian: dF_i = alpha dp_i + beta ds_i + gamma dp_ncol.
    struct SmoothRow {
        double alpha = 0.0, beta = 1.0, gamma = 0.0;
        int ncol = -1;  // the pair's normal row (tangential rows of friction pairs), else -1
    };

    /// The natural map of natural_residual with every max(0, .) (and so every min and clamp,
    /// and the friction limit's tau) smoothed by smax with e = eps_m / w (w = W_ii of the
    /// row, so eps_m is in metres like F): F_eps is smooth for eps_m > 0, within about
    /// eps_m of F per component, and F_0 is the natural map (natural_residual). Per component:
    ///   unilateral normal  F = w (p_n + smax(s_n / w - p_n, e))         (= w (p_n - min(0, a)))
    ///   tangential         F = w (p_t - clip(a)),  a = p_t - s_t / w,
    ///                      clip(a) = -L + smax(a + L, e) - smax(a - L, e),  L = mu tau_eps(p_n)
    ///                      (tau_eps = smax(-p_n) for Coulomb, smax(F_c - p_n) for clamps)
    ///   bilateral, bonded  F = s.
    /// With `jac`, the coefficients of its Jacobian per row. The previous step's tau rule
    /// has a constant limit (gamma = 0).
    void smoothed_residual(const Eigen::VectorXd& p, const Eigen::VectorXd& s, double eps_m, Eigen::VectorXd& F,
                           std::vector<SmoothRow>* jac) const {
        F = s;
        if (jac) jac->assign(static_cast<std::size_t>(s.size()), SmoothRow{});
        const bool prev = laws.tau_rule == TauRule::previous_step;
        for (int k = 0; k < static_cast<int>(laws.pairs.size()); ++k) {
            const auto& c = laws.pairs[k];
            if (c.row_n >= 0 && c.kind == PairKind::coulomb) {
                const double w = diag[c.row_n], pn = p[c.row_n], y = s[c.row_n] / w - pn, e = eps_m / w;
                F[c.row_n] = w * (pn + smax(y, e));
                if (jac) {
                    const double D = dsmax(y, e);  // dF = w (1 - D) dp_n + D ds_n
                    (*jac)[c.row_n] = SmoothRow{w * (1.0 - D), D, 0.0, -1};
                }
            }
            if (c.row_t < 0 || c.kind == PairKind::bonded) continue;
            const double w = diag[c.row_t], pt = p[c.row_t], e = eps_m / w, a = pt - s[c.row_t] / w;
            double tau = 0.0, dtau = 0.0;  // tau and d tau / d p_n
            if (prev) {
                tau = friction_normal_force(laws, k, p);
            } else if (c.row_n >= 0) {
                const double en = eps_m / diag[c.row_n];
                const double y = (c.kind == PairKind::clamp ? c.preload_n : 0.0) - p[c.row_n];
                tau = smax(y, en);
                dtau = -dsmax(y, en);
            } else {
                tau = c.kind == PairKind::clamp ? c.preload_n : 0.0;
            }
            const double mu = c.friction_coefficient, L = mu * tau;
            const double hi = smax(a + L, e), lo = smax(a - L, e);
            F[c.row_t] = w * (pt - (-L + hi - lo));
            if (jac) {
                const double dh = dsmax(a + L, e), dl = dsmax(a - L, e);
                const double Ca = dh - dl, CL = -1.0 + dh + dl;  // d clip / da, d clip / dL
                (*jac)[c.row_t] = SmoothRow{w * (1.0 - Ca), Ca, -w * CL * mu * dtau, prev ? -1 : c.row_n};
            }
        }
    }

    /// The Newton step of the smoothed map, J dp = -F with J = A + B W (A: alpha on the
    /// diagonal and gamma at (t, n); B = diag(beta)), without W: with dz = K^-1 G^T dp,
    ///     [ K      -G^T ] [dz]   [ 0]
    ///     [ B G     A   ] [dp] = [-F],
    /// scaled like solve_modes (dz = Dz y, dp_i = pi_i / h_i and contact row i divided by
    /// h_i, h_i = ||G_i Dz||). Its pattern does not depend on the iterate, so the LU's
    /// ordering is made once per (K, G) and every iteration is one numeric factorisation.
    /// A row whose component is held (beta = 1, alpha = 0), open (alpha = w, beta = 0) or
    /// in between (a component near its kink: both ~ 1/2) is regular, which is what the
    /// natural map's generalised Jacobian lacks near a degenerate solution.
    bool smoothing_direction(const std::vector<SmoothRow>& J, const Eigen::VectorXd& F, Eigen::VectorXd& dp,
                             Eigen::VectorXd& dzv) {
        const int n = static_cast<int>(K.rows()), m = static_cast<int>(F.size());
        std::vector<Eigen::Triplet<double>> t;
        t.reserve(static_cast<std::size_t>(K.nonZeros() + 2 * G.nonZeros() + 2 * m));
        append_scaled_K(t);
        for (int i = 0; i < m; ++i) {
            const double hi = row_h[i];
            for (SpMat::InnerIterator it(Gt_scaled, i); it; ++it) {
                t.emplace_back(it.row(), n + i, -it.value() / hi);
                t.emplace_back(n + i, it.row(), J[i].beta * it.value() / hi);
            }
            t.emplace_back(n + i, n + i, J[i].alpha / (hi * hi));
            if (J[i].ncol >= 0) t.emplace_back(n + i, n + J[i].ncol, J[i].gamma / (hi * row_h[J[i].ncol]));
        }
        Js.resize(n + m, n + m);
        Js.setFromTriplets(t.begin(), t.end());
        Js.makeCompressed();
        if (!js_analysed) {
            js_lu.analyzePattern(Js);
            js_analysed = true;
        }
        js_lu.factorize(Js);
        if (js_lu.info() != Eigen::Success) return false;
        Eigen::VectorXd rhs_s = Eigen::VectorXd::Zero(n + m);
        for (int i = 0; i < m; ++i) rhs_s[n + i] = -F[i] / row_h[i];
        Eigen::VectorXd y = js_lu.solve(rhs_s);
        y += js_lu.solve(rhs_s - Js * y);  // one step of iterative refinement
        if (!y.allFinite()) return false;
        dzv = dz.cwiseProduct(y.head(n));
        dp = y.tail(m).cwiseQuotient(row_h);
        return true;
    }

    /// Smoothing Newton method (Chen, Qi and Sun's Jacobian smoothing with a continuation on
    /// the smoothing, here on the natural map of eq. 8): for transitions where the semismooth
    /// Newton method stalls, i.e. near a degenerate solution (identical leaves: many
    /// components with force and gap both ~0). There the natural map has kinks next to the
    /// iterate, so ||F||^2 has no descent along the semismooth step and that method's
    /// generalised Jacobians (every component either held or free) become near-singular.
    /// F_eps (smoothed_residual) has neither problem: ||F_eps||^2 is differentiable, the
    /// Newton step of F_eps is a descent direction for it, so Armijo's backtracking always
    /// finds a step, and a component at its kink enters its row half held, half free.
    /// Each iteration: one sparse LU of the Jacobian's saddle-point system
    /// (smoothing_direction), an Armijo search on ||F_eps||^2 (s is affine in p: O(m) per
    /// trial), then eps_m = min(eps_m, kSmoothTrack ||F_0||_inf), so the smoothing falls
    /// with the natural residual (geometrically once F_eps is solved: ||F_0|| <= ||F_eps||
    /// + ~2 eps_m). Stops when every component of the natural map is within `accept` (as the
    /// semismooth method) and leaves the modes at p for the passes that follow; false
    /// after kSmoothIterations or when no step length lowers the merit. On entry z must be
    /// K^-1 (b + G^T p).
    bool smoothing_newton(const Eigen::VectorXd& d, Eigen::VectorXd& p, Eigen::VectorXd& z, SolveResult& r) {
        const int m = static_cast<int>(d.size());
        if (m == 0) return true;
        Eigen::VectorXd sk = Grow * z - d, F, Fn, Ft, dp, dzv, ds, pa, sa;
        std::vector<SmoothRow> J;
        natural_residual(p, sk, Fn, false);
        double nat = Fn.lpNorm<Eigen::Infinity>();
        double eps = kSmoothStart * nat, best = nat;
        int since_best = 0;
        for (int it = 0; it <= kSmoothIterations; ++it) {
            const double roundoff =
                1e-13 * (d.lpNorm<Eigen::Infinity>() + g_norm_inf * z.lpNorm<Eigen::Infinity>());
            const double accept = std::max(0.5 * kAccept * options.tolerance_m, roundoff);
            if (nat <= accept) {
                s = sk;
                natural_residual(p, sk, F, true);  // the modes at p, for the passes that follow
                return true;
            }
            if (it == kSmoothIterations || since_best >= kSmoothStall) break;
            ++r.iterations;
            ++r.smoothing_iterations;
            eps = std::max(eps, 0.1 * accept);
            smoothed_residual(p, sk, eps, F, &J);
            const double theta = F.squaredNorm();
            ++r.factorizations;
            if (!smoothing_direction(J, F, dp, dzv)) return false;
            ds = Grow * dzv;
            // Armijo's backtracking on theta = ||F_eps||^2 (the exact Newton step of a smooth map is
            // a descent direction: d theta / da = -2 theta at a = 0)
            double a = 1.0;
            bool found = false;
            for (int j = 0; j < kSmoothHalvings && !found; ++j) {
                if (j > 0) a *= 0.5;
                pa = p + a * dp;
                sa = sk + a * ds;
                smoothed_residual(pa, sa, eps, Ft, nullptr);
                found = Ft.squaredNorm() <= (1.0 - 2.0 * kArmijo * a) * theta;
            }
            if (!found) return false;
            p = pa;
            sk = sa;
            z += a * dzv;
            natural_residual(p, sk, Fn, false);
            nat = Fn.lpNorm<Eigen::Infinity>();
            eps = std::min(eps, kSmoothTrack * nat);
            // a stall (measured at 10 leaves x 400 elements: a local minimum of ||F_eps|| where
            // its Jacobian is near-singular, the slip coupling's doing) is given up early
            if (nat < 0.9 * best) {
                best = nat;
                since_best = 0;
            } else {
                ++since_best;
            }
        }
        return false;
    }

    // ---- continuation on the offsets ----------------------------------------------------
    /// Continuation (homotopy) for a transition no Newton method settles from the step's
    /// start. The step's forces p (projected on the admissible set) solve the problem with the
    /// offsets d0 = G z0 - s_c, where z0 = K^-1 (b + G^T p) and s_c is the nearest relative
    /// position the laws allow at p (a closed or stuck component at s = 0, an open one at its
    /// gap). Along d(a) = d0 + a (d - d0), a from 0 to 1, the solution moves continuously
    /// (piecewise linearly while no pair changes mode); each sub-step from a to a + h is
    /// solved by the active-set passes from the modes at a, then, if they do not settle, by
    /// the semismooth Newton method from the solution at a; h doubles after a success and
    /// halves after a failure. The answer at a = 1 solves the step's own problem (the same
    /// passes confirm it), so continuation changes the way, not the result.
    /// Measured (BENCHMARKS.md): on 10 identical leaves x 100 elements it settled every
    /// transition both Newton methods gave up on (5 of 300 steps), in 2-4 sub-steps each,
    /// where the Tresca fixed point had cost up to 3,621 factorisations. It does not help where the step starts
    /// from rest with every pair at zero force and zero gap (10 identical leaves x 400): the
    /// problem is then positively homogeneous in a but for the clamps' preload, so the
    /// first sub-step is as hard as the whole step however short.
    /// Returns false when h falls below kContinuationMinStep.
    bool continuation(const Eigen::VectorXd& b, const Eigen::VectorXd& d, Eigen::VectorXd& p, Eigen::VectorXd& z,
                      SolveResult& r) {
        const int np = static_cast<int>(laws.pairs.size());
        for (int k = 0; k < np; ++k) {
            const ContactPair& c = laws.pairs[k];
            if (c.row_n >= 0 && detail::ModeSet::unilateral(c)) p[c.row_n] = std::min(p[c.row_n], 0.0);
            if (c.row_t >= 0 && c.kind != PairKind::bonded) {
                const double limit = c.friction_coefficient * friction_normal_force(laws, k, p);
                p[c.row_t] = std::clamp(p[c.row_t], -limit, limit);
            }
        }
        Eigen::VectorXd sc = positions(b, d, p, z);
        for (int k = 0; k < np; ++k) {
            const ContactPair& c = laws.pairs[k];
            if (c.row_n >= 0)
                sc[c.row_n] = detail::ModeSet::unilateral(c) && p[c.row_n] >= 0.0 ? std::min(0.0, sc[c.row_n]) : 0.0;
            if (c.row_t >= 0) sc[c.row_t] = 0.0;
        }
        const Eigen::VectorXd d0 = Grow * z - sc;
        double a = 0.0, h = 0.5;
        while (a < 1.0) {
            if (h < kContinuationMinStep) return false;
            const double at = std::min(1.0, a + h);
            const bool ok = continuation_substep(b, d0 + at * (d - d0), p, z, r);
            if (ok) {
                a = at;
                h = std::min(1.0, 2.0 * h);
            } else {
                h *= 0.5;
            }
        }
        s = Grow * z - d;
        return true;
    }

    /// One continuation sub-step: the problem (b, d) from the solution p, z of a nearby one,
    /// by the active-set passes from the modes at (p, s), then by the semismooth Newton
    /// method. On failure p, z and the modes are those on entry.
    bool continuation_substep(const Eigen::VectorXd& b, const Eigen::VectorXd& d, Eigen::VectorXd& p,
                              Eigen::VectorXd& z, SolveResult& r) {
        const Eigen::VectorXd p_keep = p, z_keep = z;
        const std::vector<signed char> nmode_keep = modes.nmode, tmode_keep = modes.tmode;
        ++r.continuation_steps;
        bool ok = false;
        try {
            modes.init(laws, p, Grow * z - d);
            ok = passes(b, d, p, z, kContinuationPasses, r);
            if (!ok) {
                p = p_keep;
                z = z_keep;
                ok = semismooth_newton(b, d, p, z, r) && passes(b, d, p, z, options.max_active_set_iterations, r);
            }
        } catch (const SingularModes&) {
            lu_key.clear();
            ok = false;
        }
        if (!ok) {
            p = p_keep;
            z = z_keep;
            modes.nmode = nmode_keep;
            modes.tmode = tmode_keep;
        }
        return ok;
    }
};

SparseContactSolver::SparseContactSolver(const SolverOptions& options, const SparsePathTuning& tuning)
    : impl_(std::make_unique<Impl>()) {
    make_solver(options);  // validates the options
    if (tuning.schur_max_rows < 0)
        throw InputError("tuning.schur_max_rows", "value " + std::to_string(tuning.schur_max_rows) + " must be >= 0");
    if (tuning.newton_min_rows < 0)
        throw InputError("tuning.newton_min_rows", "value " + std::to_string(tuning.newton_min_rows) + " must be >= 0");
    if (tuning.max_border_rows < 0)
        throw InputError("tuning.max_border_rows", "value " + std::to_string(tuning.max_border_rows) + " must be >= 0");
    impl_->tuning = tuning;
    if (options.kind != SolverKind::exact)
        throw InputError("solver.kind", std::string("value '") + to_string(options.kind) +
                                            "' is not available on the sparse contact path: it has the exact "
                                            "(active-set) solver only");
    impl_->options = options;
}

SparseContactSolver::~SparseContactSolver() = default;

const Eigen::VectorXd& SparseContactSolver::relative_positions() const { return impl_->s; }
const Eigen::VectorXd& SparseContactSolver::compliance_diagonal() const { return impl_->diag; }

SolveResult SparseContactSolver::solve(const SparseContactProblem& problem, Eigen::VectorXd& p, Eigen::VectorXd& z,
                                       bool structure_unchanged) {
    Impl& im = *impl_;
    const int m = problem.size();
    const int np = static_cast<int>(problem.pairs.size());
    const bool known = im.laws.q.size() == m && static_cast<int>(im.laws.pairs.size()) == np && im.K.rows() == problem.K.rows() &&
                       im.G.rows() == problem.G.rows() && im.G.cols() == problem.G.cols();
    if (!known || (!structure_unchanged && (!same_matrix(problem.K, im.K) || !same_matrix(problem.G, im.G) ||
                                            !same_laws(im.laws.pairs, problem.pairs))))
        im.reset_structure(problem);
    else if (problem.b.size() != problem.K.rows() || problem.d.size() != m)
        problem.validate();  // throws InputError naming the field
    im.laws.tau_rule = problem.tau_rule;
    im.laws.tau_previous_n = problem.tau_previous_n;
    if (static_cast<int>(im.modes.nmode.size()) != np) {
        if (p.size() != m) p = Eigen::VectorXd::Zero(m);
        im.modes.init(im.laws, p, im.positions_of(problem, p, z));
    }
    SolveResult r;
    im.updates = 0;
    bool singular = false;
    const Eigen::VectorXd p_start = p;
    try {
        // 1. From the previous step's modes: most steps end here in one pass.
        if (!im.tuning.newton_first)
            r.converged = im.passes(problem.b, problem.d, p, z, im.options.max_active_set_iterations, r);
        // 2a. A transition the passes do not settle: the semismooth Newton method on the
        //     natural map from the previous step's forces, extrapolated (for the first
        //     step: the stepper's start), then the active-set passes from its modes
        //     (one pass, normally: they re-solve its last set of modes and find no violation,
        //     so the answer is the exact solver's linear solution of those modes). If it
        //     fails, the smoothing Newton method from its best iterate (then from the step's
        //     start), then the passes from its modes; if that fails too, the continuation on
        //     the offsets (continuation()).
        const TransitionMethod tm = im.tuning.transition;
        if (!r.converged && tm != TransitionMethod::tresca && (m >= im.tuning.newton_min_rows || im.tuning.newton_first)) {
            const Eigen::VectorXd p_passes = p;
            const std::vector<signed char> nmode_passes = im.modes.nmode, tmode_passes = im.modes.tmode;
            if (tm == TransitionMethod::newton || tm == TransitionMethod::semismooth) {
                // the start: the previous step's forces extrapolated linearly from the two solves
                // before, when the warm start is the last solve's answer (measured, 10 x 100
                // friction: 14.4 -> 9.5 Newton iterations per step on the graduated spring, 14.2 ->
                // 11.1 on identical leaves, BENCHMARKS.md); the passes above keep the previous
                // modes (modes read from the extrapolation cost more: 27.7 iterations per step)
                const bool extrapolate =
                    im.previous_p.size() == m && im.last_p.size() == m && p_start == im.last_p;
                p = extrapolate ? Eigen::VectorXd(2.0 * im.last_p - im.previous_p) : p_start;
                im.s = im.positions_of(problem, p, z);
                if (im.semismooth_newton(problem.b, problem.d, p, z, r))
                    r.converged = im.passes(problem.b, problem.d, p, z, im.options.max_active_set_iterations, r);
            }
            // the smoothing method from the semismooth method's best iterate (measured on the
            // graduated 10-leaf spring, 10 x 100, 100 steps: 3.2 s instead of 10.2 s from the
            // start, BENCHMARKS.md), and if that or the passes after it fail, from the start
            const bool smoothing = tm == TransitionMethod::newton || tm == TransitionMethod::smoothing;
            const bool from_best = tm == TransitionMethod::newton && im.best_p.size() == m;
            for (int attempt = from_best ? 0 : 1; smoothing && attempt < 2 && !r.converged; ++attempt) {
                p = attempt == 0 ? im.best_p : p_start;
                im.s = im.positions_of(problem, p, z);
                if (im.smoothing_newton(problem.d, p, z, r))
                    r.converged = im.passes(problem.b, problem.d, p, z, im.options.max_active_set_iterations, r);
            }
            // then the continuation on the offsets from the step's start (2-4 sub-steps where the
            // Newton methods stall from it, measured on 10 identical leaves x 100 elements)
            if (!r.converged && (tm == TransitionMethod::newton || tm == TransitionMethod::continuation)) {
                p = p_start;
                r.converged = im.continuation(problem.b, problem.d, p, z, r);
            }
            if (!r.converged) {  // the Tresca fixed point below starts where the passes ended
                p = p_passes;
                im.modes.nmode = nmode_passes;
                im.modes.tmode = tmode_passes;
            }
        }
        // 2b. Otherwise (or if it failed): the Tresca fixed point, then the coupled
        //    Coulomb problem from its modes; if that polish fails, the settled fixed point
        //    (Coulomb to within kAccept x tolerance) is taken and flagged, as in the dense solver.
        if (!r.converged) {
            const bool settled = im.tresca_fixed_point(problem.b, problem.d, p, z, r);
            if (!settled) im.modes.init(im.laws, p, im.positions_of(problem, p, z));
            const Eigen::VectorXd p_tresca = p;
            r.converged = im.passes(problem.b, problem.d, p, z, im.options.max_active_set_iterations, r);
            if (!r.converged && settled) {
                p = p_tresca;
                im.s = im.positions_of(problem, p, z);
                r.converged = true;
                r.fell_back = true;
            }
        }
    } catch (const SingularModes&) {
        singular = true;  // a set of modes with dependent held rows: leave it to the dense solver
        im.lu_key.clear();
    }
    if (!r.converged) {
        // 3. Last resort for problems small enough: the dense problem and the dense exact
        //    solver (Tresca fixed point, Gauss-Seidel). O(m^2) memory; reported.
        if (m > kDenseFallbackMaxRows) {
            p = p_start;
            r.message = std::string("sparse path: the active-set passes ") +
                        (singular ? "met a singular set of modes" : "and the Tresca fixed point did not settle") +
                        "; the dense fallback is not tried for " + std::to_string(m) + " > " +
                        std::to_string(kDenseFallbackMaxRows) + " contact rows";
            im.s = im.positions_of(problem, p, z);
            r.residual_m = error_vector(im.laws, p, im.s).norm();
            return r;
        }
        const ContactProblem dense = problem.to_dense();
        SolveResult d = make_solver(im.options)->solve(dense, p);
        r.iterations += d.iterations;
        r.factorizations += d.factorizations;
        r.tresca_iterations += d.tresca_iterations;
        r.fell_back = true;
        r.converged = d.converged;
        if (!d.converged)
            r.message = std::string("sparse path: the active-set passes ") +
                        (singular ? "met a singular set of modes" : "did not settle") +
                        " and the dense fallback failed: " + d.message;
        im.s = im.positions_of(problem, p, z);
        im.modes.init(im.laws, p, im.s);
    }
    r.updates = im.updates;
    detail::residual_norms(im.laws, im.diag, p, im.s, r.residual_m, r.natural_residual_m);
    if (r.converged && !(r.residual_m < im.options.tolerance_m)) {
        r.converged = false;
        r.message = "sparse path (active set) ended with ||v|| = " + format_value(r.residual_m) +
                    " m above the tolerance " + format_value(im.options.tolerance_m) + " m (natural-map residual " +
                    format_value(r.natural_residual_m) + " m)";
    }
    if (r.converged) {
        im.previous_p = im.last_p;
        im.last_p = p;
    }
    return r;
}

}  // namespace stackbeam
