// The Schur route of the mode solver (mode_solver.hpp): few held rows, the dense Schur
// complement of the held rows on K's Cholesky factor (the columns K^-1 g_i^T cached per row),
// a fresh dense LU or the low-rank (Woodbury) update of the base's LU (docs/decisions/020, 038).
#include <algorithm>
#include <utility>

#include "contact/sparse/linear/mode_solver.hpp"
#include "contact/sparse/linear/mode_solver_common.hpp"
#include "stackbeam/errors.hpp"

namespace stackbeam::detail::sparse {

using modes::ModeLinearization;

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
}  // namespace

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

}  // namespace stackbeam::detail::sparse
