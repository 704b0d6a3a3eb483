// The linear problem of a set of modes on the sparse stiffness (mode_solver.hpp).
//
// Why these ways:
//  - The factorisation depends only on the modes; it is kept and reused while they stay,
//    like the dense solver's LU. Within one set of modes the solution is affine in the
//    right-hand side; on the closed-form stepper only b (the rigid body's load, one entry)
//    changes from step to step, and e, d_S only when the modes or anchors do. So two
//    back-solves per set of modes ({unit b entry} and {e, d_S}) are cached and a step whose
//    modes stay costs O(n) (a linear combination, one product with G), not a back-solve.
//  - The saddle-point system is not symmetric when a slip row is coupled to its normal
//    force, and it is indefinite, so it is factorised by a sparse LU (COLAMD ordering: no
//    extra package) when many rows are held (bonded and frictionless runs: thousands).
//  - Few held rows (the usual situation of friction runs on identical leaves: most pairs
//    open, the clamps held): the dense Schur complement of the held rows on K's Cholesky
//    factor, a new set of modes costing the solves of the rows new to the column cache and
//    a small dense LU.
//  - Held sets near the last sparse LU's (e.g. the box QP's primal active-set iterations,
//    one row per iteration): the LU bordered by the changed rows.
#include "contact/sparse/linear/mode_solver.hpp"

#include <algorithm>
#include <utility>

#include "contact/sparse/linear/mode_solver_common.hpp"
#include "contact/sparse/linear/selected_inverse.hpp"
#include "stackbeam/errors.hpp"

