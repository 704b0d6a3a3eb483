// The homotopy's base (path_base.hpp): its solutions and columns on the base's factorisation,
// and the confirming passes' solves on the kept base (solve_on_kept_base, docs/decisions/045).
#include "contact/sparse/transitions/path_base.hpp"

namespace stackbeam::detail::sparse {


/// Whether the homotopy keeps its base here (Switches::path_keep_base: on, and enough unknowns).
bool keeps_base(const SparsePath& path) {
    return path.switches.path_keep_base > 0 && path.stiffness().dofs() >= path.switches.path_keep_base;
}

/// x^ of the base for the data (b_j, d_j), j < k (k <= 2), and its displacements into zx[j] where
/// zx is not null: the kept ones reused, the others in one multi-column refined solve with the
/// base's factorisation (ModeSolver::solve_block) and kept. Returns the factorisations (0 where
/// the base is current). Throws SingularModes.
int base_solutions(SparsePath& path, KeptBase& kb, int k, const Eigen::VectorXd* const* b, const Eigen::VectorXd* const* d,
                   Eigen::VectorXd* const* X, Eigen::VectorXd* const* zx) {
    const int m = path.laws.size(), n = path.stiffness().dofs();
    std::vector<int> missing;
    for (int j = 0; j < k; ++j) {
        const KeptBase::Solution* s = kb.solution(*b[j], *d[j]);
        if (!s) {
            missing.push_back(j);
            continue;
        }
        *X[j] = s->X;
        if (zx) *zx[j] = s->z;
    }
    if (missing.empty()) return 0;
    const int nm = static_cast<int>(missing.size());
    Eigen::MatrixXd B(n, nm), D(m, nm), P, Z;
    for (int c = 0; c < nm; ++c) {
        B.col(c) = *b[missing[static_cast<std::size_t>(c)]];
        D.col(c) = *d[missing[static_cast<std::size_t>(c)]];
    }
    const int f = path.solver.solve_block(kb.lin, kb.key, B, D, P, Z);
    const Eigen::MatrixXd GZ = path.stiffness().Grow * Z;
    for (int c = 0; c < nm; ++c) {
        const int j = missing[static_cast<std::size_t>(c)];
        Eigen::VectorXd& x = *X[j];
        x.resize(2 * m);
        x << P.col(c), GZ.col(c);
        auto& s = kb.sol[kb.next_sol];
        kb.next_sol = 1 - kb.next_sol;
        s.b = *b[j];
        s.d = *d[j];
        s.X = x;
        s.z = Z.col(c);
        if (zx) *zx[j] = s.z;
    }
    return f;
}

/// The columns y_r of `rows` not in kb yet, solved on the base's factorisation (one multi-column
/// solve without refinement, ModeSolver::unit_solves); where the factorisation is a bordered update
/// or the primal route's, one solve() per column if `per_column`, else nothing (returns -1).
/// Returns the factorisations (0 where the base is current); counts into stats.
int add_columns(SparsePath& path, KeptBase& kb, std::vector<int> rows, bool per_column, PathStats& stats) {
    const int m = path.laws.size();
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    rows.erase(std::remove_if(rows.begin(), rows.end(), [&](int row) { return kb.col[static_cast<std::size_t>(row)] >= 0; }),
               rows.end());
    if (rows.empty()) return 0;
    const double c0 = thread_cpu_s();
    const SparseStiffness& st = path.stiffness();
    const Eigen::VectorXd& W = path.diag();
    const int k = static_cast<int>(rows.size());
    int f = 0;
    Eigen::MatrixXd P, Z;
    if (path.solver.unit_solves(kb.lin, rows, false, P, Z)) {
        ++stats.column_blocks;
    } else if (!per_column) {
        return -1;
    } else {  // a bordered or primal factorisation: one solve() per column
        const Eigen::VectorXd zero_b = Eigen::VectorXd::Zero(st.K.rows()), zero_d = Eigen::VectorXd::Zero(m);
        P.resize(m, k);
        Z.resize(st.K.rows(), k);
        for (int j = 0; j < k; ++j) {
            modes::ModeLinearization lin = kb.lin;
            lin.e.setZero();
            Eigen::VectorXd d = zero_d, Pj, zj;
            if (kb.eqs[static_cast<std::size_t>(rows[j])].kind == Eq::held) d[rows[j]] = 1.0;
            else lin.e[rows[j]] = 1.0;
            f += path.solver.solve(lin, kb.key, zero_b, d, Pj, zj);
            P.col(j) = Pj;
            Z.col(j) = zj;
        }
    }
    const bool keep = keeps_base(path);
    const int n = static_cast<int>(st.K.rows());  // (Z may have more rows: unit_solves' scratch)
    double* const rn2 = kb.rn2.data();
    for (int j = 0; j < k; ++j) {
        const double s = kb.eqs[static_cast<std::size_t>(rows[j])].kind == Eq::held ? 1.0 : 1.0 / W[rows[j]];
        const double* pj = P.col(j).data();
        const auto zj = Z.col(j).head(n);
        // the column [s p; s G z] written in memory order, its squares into the rows' norms; G z
        // row by row here (SparseStiffness::row_dot: the sums of Eigen's row-major sparse x dense
        // product, in the row's order), not as an m x k temporary first
        double* y = kb.Y.next();
        for (int q = 0; q < m; ++q) {
            const double v = s * pj[q];
            y[q] = v;
            rn2[q] += v * v;
        }
        for (int q = 0; q < m; ++q) {
            const double v = s * st.row_dot(q, zj);
            y[m + q] = v;
            rn2[m + q] += v * v;
        }
        kb.col[static_cast<std::size_t>(rows[j])] = kb.Y.commit();
        if (keep) kb.add_zc(s, Z, j, n);  // (the last use of Z's column j)
    }
    stats.columns += k;
    stats.column_s += thread_cpu_s() - c0;
    return f;
}

namespace {
/// The trace's check of a kept-base solve (TransitionTrace::check_kept; tests): the same modes
/// solved from scratch by mode solvers of its own on the whole saddle-point system, refined: Eigen's
/// SparseLU (the reference) and, in builds with KLU, KLU on the held set's system (the default
/// route's); the largest differences of p and z (kept against the reference, and KLU's against it:
/// the round-off of two direct solves of the same system) relative to their largest entries.
void check_kept_solve(SparsePath& path, const Step& step, const Eigen::VectorXd& p, const Eigen::VectorXd& z) {
    TransitionTrace& tr = *path.observer;
    KeptBase& kb = *path.kept;
    if (!kb.check[0]) {
        ModeSolverTuning own;  // the whole saddle-point system (not the Schur way, whose z = K^-1 (...)
        own.schur_max_rows = 0;  // after p_S stops at K's round-off), no bordered updates
        own.max_border_rows = 0;
        kb.check[0] = std::make_shared<ModeSolver>(own);
        if (klu_built()) {
            own.fixed_pattern = FixedPatternLu::klu_held_amd;
            kb.check[1] = std::make_shared<ModeSolver>(own);
        }
        for (auto& c : kb.check)
            if (c) c->reset(path.stiffness().K, path.stiffness().G);
    }
    modes::ModeLinearization lin;
    path.modes.linearize(path.laws, lin);
    const std::vector<signed char> key = solver_key(path.laws, path.modes);
    auto rel = [](const Eigen::VectorXd& a, const Eigen::VectorXd& ref) {
        return (a - ref).lpNorm<Eigen::Infinity>() / std::max(ref.lpNorm<Eigen::Infinity>(), 1e-300);
    };
    Eigen::VectorXd pf, zf, pk = p;
    kb.check[0]->solve(lin, key, step.b, step.d, pf, zf);
    path.modes.put_slip_forces(path.laws, pf);
    path.modes.put_slip_forces(path.laws, pk);
    ++tr.kept_checked;
    tr.kept_p_diff = std::max(tr.kept_p_diff, rel(pk, pf));
    tr.kept_z_diff = std::max(tr.kept_z_diff, rel(z, zf));
    if (kb.check[1]) {
        Eigen::VectorXd p2, z2;
        kb.check[1]->solve(lin, key, step.b, step.d, p2, z2);
        path.modes.put_slip_forces(path.laws, p2);
        tr.fresh_p_diff = std::max(tr.fresh_p_diff, rel(p2, pf));
        tr.fresh_z_diff = std::max(tr.fresh_z_diff, rel(z2, zf));
    }
}
}  // namespace

bool solve_on_kept_base(SparsePath& path, const Step& step, Eigen::VectorXd& p, Eigen::VectorXd& z) {
    if (!keeps_base(path) || !path.kept || path.solves_since_path > 1 || !path.kept->current(path)) return false;
    RouteStats* const rs = path.observer ? &path.observer->routes : nullptr;
    const double c0 = thread_cpu_s(), cached0 = rs ? rs->seconds[route_cached] : 0.0;
    KeptBase& kb = *path.kept;
    const ContactProblem& laws = path.laws;
    const SparseStiffness& st = path.stiffness();
    const int m = laws.size();
    const Eigen::VectorXd& W = path.diag();
    const int limit = path.switches.path_rebase_rows > 0 ? path.switches.path_rebase_rows : kMaxChangedRows;
    // the modes' equations and the rows C where they differ from the base's
    std::vector<Eq> eq;
    mode_equations(laws, path.modes.nmode, path.modes.tmode, eq);
    std::vector<int> C;
    changed_rows(eq, kb.eqs, C);
    const int nc = static_cast<int>(C.size());
    if (nc > limit) return false;
    PathStats unused;
    Eigen::VectorXd X, zh;
    try {
        if (add_columns(path, kb, C, false, unused) < 0) return false;
        const Eigen::VectorXd* b[1] = {&step.b};
        const Eigen::VectorXd* d[1] = {&step.d};
        Eigen::VectorXd* Xp[1] = {&X};
        Eigen::VectorXd* zp[1] = {&zh};
        base_solutions(path, kb, 1, b, d, Xp, zp);
    } catch (const SingularModes&) {
        return false;
    }
    const ColumnStore& Y = kb.Y;
    if (kb.nzc != Y.size()) return false;  // (columns made with the switch off)
    // the bordered system on C: H lambda = F (metres both ways, as the path's)
    const Eigen::MatrixXd H = bordered_matrix(eq, C, Y, kb.col, W, m);
    const Eigen::PartialPivLU<Eigen::MatrixXd> lu(H);
    if (nc > 0 && !(H.allFinite() && lu.rcond() > kKeptRcond)) return false;
    // x = xb + Y lambda with the modes' equations on C (right-hand sides there `target(row)`):
    // its forces pf and displacements zf
    auto bordered = [&](const Eigen::VectorXd& Xb, const Eigen::VectorXd& zb, const std::function<double(int)>& target,
                        Eigen::VectorXd& pf, Eigen::VectorXd& zf) {
        pf = Xb.head(m);
        zf = zb;
        if (nc == 0) return;
        const Eigen::VectorXd l = lu.solve(bordered_rhs(eq, C, W, m, target, Xb));
        Eigen::VectorXd L = Eigen::VectorXd::Zero(Y.padded());
        for (int j = 0; j < nc; ++j) {
            const int cj = kb.col[C[j]];
            L[cj] = l[j];
            zf += l[j] * kb.z_of(cj, static_cast<int>(zf.size()));
        }
        for (int q = 0; q < m; ++q) pf[q] += Y.dot(q, L);
    };
    // the force equations put exactly (p = 0; slip p_t = e + c p_n: a slip row's normal row is
    // held or zero, never slip)
    auto put_force_equations = [&](Eigen::VectorXd& pf) {
        for (int row = 0; row < m; ++row)
            if (eq[row].kind == Eq::zero) pf[row] = 0.0;
        for (int row = 0; row < m; ++row)
            if (eq[row].kind == Eq::slip) pf[row] = eq[row].e + (eq[row].other >= 0 ? eq[row].coef * pf[eq[row].other] : 0.0);
    };
    Eigen::VectorXd pn, zn;
    bordered(X, zh, [&](int r) { return eq[r].rhs(r, step.d); }, pn, zn);
    put_force_equations(pn);
    // iterative refinement against the modes' own system (K z - G^T p = b, the held rows' G z = d,
    // the force equations exact): each correction the same bordered solve of the residual (the
    // base's factorisation, unrefined columns: a contraction), until the held rows' residual is at
    // the round-off a direct solve of the whole system reaches
    modes::ModeLinearization lin0 = kb.lin;
    lin0.e.setZero();
    Eigen::VectorXd res(m);
    double last = std::numeric_limits<double>::infinity();
    for (int it = 0;; ++it) {
        const Eigen::VectorXd s = st.Grow * zn - step.d;
        double err = 0.0;
        for (int row = 0; row < m; ++row) {
            res[row] = eq[row].kind == Eq::held ? -s[row] : 0.0;
            err = std::max(err, std::abs(res[row]));
        }
        const double roundoff = st.roundoff(step.d, zn);
        if (err <= kKeptResidual * roundoff) break;
        if (it == kKeptCorrections || !(err < 0.5 * last)) {  // no longer decreasing
            if (err <= kKeptStall * roundoff) break;
            return false;  // not at round-off: the caller factorises
        }
        last = err;
        // the correction: the base's solve of the residual (the load's; the held rows' outside C,
        // whose equations are the base's), bordered on C
        Eigen::MatrixXd B(st.K.rows(), 1), D(m, 1), P, Z;
        B.col(0) = step.b + st.Gt * pn - st.K * zn;
        D.col(0) = res;
        for (int row : C) D(row, 0) = 0.0;
        try {
            path.solver.solve_block(lin0, kb.key, B, D, P, Z);
        } catch (const SingularModes&) {
            return false;
        }
        Eigen::VectorXd dX(2 * m), dp, dz;
        dX << P.col(0), st.Grow * Z.col(0);
        bordered(dX, Z.col(0), [&](int r) { return res[r]; }, dp, dz);
        pn += dp;
        zn += dz;
        put_force_equations(pn);
    }
    p = pn;
    z = zn;
    path.solver.count_update();
    if (path.observer && path.observer->check_kept) check_kept_solve(path, step, p, z);
    if (rs) {  // (its base solves are counted as the base's cached calls: their time once)
        rs->count[route_kept] += 1;
        rs->seconds[route_kept] += thread_cpu_s() - c0 - (rs->seconds[route_cached] - cached0);
        rs->held[route_kept] += static_cast<double>(kb.lin.S.size());
    }
    return true;
}

}  // namespace stackbeam::detail::sparse
