// The sparse LU route of the mode solver (mode_solver.hpp): a held set's saddle-point system
// factorised by a sparse LU (its own system ordered from scratch, or the fixed-pattern one,
// fixed_pattern_lu.hpp), its solves refined, and the bordered (low-rank) update of the last LU
// for held sets near it (try_border, border_solve; docs/decisions/002, 035).
#include <algorithm>
#include <utility>

#include "contact/sparse/linear/mode_solver.hpp"
#include "contact/sparse/linear/mode_solver_common.hpp"
#include "stackbeam/errors.hpp"

namespace stackbeam::detail::sparse {

using modes::ModeLinearization;

/// The scaled saddle-point system of lin's held set, factorised by the sparse LU: its own
/// system ordered from scratch, or the fixed-pattern one (fixed_pattern_lu.hpp) ordered once.
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