namespace stackbeam::detail::sparse {

using modes::ModeLinearization;

#ifndef STACKBEAM_HAVE_CHOLMOD
// a build without CHOLMOD: no primal route (held sets above the Schur way's limit take the sparse LU)
bool primal_route_built() { return false; }
std::shared_ptr<PrimalSolver> make_primal_solver(PrimalOrdering) { return nullptr; }
#endif

namespace {
// the primal route takes a held set with at most this many held rigid rows (each one a
// column of its Schur complement, solved with the factor at every new set)
constexpr int kPrimalMaxRigidRows = 200;
}  // namespace

std::vector<int> layer_dofs(const SpMat& K, const SpMat& G) {
    std::vector<int> dof(static_cast<std::size_t>(G.rows()), -1);
    for (int j = 0; j < static_cast<int>(K.cols()); ++j) {
        bool diag_only = true;
        double kjj = 0.0;
        for (SpMat::InnerIterator it(K, j); it; ++it) {
            if (it.row() != j && it.value() != 0.0) diag_only = false;
            if (it.row() == j) kjj = it.value();
        }
        int row = -1, count = 0;
        for (SpMat::InnerIterator it(G, j); it; ++it)
            if (it.value() != 0.0) {
                row = static_cast<int>(it.row());
                ++count;
            }
        if (diag_only && kjj > 0.0 && count == 1 && dof[static_cast<std::size_t>(row)] < 0)
            dof[static_cast<std::size_t>(row)] = j;
    }
    return dof;
}

void SparseStiffness::build(const SpMat& K_, const SpMat& G_) {
    K = K_;
    G = G_;
    K.makeCompressed();
    G.makeCompressed();
    k_llt.compute(K);
    if (k_llt.info() != Eigen::Success) throw InputError("problem.K", "is not positive definite");
    const int m = rows();
    diag = selected_compliance_diagonal(K, G, k_llt);
    g_norm_inf = 0.0;
    const SpMat absG = G.cwiseAbs();
    const Eigen::VectorXd row_sums = absG * Eigen::VectorXd::Ones(G.cols());
    if (m > 0) g_norm_inf = row_sums.maxCoeff();
    dz = K.diagonal().cwiseSqrt().cwiseInverse();
    Gt_scaled = dz.asDiagonal() * SpMat(G.transpose());
    Gt_scaled.makeCompressed();
    Gt = SpMat(G.transpose());
    Grow = G;
    row_h.resize(m);
    for (int i = 0; i < m; ++i) {
        const double h = Gt_scaled.col(i).norm();
        row_h[i] = h > 0.0 ? h : 1.0;
    }
}

Eigen::VectorXd SparseStiffness::positions(const Eigen::VectorXd& b, const Eigen::VectorXd& d,
                                           const Eigen::VectorXd& p, Eigen::VectorXd& z) const {
    z = k_llt.solve(b + Gt * p);
    return Grow * z - d;
}

double SparseStiffness::roundoff(const Eigen::VectorXd& d, const Eigen::VectorXd& z) const {
    return 1e-13 * (d.lpNorm<Eigen::Infinity>() + g_norm_inf * z.lpNorm<Eigen::Infinity>());
}

void SparseStiffness::append_scaled_K(std::vector<Eigen::Triplet<double>>& t) const {
    for (int j = 0; j < K.outerSize(); ++j)
        for (SpMat::InnerIterator it(K, j); it; ++it)
            t.emplace_back(it.row(), it.col(), it.value() * dz[it.row()] * dz[it.col()]);
}

void ModeSolver::reset(const SpMat& K, const SpMat& G, const std::vector<std::pair<int, int>>& couplings) {
    st_.build(K, G);
    const auto m = static_cast<std::size_t>(st_.rows());
    lu_key_.clear();
    lu_ok = false;
    const_ok = false;
    unit_dof = -1;
    xcol.assign(m, Eigen::VectorXd());
    xcol_count = 0;
    bcol.assign(m, Eigen::VectorXd());
    bcol_count = 0;
    base_valid = false;
    border_active = false;
    base_schur = false;
    wb_active = false;
    l_nonzeros = static_cast<double>(st_.k_llt.matrixL().nestedExpression().nonZeros());
    lu_primal = false;
    fixed_.reset();
    if (tuning_.fixed_pattern != FixedPatternLu::off) {
        fixed_ = std::make_unique<FixedSaddle>(tuning_.fixed_pattern, tuning_.residual_refactor_check);
        fixed_->reset(st_, couplings);
        const std::vector<int> dof = layer_dofs(st_.K, st_.G);
        layer_row_.assign(m, 0);
        for (std::size_t r = 0; r < m; ++r) layer_row_[r] = dof[r] >= 0 ? 1 : 0;
    }
    primal_.reset();
    if (tuning_.primal_min_rows > 0 && primal_route_built()) {
        primal_ = make_primal_solver(tuning_.primal_ordering);
        primal_->reset(st_);
        if (primal_->layer_rows() == 0) primal_.reset();
    }
}

void ModeSolver::accept() {
    if (lu_primal && !lu_key_.empty()) primal_->refresh();
    if (!lu_schur || !wb_active || lu_key_.empty() || border_active) return;
    dlu.compute(Mschur);
    wb_active = false;
    if (Mschur.rows() == 0 || dlu.rcond() > 1e-14) make_schur_base();
    else base_schur = false;
}

/// The linear problem of `lin` (held rows S with s = 0, fixed forces e, slip coupling),
/// factorised unless `key` names the current factorisation. Two ways, by the number of
/// held rows:
///  - up to tuning_.schur_max_rows: the Schur complement on the held rows, M p_S = d_S - G_S z0,
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
int ModeSolver::solve(const ModeLinearization& lin, const std::vector<signed char>& key, const Eigen::VectorXd& b,
                      const Eigen::VectorXd& d, Eigen::VectorXd& p, Eigen::VectorXd& z) {
    return counted(lin.S.size(), [&]() { return solve_key(lin, key, b, d, p, z); });
}

/// One call of the solver (solve_key, solve_block) under the trace's route statistics
/// (set_route_stats): its route, CPU time, held rows and KLU pivotings; without them just the call.
int ModeSolver::counted(std::size_t held_rows, const std::function<int()>& call) {
    if (!routes_) return call();
    const double t0 = thread_cpu_s();
    const long pivoted0 = fixed_ ? fixed_->lu().pivoted : 0;
    route_ = route_cached;
    const int f = call();
    routes_->count[route_] += 1;
    routes_->seconds[route_] += thread_cpu_s() - t0;
    routes_->held[route_] += static_cast<double>(held_rows);
    if (fixed_) routes_->fixed_pivoted += fixed_->lu().pivoted - pivoted0;
    return f;
}

int ModeSolver::solve_key(const ModeLinearization& lin, const std::vector<signed char>& key, const Eigen::VectorXd& b,
                          const Eigen::VectorXd& d, Eigen::VectorXd& p, Eigen::VectorXd& z) {
    const int n = static_cast<int>(st_.K.rows());
    const auto& S = lin.S;
    const int ms = static_cast<int>(S.size());
    const int factorised = make_current(lin, key);
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
        direct_solve(lin, b + st_.G.transpose() * lin.e, dS, pS, z);
        all_forces(lin, pS, p);
        return factorised;
    }
    if (!const_ok || const_e != lin.e || const_dS != dS) {
        direct_solve(lin, st_.G.transpose() * lin.e, dS, pc, zc);
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
    all_forces(lin, pS, p);
    return factorised;
}

/// Makes lin's factorisation (named by key) current: reused, a bordered update of the
/// last sparse LU (counted in updates()), or factorised (returns 1). Throws SingularModes
/// if the held rows are dependent.
int ModeSolver::make_current(const ModeLinearization& lin, const std::vector<signed char>& key) {
    const int m = st_.rows();
    const auto& S = lin.S;
    const int ms = static_cast<int>(S.size());
    pos.assign(m, -1);
    for (int i = 0; i < ms; ++i) pos[S[i]] = i;
    int factorised = 0;
    if (key != lu_key_ && try_border(lin)) {
        ++updates_;
        route_ = route_border;
        lu_key_ = key;
        key_uses = 0;
        const_ok = false;
        unit_dof = -1;
    } else if (key != lu_key_) {
        border_active = false;
        wb_active = false;
        factorised = 1;
        lu_primal = false;
        if (primal_ && ms >= tuning_.primal_min_rows) {
            // the primal route: at least one held layer row, and few enough held rigid rows
            // for their Schur complement (kPrimalMaxRigidRows solves per set)
            int layer = 0;
            for (int r : S) layer += primal_->is_layer(r) ? 1 : 0;
            lu_primal = layer > 0 && ms - layer <= kPrimalMaxRigidRows;
        }
        lu_schur = !lu_primal && ms <= tuning_.schur_max_rows;
        if (lu_primal) {
            const long before = primal_->stats().factorisations;
            lu_ok = primal_->factor(lin, pos);
            factorised = primal_->stats().factorisations > before ? 1 : 0;
            if (factorised == 0) ++updates_;
            route_ = route_primal;
        } else if (lu_schur) {
            // a fresh dense Schur LU only up to schur_fresh_max_rows held rows (docs/decisions/038):
            // a larger set that no update of the base reaches takes the sparse LU
            const bool fresh = tuning_.schur_fresh_max_rows < 0 || ms <= tuning_.schur_fresh_max_rows;
            factorised = factor_schur_update(lin, fresh);
            if (factorised < 0 && !fresh) {
                lu_schur = false;
                factorised = 1;
            } else if (factorised < 0) {
                factor_schur(lin);
                factorised = 1;
            } else if (factorised == 0) {
                ++updates_;
            }
            if (lu_schur) route_ = factorised == 1 ? route_schur_lu : wb_active ? route_schur_update : route_schur_base;
        }
        if (!lu_primal && !lu_schur) {
            factor_lu(lin);
            route_ = lu_fixed ? route_fixed_lu : route_lu;
        }
        lu_key_ = key;
        key_uses = 0;
        const_ok = false;
        unit_dof = -1;
    }
    if (!lu_ok) throw SingularModes{};
    return factorised;
}

int ModeSolver::solve_block(const ModeLinearization& lin, const std::vector<signed char>& key, const Eigen::MatrixXd& B,
                            const Eigen::MatrixXd& D, Eigen::MatrixXd& P, Eigen::MatrixXd& Z) {
    return counted(lin.S.size(), [&]() { return solve_block_key(lin, key, B, D, P, Z); });
}

int ModeSolver::solve_block_key(const ModeLinearization& lin, const std::vector<signed char>& key,
                                const Eigen::MatrixXd& B, const Eigen::MatrixXd& D, Eigen::MatrixXd& P,
                                Eigen::MatrixXd& Z) {
    const int factorised = make_current(lin, key);
    const int n = st_.dofs(), m = st_.rows(), ms = static_cast<int>(lin.S.size()), k = static_cast<int>(B.cols());
    P.resize(m, k);
    Z.resize(n, k);
    Eigen::MatrixXd F = B;  // the loads b + G^T e
    F.colwise() += st_.Gt * lin.e;
    Eigen::MatrixXd DS(ms, k);
    for (int i = 0; i < ms; ++i) DS.row(i) = D.row(lin.S[static_cast<std::size_t>(i)]);
    Eigen::VectorXd pS, p, z;
    if (border_active || lu_schur || lu_primal) {  // one solve per column
        for (int j = 0; j < k; ++j) {
            if (border_active) {
                border_solve(lin, B.col(j), D.col(j), p, z);
            } else {
                direct_solve(lin, F.col(j), DS.col(j), pS, z);
                all_forces(lin, pS, p);
            }
            P.col(j) = p;
            Z.col(j) = z;
        }
    } else {  // the sparse LU: one multi-column solve, refined
        Eigen::MatrixXd R(n + ms, k);
        R.topRows(n) = st_.dz.asDiagonal() * F;
        R.bottomRows(ms) = row_scale.asDiagonal() * DS;
        const Eigen::MatrixXd X = refined_solve(R);
        Z = st_.dz.asDiagonal() * X.topRows(n);
        for (int j = 0; j < k; ++j) {
            pS = row_scale.cwiseProduct(X.col(j).tail(ms));
            all_forces(lin, pS, p);
            P.col(j) = p;
        }
    }
    return factorised;
}

}  // namespace stackbeam::detail::sparse
