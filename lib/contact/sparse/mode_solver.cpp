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
#include "contact/sparse/mode_solver.hpp"

#include <algorithm>
#include <utility>

#include "contact/sparse/selected_inverse.hpp"
#include "stackbeam/errors.hpp"

namespace stackbeam::detail::sparse {

using modes::ModeLinearization;

#ifndef STACKBEAM_HAVE_CHOLMOD
// a build without CHOLMOD: no primal route (held sets above the Schur way's limit take the sparse LU)
bool primal_route_built() { return false; }
std::shared_ptr<PrimalSolver> make_primal_solver(PrimalOrdering) { return nullptr; }
#endif

namespace {
// cached columns K^-1 g_i^T: at most this many doubles (80 MB)
constexpr double kColumnCacheDoubles = 1e7;
// the Schur way's low-rank update: not below this many held rows (a small dense LU is
// cheaper than the update's bookkeeping), and only while the update's rank k (changed
// rows plus changed columns) is at most 1/kUpdateRankFraction of the held rows (its cost,
// k base solves and a k x k LU, against the LU's ms^3 / 3; docs/decisions/020)
constexpr int kMinUpdateRows = 24;
constexpr int kUpdateRankFraction = 4;
/// Whether a held set of ms rows, the update's rank k against a base of nb rows, is
/// factorised afresh rather than updated (the update's cost against a fresh LU's).
bool fresh_schur_lu(int ms, int nb, int k) { return ms < kMinUpdateRows || nb == 0 || kUpdateRankFraction * k > ms; }
// the primal route takes a held set with at most this many held rigid rows (each one a
// column of its Schur complement, solved with the factor at every new set)
constexpr int kPrimalMaxRigidRows = 200;

/// The slip couplings of lin's held rows as columns of the Schur complement: ct[c] the slip
/// row coupled to held row S[c] (or -1), cc[c] its coefficient. False if a held row carries
/// more than one coupling (one slip row per pair: not met; the caller then rebuilds).
bool column_couplings(const ModeLinearization& lin, const std::vector<int>& pos, std::vector<int>& ct,
                      std::vector<double>& cc) {
    ct.assign(lin.S.size(), -1);
    cc.assign(lin.S.size(), 0.0);
    for (std::size_t a = 0; a < lin.coupled.size(); ++a) {
        const int c = pos[static_cast<std::size_t>(lin.coupled[a].second)];
        if (c < 0) continue;
        if (ct[static_cast<std::size_t>(c)] >= 0) return false;
        ct[static_cast<std::size_t>(c)] = lin.coupled[a].first;
        cc[static_cast<std::size_t>(c)] = lin.coef[a];
    }
    return true;
}

/// Each slipping row's force from its pair's normal force (held or fixed): p_t += coef p_n.
void add_slip_couplings(const ModeLinearization& lin, Eigen::Ref<Eigen::VectorXd> p) {
    for (std::size_t a = 0; a < lin.coupled.size(); ++a) p[lin.coupled[a].first] += lin.coef[a] * p[lin.coupled[a].second];
}

/// Every contact row's force [N] from the held rows' pS: the fixed forces e, pS on the held
/// rows, the slip couplings.
void all_forces(const ModeLinearization& lin, const Eigen::VectorXd& pS, Eigen::VectorXd& p) {
    p = lin.e;
    for (std::size_t i = 0; i < lin.S.size(); ++i) p[lin.S[i]] = pS[static_cast<Eigen::Index>(i)];
    add_slip_couplings(lin, p);
}
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

/// The scaled saddle-point system of lin's held set, factorised by the sparse LU: its own
/// system ordered from scratch, or the fixed-pattern one (fixed_saddle.hpp) ordered once.
void ModeSolver::factor_lu(const ModeLinearization& lin) {
    const int n = static_cast<int>(st_.K.rows());
    const auto& S = lin.S;
    const int ms = static_cast<int>(S.size());
    row_scale.resize(ms);
    for (int i = 0; i < ms; ++i) row_scale[i] = 1.0 / st_.row_h[S[i]];
    int rigid = 0;
    if (fixed_)
        for (int r : S) rigid += layer_row_[static_cast<std::size_t>(r)] ? 0 : 1;
    lu_fixed = fixed_ && rigid <= tuning_.fixed_max_rigid_rows;
    if (lu_fixed) {
        lu_ok = fixed_->factor(lin, pos, row_scale);
    } else {
        // [Dz K Dz, -Dz (G_S^T + G_slip^T D) R; R G_S Dz, 0]
        std::vector<Eigen::Triplet<double>> t;
        t.reserve(static_cast<std::size_t>(st_.K.nonZeros() + 4 * st_.G.nonZeros()));
        st_.append_scaled_K(t);
        for (int i = 0; i < ms; ++i)
            for (SpMat::InnerIterator it(st_.Gt_scaled, S[i]); it; ++it) {
                t.emplace_back(it.row(), n + i, -it.value() * row_scale[i]);
                t.emplace_back(n + i, it.row(), it.value() * row_scale[i]);
            }
        for (std::size_t a = 0; a < lin.coupled.size(); ++a) {
            const int col = pos[lin.coupled[a].second];
            if (col < 0) continue;  // the normal row is not held: its force is fixed (e)
            for (SpMat::InnerIterator it(st_.Gt_scaled, lin.coupled[a].first); it; ++it)
                t.emplace_back(it.row(), n + col, -lin.coef[a] * it.value() * row_scale[col]);
        }
        A.resize(n + ms, n + ms);
        A.setFromTriplets(t.begin(), t.end());
        A.makeCompressed();
        lu.compute(A);
        lu_ok = lu.info() == Eigen::Success;
    }
    base_valid = lu_ok && lin.coupled.empty();
    base_S = S;
    base_pos = pos;
    for (auto& c : bcol) c.resize(0);
    bcol_count = 0;
}

/// (p_S, z) of lin's held set for the load f = b + G^T e and the held rows' offsets dS with
/// the current factorisation (Schur, primal or sparse LU). A primal solve that does not
/// converge gives the set to the sparse LU.
void ModeSolver::direct_solve(const ModeLinearization& lin, const Eigen::VectorXd& f, const Eigen::VectorXd& dS,
                              Eigen::VectorXd& pS, Eigen::VectorXd& zf) {
    if (lu_schur) {
        schur_solve(lin, st_.k_llt.solve(f), dS, pS, zf);
        return;
    }
    if (lu_primal) {
        if (primal_->solve(lin, pos, f, dS, pS, zf)) return;
        lu_primal = false;
        factor_lu(lin);
        if (!lu_ok) throw SingularModes{};
    }
    const int n = static_cast<int>(st_.K.rows()), ms = static_cast<int>(lin.S.size());
    rhs.resize(n + ms);
    rhs.head(n) = st_.dz.cwiseProduct(f);
    rhs.tail(ms) = row_scale.cwiseProduct(dS);
    x = refined_solve(rhs);
    zf = st_.dz.cwiseProduct(x.head(n));
    pS = row_scale.cwiseProduct(x.tail(ms));
}

bool ModeSolver::unit_solves(const ModeLinearization& lin, const std::vector<int>& rows, bool refine, Eigen::MatrixXd& P,
                             Eigen::MatrixXd& Z) {
    if (border_active || lu_primal || !lu_ok) return false;
    const int n = st_.dofs(), m = st_.rows(), ms = static_cast<int>(lin.S.size()), k = static_cast<int>(rows.size());
    pos.assign(m, -1);
    for (int i = 0; i < ms; ++i) pos[lin.S[static_cast<std::size_t>(i)]] = i;
    Z.resize(n, k);
    Eigen::MatrixXd PS(ms, k);
    if (lu_schur) {
        // the force columns' K^-1 g_r^T: the cached columns where there are (ensure_columns'
        // cache), the others through K's factor together; then each column's held forces by
        // the (dense, refined) Schur solve
        Eigen::MatrixXd Z0 = Eigen::MatrixXd::Zero(n, k);
        std::vector<int> solved;
        for (int j = 0; j < k; ++j) {
            const int r = rows[static_cast<std::size_t>(j)];
            if (pos[r] >= 0) continue;
            if (xcol[static_cast<std::size_t>(r)].size() != 0) {
                Z0.col(j) = xcol[static_cast<std::size_t>(r)];
                continue;
            }
            for (SpMat::InnerIterator it(st_.Gt, r); it; ++it) Z0(it.row(), j) = it.value();
            solved.push_back(j);
        }
        if (!solved.empty()) {
            Eigen::MatrixXd Y(n, static_cast<Eigen::Index>(solved.size()));
            for (std::size_t c = 0; c < solved.size(); ++c) Y.col(static_cast<Eigen::Index>(c)) = Z0.col(solved[c]);
            Y = st_.k_llt.solve(Y).eval();
            for (std::size_t c = 0; c < solved.size(); ++c) Z0.col(solved[c]) = Y.col(static_cast<Eigen::Index>(c));
        }
        Eigen::VectorXd target(ms), pS, zf;
        for (int j = 0; j < k; ++j) {
            const int i = pos[rows[static_cast<std::size_t>(j)]];
            target.setZero();
            if (i >= 0) target[i] = 1.0;
            schur_solve(lin, Z0.col(j), target, pS, zf);
            Z.col(j) = zf;
            PS.col(j) = pS;
        }
    } else {
        // solved in Z itself (n + ms rows: the displacements on top, scaled in place; the held
        // forces below, copied out): no second n x k matrix and copy per call
        // (on the fixed pattern without refinement: the right-hand sides by their nonzeros, no
        // zeroed n + ms x k matrix)
        Eigen::MatrixXd& R = Z;
        SparseColumns B;
        for (int j = 0; j < k; ++j) {
            const int r = rows[static_cast<std::size_t>(j)], i = pos[r];
            if (i >= 0) {
                B.add(n + i, row_scale[i]);
            } else {
                for (SpMat::InnerIterator it(st_.Gt, r); it; ++it) B.add(static_cast<int>(it.row()), st_.dz[it.row()] * it.value());
            }
            B.end_column();
        }
        if (lu_fixed && !refine) {
            fixed_->solve_unit_columns(B, R);
        } else {
            R = B.dense(n + ms);
            if (lu_fixed) fixed_->solve_in_place(R, refine);  // (no copy of the n + ms rows per column)
            else R = refine ? refined_solve(R) : Eigen::MatrixXd(lu.solve(R));
        }
        PS = row_scale.asDiagonal() * R.bottomRows(ms);
        R.topRows(n).array().colwise() *= st_.dz.array();  // (the same products as dz.asDiagonal() * R)
    }
    P.setZero(m, k);
    for (int j = 0; j < k; ++j) {
        const int r = rows[static_cast<std::size_t>(j)];
        if (pos[r] < 0) P(r, j) = 1.0;
        for (int i = 0; i < ms; ++i) P(lin.S[static_cast<std::size_t>(i)], j) = PS(i, j);
        add_slip_couplings(lin, P.col(j));
    }
    return true;
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
/// than tuning_.max_border_rows rows differ.
bool ModeSolver::try_border(const ModeLinearization& lin) {
    const auto& S = lin.S;
    // on KLU's fixed pattern a new factorisation is a refactorisation (about 10 ms at
    // 10 x 400) and each changed row a solve of the whole fixed system: a smaller limit
    // (measured, identical 10 x 400: 150 rows 243, none 194 CPU s per simulated second;
    // docs/decisions/035)
    const int limit = lu_fixed && tuning_.fixed_max_border_rows >= 0
                          ? std::min(tuning_.max_border_rows, tuning_.fixed_max_border_rows)
                          : tuning_.max_border_rows;
    if (limit == 0 || !base_valid || !lin.coupled.empty() || static_cast<int>(S.size()) <= tuning_.schur_max_rows)
        return false;
    std::vector<int> rows;
    for (int i : base_S)
        if (pos[i] < 0) rows.push_back(i);
    const int nr = static_cast<int>(rows.size());
    if (nr > limit) return false;
    for (int i : S)
        if (base_pos[i] < 0) rows.push_back(i);
    if (static_cast<int>(rows.size()) > limit) return false;
    border_rows = std::move(rows);
    border_nr = nr;
    border_active = true;
    lu_schur = false;
    lu_ok = true;
    return true;
}

/// Bordered solve of the current held set (see try_border) for load b and offsets d.
void ModeSolver::border_solve(const ModeLinearization& lin, const Eigen::VectorXd& b, const Eigen::VectorXd& d,
                  Eigen::VectorXd& p, Eigen::VectorXd& z) {
    const int n = static_cast<int>(st_.K.rows());
    const int ms0 = static_cast<int>(base_S.size());
    const int k = static_cast<int>(border_rows.size());
    auto scale_of = [&](int a) { return 1.0 / st_.row_h[a]; };
    // U y added to v
    auto add_U = [&](const Eigen::VectorXd& y, Eigen::VectorXd& v) {
        for (int j = 0; j < k; ++j) {
            const int i = border_rows[static_cast<std::size_t>(j)];
            if (j < border_nr) v[n + base_pos[i]] += y[j];
            else v.head(n) -= (scale_of(i) * y[j]) * st_.Gt_scaled.col(i);
        }
    };
    auto apply_Wt = [&](const Eigen::VectorXd& v) {
        Eigen::VectorXd out(k);
        for (int j = 0; j < k; ++j) {
            const int i = border_rows[static_cast<std::size_t>(j)];
            out[j] = j < border_nr ? v[n + base_pos[i]] : scale_of(i) * st_.Gt_scaled.col(i).dot(v.head(n));
        }
        return out;
    };
    // columns A0^-1 U_j (cached per row while the base stays; at most 4 x max_border_rows
    // of them, (n + ms0) doubles each: the cache is dropped past that)
    if (bcol_count > 4 * static_cast<std::size_t>(tuning_.max_border_rows)) {
        for (auto& c : bcol) c.resize(0);
        bcol_count = 0;
    }
    auto border_column = [&](int j, Eigen::Ref<Eigen::VectorXd> u) {  // U_j
        const int i = border_rows[static_cast<std::size_t>(j)];
        u.setZero();
        if (j < border_nr) u[n + base_pos[i]] = 1.0;
        else u.head(n) = -scale_of(i) * st_.Gt_scaled.col(i);
    };
    if (tuning_.block_border_solves) {
        // the columns not cached, in blocks: one multi-column solve (and refinement) each,
        // one pass over the LU's factors per few columns instead of per column
        std::vector<int> missing;
        for (int j = 0; j < k; ++j)
            if (bcol[static_cast<std::size_t>(border_rows[static_cast<std::size_t>(j)])].size() == 0) missing.push_back(j);
        constexpr std::size_t kBlock = 32;
        Eigen::MatrixXd Ublk;
        for (std::size_t j0 = 0; j0 < missing.size(); j0 += kBlock) {
            const auto nb = static_cast<Eigen::Index>(std::min(kBlock, missing.size() - j0));
            Ublk.resize(n + ms0, nb);
            for (Eigen::Index c = 0; c < nb; ++c) border_column(missing[j0 + static_cast<std::size_t>(c)], Ublk.col(c));
            const Eigen::MatrixXd Y = refined_solve(Ublk);
            for (Eigen::Index c = 0; c < nb; ++c) {
                bcol[static_cast<std::size_t>(border_rows[static_cast<std::size_t>(missing[j0 + static_cast<std::size_t>(c)])])] = Y.col(c);
                ++bcol_count;
            }
        }
    }
    Eigen::MatrixXd C(k, k);
    for (int j = 0; j < k; ++j) {
        const int i = border_rows[static_cast<std::size_t>(j)];
        Eigen::VectorXd& col = bcol[static_cast<std::size_t>(i)];
        if (col.size() == 0) {
            Eigen::VectorXd u(n + ms0);
            border_column(j, u);
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
    f.head(n) = st_.dz.cwiseProduct(b + st_.G.transpose() * ep);
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
        Eigen::VectorXd rf = f - apply_A(xx);
        Eigen::VectorXd uy = Eigen::VectorXd::Zero(n + ms0);
        add_U(yy, uy);
        rf -= uy;
        const Eigen::VectorXd rg = g - apply_Wt(xx);
        solve_bordered(rf, rg, dx, dy);
        xx += dx;
        yy += dy;
    }
    z = st_.dz.cwiseProduct(xx.head(n));
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
void ModeSolver::load_solve(const ModeLinearization& lin, const Eigen::VectorXd& f, Eigen::VectorXd& pS,
                Eigen::VectorXd& zf) {
    direct_solve(lin, f, Eigen::VectorXd::Zero(static_cast<Eigen::Index>(lin.S.size())), pS, zf);
}

/// Column K^-1 g_i^T of contact row i [m/N per unit force], cached (solved in blocks
/// for the rows in `rows` not cached yet; when the cache would exceed kColumnCacheDoubles
/// the columns of rows outside `rows` are dropped).
void ModeSolver::ensure_columns(const std::vector<int>& rows) {
    const int n = static_cast<int>(st_.K.rows());
    std::vector<int> missing;
    for (int r : rows)
        if (xcol[static_cast<std::size_t>(r)].size() == 0) missing.push_back(r);
    if (missing.empty()) return;
    if (static_cast<double>(xcol_count + missing.size()) * n > kColumnCacheDoubles) {
        // full: drop the columns of rows outside this set only (the held set of the next
        // key mostly overlaps this one; dropping every column made each new key re-solve
        // all of them: identical 10 x 400 elastic 307 -> 101 s per simulated second)
        std::vector<char> needed(xcol.size(), 0);
        for (int r : rows) needed[static_cast<std::size_t>(r)] = 1;
        for (std::size_t i = 0; i < xcol.size(); ++i)
            if (!needed[i] && xcol[i].size() != 0) {
                xcol[i].resize(0);
                --xcol_count;
            }
    }
    constexpr int kBlock = 32;
    Eigen::MatrixXd Y;
    for (std::size_t j0 = 0; j0 < missing.size(); j0 += kBlock) {
        const int nb = static_cast<int>(std::min<std::size_t>(kBlock, missing.size() - j0));
        Y.setZero(n, nb);
        for (int c = 0; c < nb; ++c)
            for (SpMat::InnerIterator it(st_.Gt, missing[j0 + static_cast<std::size_t>(c)]); it; ++it)
                Y(it.row(), c) = it.value();
        Y = st_.k_llt.solve(Y).eval();
        for (int c = 0; c < nb; ++c) {
            xcol[static_cast<std::size_t>(missing[j0 + static_cast<std::size_t>(c)])] = Y.col(c);
            ++xcol_count;
        }
    }
}

/// The Schur complement M = G_S K^-1 (G_S^T + G_slip^T D) of the held rows, LU-factorised.
void ModeSolver::factor_schur(const ModeLinearization& lin) {
    const auto& S = lin.S;
    const int ms = static_cast<int>(S.size());
    std::vector<int> rows(S);
    for (std::size_t a = 0; a < lin.coupled.size(); ++a)
        if (pos[lin.coupled[a].second] >= 0) rows.push_back(lin.coupled[a].first);
    ensure_columns(rows);
    Eigen::MatrixXd M(ms, ms);
    for (int c = 0; c < ms; ++c) {
        const Eigen::VectorXd& xc = xcol[static_cast<std::size_t>(S[c])];
        for (int r = 0; r < ms; ++r) M(r, c) = st_.row_dot(S[r], xc);
    }
    for (std::size_t a = 0; a < lin.coupled.size(); ++a) {
        const int c = pos[lin.coupled[a].second];
        if (c < 0) continue;
        const Eigen::VectorXd& xt = xcol[static_cast<std::size_t>(lin.coupled[a].first)];
        for (int r = 0; r < ms; ++r) M(r, c) += lin.coef[a] * st_.row_dot(S[r], xt);
    }
    dlu.compute(M);
    // a singular set of modes (dependent held rows) is left to the caller, as with the sparse LU
    lu_ok = ms == 0 || (M.allFinite() && dlu.rcond() > 1e-14);
    Mschur = std::move(M);
    wb_active = false;
    schur_S = S;
    if (tuning_.schur_updates && lu_ok && column_couplings(lin, pos, schur_ct, schur_cc)) make_schur_base();
    else base_schur = false;
}

/// The base of the Schur way's updates: the current held set, whose Schur complement dlu factorises.
void ModeSolver::make_schur_base() {
    bs_S = schur_S;
    bs_ct = schur_ct;
    bs_cc = schur_cc;
    bs_M = Mschur;
    bs_index.assign(static_cast<std::size_t>(st_.rows()), -1);
    for (std::size_t i = 0; i < bs_S.size(); ++i) bs_index[static_cast<std::size_t>(bs_S[i])] = static_cast<int>(i);
    base_schur = true;
}

/// The Schur complement of lin's held set from the base's (copied where a row and a column
/// both stay in the held set and the column's slip coupling is the same, computed where
/// not), and its solve: a low-rank update of the base's dense LU when few rows and columns
/// changed, else a dense LU of its own (which becomes the base). Returns true for an update
/// 0 for an update (or the base's own set again: no factorisation), 1 when it factorised,
/// -1 without doing anything when there is no base or a held row carries two couplings
/// (the caller then calls factor_schur).
///
/// The update (Woodbury's identity on a bordered embedding): on the index set U = base rows
/// plus added rows, the base's matrix is A0 = [M0 0; 0 I]; the new set's is A0 with
///  - each removed base row's equation replaced by p_r = 0 (its force is fixed, in e),
///  - each added row's equation its row of the new M (and p = 0 on removed columns),
///  - each column whose slip coupling changed, and each added column, its new entries in
///    the kept rows;
/// so A = A0 + U V^T with U = [unit columns of the changed rows, the changed columns'
/// differences in the kept rows] and V^T = [the changed rows' differences; unit rows of the
/// changed columns], rank k. With Z = A0^-1 U (k solves with the base's LU) and the
/// capacitance C = I + V^T Z (k x k, dense LU), A^-1 y = A0^-1 y - Z C^-1 V^T A0^-1 y
/// (schur_inverse). The slip coupling mu k_n of a slipping pair stays in these dense
/// entries, exact. Each solve is refined against the explicit new M (schur_solve), and the
/// base is the last set factorised (accept() refreshes it at each accepted step), so
/// updates never compound.
///
/// With may_factorise false (ModeSolverTuning::schur_fresh_max_rows) a set that needs a
/// fresh dense LU returns -1 before anything is computed (the caller takes the sparse LU).
int ModeSolver::factor_schur_update(const ModeLinearization& lin, bool may_factorise) {
    if (!tuning_.schur_updates || !base_schur) return -1;
    const auto& S = lin.S;
    const int ms = static_cast<int>(S.size()), nb = static_cast<int>(bs_S.size());
    std::vector<int> ct;
    std::vector<double> cc;
    if (!column_couplings(lin, pos, ct, cc)) return -1;
    std::vector<int> added, removed;
    std::vector<char> col_new(static_cast<std::size_t>(ms), 0);
    std::vector<int> needed;
    int changed_kept = 0;
    for (int i = 0; i < ms; ++i) {
        const auto ui = static_cast<std::size_t>(i);
        const int j = bs_index[static_cast<std::size_t>(S[ui])];
        if (j < 0) {
            added.push_back(i);
            col_new[ui] = 1;
        } else if (ct[ui] != bs_ct[static_cast<std::size_t>(j)] || cc[ui] != bs_cc[static_cast<std::size_t>(j)]) {
            col_new[ui] = 1;
            ++changed_kept;
        }
        if (col_new[ui]) {
            needed.push_back(S[ui]);
            if (ct[ui] >= 0) needed.push_back(ct[ui]);
        }
    }
    for (int j = 0; j < nb; ++j)
        if (pos[static_cast<std::size_t>(bs_S[static_cast<std::size_t>(j)])] < 0) removed.push_back(j);
    if (!may_factorise) {  // (the rank test of the update below, before its work)
        const int na = static_cast<int>(added.size());
        const int k = static_cast<int>(removed.size()) + 2 * na + changed_kept;
        if (fresh_schur_lu(ms, nb, k)) return -1;
    }
    ensure_columns(needed);
    // g_a K^-1 g_b^T from whichever of the two columns is cached (every entry computed below
    // has one: an added row's, a changed column's or its coupled slip row's)
    auto W = [&](int a, int b) {
        const Eigen::VectorXd& xb = xcol[static_cast<std::size_t>(b)];
        return xb.size() != 0 ? st_.row_dot(a, xb) : st_.row_dot(b, xcol[static_cast<std::size_t>(a)]);
    };
    Eigen::MatrixXd M(ms, ms);
    for (int c = 0; c < ms; ++c) {
        const auto uc = static_cast<std::size_t>(c);
        const int jc = bs_index[static_cast<std::size_t>(S[uc])];
        for (int r = 0; r < ms; ++r) {
            const int jr = bs_index[static_cast<std::size_t>(S[static_cast<std::size_t>(r)])];
            if (!col_new[uc] && jr >= 0) {
                M(r, c) = bs_M(jr, jc);
            } else {
                double v = W(S[static_cast<std::size_t>(r)], S[uc]);
                if (ct[uc] >= 0) v += cc[uc] * W(S[static_cast<std::size_t>(r)], ct[uc]);
                M(r, c) = v;
            }
        }
    }
    Mschur = std::move(M);
    schur_S = S;
    schur_ct = std::move(ct);
    schur_cc = std::move(cc);
    const int na = static_cast<int>(added.size());
    const int k1 = static_cast<int>(removed.size()) + na, k2 = changed_kept + na, k = k1 + k2;
    wb_active = false;
    lu_ok = true;
    if (k == 0 && nb == ms) return 0;  // the base's own set (back to it after a trial): dlu is its LU
    auto factorise = [&] {             // a dense LU of the new M, which becomes the base
        dlu.compute(Mschur);
        lu_ok = ms == 0 || (Mschur.allFinite() && dlu.rcond() > 1e-14);
        if (lu_ok) make_schur_base();
        else base_schur = false;
        return 1;
    };
    if (fresh_schur_lu(ms, nb, k)) return factorise();
    // the bordered embedding (see above)
    const int nu = nb + na;
    wb_nb = nb;
    wb_nu = nu;
    wb_map.assign(static_cast<std::size_t>(ms), -1);
    for (int i = 0; i < ms; ++i) wb_map[static_cast<std::size_t>(i)] = bs_index[static_cast<std::size_t>(S[static_cast<std::size_t>(i)])];
    for (int t = 0; t < na; ++t) wb_map[static_cast<std::size_t>(added[static_cast<std::size_t>(t)])] = nb + t;
    wb_rows.clear();
    wb_cols.clear();
    Eigen::MatrixXd U = Eigen::MatrixXd::Zero(nu, k);
    wb_Drows.setZero(k1, nu);
    int q = 0;
    for (int j : removed) {  // row j of A: e_j^T instead of [M0(j, :) 0]
        wb_rows.push_back(j);
        wb_Drows.row(q).head(nb) = -bs_M.row(j);
        wb_Drows(q, j) += 1.0;
        U(j, q) = 1.0;
        ++q;
    }
    for (int t = 0; t < na; ++t) {  // row nb + t of A: the added row's entries instead of e^T
        const int i = added[static_cast<std::size_t>(t)];
        wb_rows.push_back(nb + t);
        for (int c = 0; c < ms; ++c) wb_Drows(q, wb_map[static_cast<std::size_t>(c)]) = Mschur(i, c);
        wb_Drows(q, nb + t) -= 1.0;
        U(nb + t, q) = 1.0;
        ++q;
    }
    for (int c = 0; c < ms; ++c) {  // changed and added columns: their differences in the kept rows
        if (!col_new[static_cast<std::size_t>(c)]) continue;
        const int uc = wb_map[static_cast<std::size_t>(c)];
        const bool kept = uc < nb;
        wb_cols.push_back(uc);
        for (int r = 0; r < ms; ++r) {
            const int ur = wb_map[static_cast<std::size_t>(r)];
            if (ur >= nb) continue;  // added rows: in the row part
            U(ur, q) = Mschur(r, c) - (kept ? bs_M(ur, uc) : 0.0);
        }
        ++q;
    }
    wb_Z.resize(nu, k);
    wb_Z.topRows(nb) = dlu.solve(U.topRows(nb));
    wb_Z.bottomRows(na) = U.bottomRows(na);
    Eigen::MatrixXd C = Eigen::MatrixXd::Identity(k, k);
    C.topRows(k1) += wb_Drows * wb_Z;
    for (int c = 0; c < k2; ++c) C.row(k1 + c) += wb_Z.row(wb_cols[static_cast<std::size_t>(c)]);
    wb_C.compute(C);
    if (!(C.allFinite() && wb_C.rcond() > 1e-12)) return factorise();  // near-singular: decided by a dense LU
    wb_active = true;
    return 0;
}

/// M^-1 r for the current held set (in lin.S order): the dense LU, or the update of the base's.
Eigen::VectorXd ModeSolver::schur_inverse(const Eigen::VectorXd& r) const {
    if (!wb_active) return dlu.solve(r);
    const int ms = static_cast<int>(r.size()), k1 = static_cast<int>(wb_Drows.rows()),
              k2 = static_cast<int>(wb_cols.size());
    Eigen::VectorXd y = Eigen::VectorXd::Zero(wb_nu);
    for (int i = 0; i < ms; ++i) y[wb_map[static_cast<std::size_t>(i)]] = r[i];
    y.head(wb_nb) = dlu.solve(y.head(wb_nb)).eval();
    Eigen::VectorXd t(k1 + k2);
    t.head(k1) = wb_Drows * y;
    for (int c = 0; c < k2; ++c) t[k1 + c] = y[wb_cols[static_cast<std::size_t>(c)]];
    y -= wb_Z * wb_C.solve(t);
    Eigen::VectorXd out(ms);
    for (int i = 0; i < ms; ++i) out[i] = y[wb_map[static_cast<std::size_t>(i)]];
    return out;
}

/// Held-row solve with the Schur complement: p_S from M p_S = target - G_S z0 (one
/// step of iterative refinement with the explicit M, as the sparse LU's solves get; two
/// after a low-rank update) and z = z0 + K^-1 (G_S^T p_S + G_slip^T D p_S): one solve with
/// K's factor, or the sum of the cached columns K^-1 g^T when that is cheaper (few held
/// rows: n (ms + coupled) against 2 nnz(L) multiply-adds; with schur_updates false always
/// the sum, as before).
void ModeSolver::schur_solve(const ModeLinearization& lin, const Eigen::VectorXd& z0, const Eigen::VectorXd& target,
                 Eigen::VectorXd& pS, Eigen::VectorXd& zout) {
    const auto& S = lin.S;
    const int ms = static_cast<int>(S.size());
    zout = z0;
    pS.setZero(ms);
    if (ms == 0) return;
    Eigen::VectorXd res(ms);
    for (int r = 0; r < ms; ++r) res[r] = target[r] - st_.row_dot(S[r], z0);
    pS = schur_inverse(res);
    for (int refine = wb_active ? 2 : 1; refine > 0; --refine) pS += schur_inverse(res - Mschur * pS);
    const double columns = static_cast<double>(ms + static_cast<int>(lin.coupled.size()));
    if (tuning_.schur_updates && columns * static_cast<double>(z0.size()) > 2.0 * l_nonzeros) {
        Eigen::VectorXd q = Eigen::VectorXd::Zero(st_.rows());
        for (int c = 0; c < ms; ++c) q[S[c]] += pS[c];
        for (std::size_t a = 0; a < lin.coupled.size(); ++a) {
            const int c = pos[lin.coupled[a].second];
            if (c >= 0) q[lin.coupled[a].first] += lin.coef[a] * pS[c];
        }
        zout += st_.k_llt.solve(st_.Gt * q);
        return;
    }
    std::vector<int> rows(S);
    for (std::size_t a = 0; a < lin.coupled.size(); ++a)
        if (pos[lin.coupled[a].second] >= 0) rows.push_back(lin.coupled[a].first);
    ensure_columns(rows);  // (the update computes only the changed ones)
    for (int c = 0; c < ms; ++c) zout += pS[c] * xcol[static_cast<std::size_t>(S[c])];
    for (std::size_t a = 0; a < lin.coupled.size(); ++a) {
        const int c = pos[lin.coupled[a].second];
        if (c >= 0) zout += (lin.coef[a] * pS[c]) * xcol[static_cast<std::size_t>(lin.coupled[a].first)];
    }
}

Eigen::VectorXd ModeSolver::apply_A(const Eigen::VectorXd& x) const {
    if (lu_fixed) return fixed_->multiply(x);
    return A * x;
}

Eigen::VectorXd ModeSolver::refined_solve(const Eigen::VectorXd& r) {
    if (lu_fixed) return fixed_->solve(r);
    return refined_solve(Eigen::MatrixXd(r)).col(0);
}

Eigen::MatrixXd ModeSolver::refined_solve(const Eigen::MatrixXd& R) {
    if (lu_fixed) return fixed_->solve(R);
    Eigen::MatrixXd Y = lu.solve(R);
    const Eigen::MatrixXd res = R - A * Y;
    Y += lu.solve(res);
    return Y;
}

}  // namespace stackbeam::detail::sparse
