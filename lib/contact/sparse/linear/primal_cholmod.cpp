// The primal form of a set of modes on a CHOLMOD factor (primal_cholmod.hpp). Compiled only
// when CMake found CHOLMOD (STACKBEAM_HAVE_CHOLMOD).
//
// Why these choices (docs/decisions/027-primal-cholmod-route.md, measured):
//  - simplicial LDL^T: cholmod_updown works on it (a supernodal factor would be converted
//    back at every update);
//  - the ordering once per (K, G), on the pattern with every layer row held, so every held
//    set's factor fits in the analysed column counts and updown never reallocates;
//  - updates while at most kMaxUpdateRank rows change (updown's cost per row against one
//    numeric factorisation, measured on the 10 x 400 stacks), a refactorisation otherwise;
//  - GMRES (restarted, right-preconditioned, written here: Eigen's GMRES is in the
//    unsupported module and takes an assembled matrix, this operator is never assembled).
#include "contact/sparse/linear/primal_cholmod.hpp"

#include <cholmod.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "contact/sparse/linear/mode_solver.hpp"

namespace stackbeam::detail::sparse {

bool primal_route_built() { return true; }

namespace {
// updown while at most this many layer rows change between the factor's set and the new
// one, a numeric refactorisation above (docs/decisions/027: measured cost ratio)
constexpr int kMaxUpdateRank = 120;
// GMRES: relative residual of the scaled system, the Krylov basis per restart, iterations in all
constexpr double kKrylovTolerance = 1e-14;
constexpr double kKrylovAccept = 1e-10;  // a stagnated iteration is still accepted below this
constexpr int kRestart = 30;
constexpr int kMaxKrylov = 120;

/// Restarted GMRES(kRestart) on apply_T B^-1 (apply_Binv: the preconditioner B^-1) for rhs
/// (its norm rhs_norm), from xh (updated), the true residual at each restart; the Krylov
/// iterations added to `iterations`. True where it reached kKrylovTolerance x rhs_norm (false
/// also where it stagnated: the caller judges the residual).
template <class ApplyT, class ApplyBinv>
bool restarted_gmres(const ApplyT& apply_T, const ApplyBinv& apply_Binv, const Eigen::VectorXd& rhs, double rhs_norm,
                     Eigen::VectorXd& xh, int& iterations) {
    bool converged = rhs_norm == 0.0;
    double last = std::numeric_limits<double>::infinity();
    // restarted GMRES(kRestart) on T^ B^-1, the true residual at each restart
    const Eigen::Index N = rhs.size();
    Eigen::VectorXd r, tmp, tmp2;
    Eigen::MatrixXd V(N, kRestart + 1), H = Eigen::MatrixXd::Zero(kRestart + 1, kRestart);
    Eigen::VectorXd cs(kRestart), sn(kRestart), g(kRestart + 1);
    while (!converged && iterations < kMaxKrylov) {
        apply_T(xh, tmp);
        r = rhs - tmp;
        const double beta = r.norm();
        if (beta <= kKrylovTolerance * rhs_norm) {
            converged = true;
            break;
        }
        if (beta > 0.5 * last) break;  // stagnated (round-off): judged below
        last = beta;
        V.col(0) = r / beta;
        g.setZero();
        g[0] = beta;
        H.setZero();
        int j = 0;
        for (; j < kRestart && iterations < kMaxKrylov; ++j) {
            ++iterations;
            apply_Binv(V.col(j), tmp);
            apply_T(tmp, tmp2);
            for (int i = 0; i <= j; ++i) {  // modified Gram-Schmidt
                H(i, j) = V.col(i).dot(tmp2);
                tmp2 -= H(i, j) * V.col(i);
            }
            H(j + 1, j) = tmp2.norm();
            if (H(j + 1, j) > 0.0) V.col(j + 1) = tmp2 / H(j + 1, j);
            for (int i = 0; i < j; ++i) {  // the previous Givens rotations
                const double a = cs[i] * H(i, j) + sn[i] * H(i + 1, j);
                H(i + 1, j) = -sn[i] * H(i, j) + cs[i] * H(i + 1, j);
                H(i, j) = a;
            }
            const double den = std::hypot(H(j, j), H(j + 1, j));
            cs[j] = den > 0.0 ? H(j, j) / den : 1.0;
            sn[j] = den > 0.0 ? H(j + 1, j) / den : 0.0;
            H(j, j) = den;
            H(j + 1, j) = 0.0;
            g[j + 1] = -sn[j] * g[j];
            g[j] = cs[j] * g[j];
            if (std::abs(g[j + 1]) <= 0.1 * kKrylovTolerance * rhs_norm || H(j, j) == 0.0) {
                ++j;
                break;
            }
        }
        if (j == 0) break;
        const Eigen::VectorXd y =
            H.topLeftCorner(j, j).triangularView<Eigen::Upper>().solve(g.head(j));
        apply_Binv(V.leftCols(j) * y, tmp);
        xh += tmp;
    }
    return converged;
}
}  // namespace

struct CholmodPrimal final : PrimalSolver {
    PrimalOrdering ordering;
    cholmod_common cc{};
    cholmod_sparse* A = nullptr;  // P, upper triangle, pattern of every layer row held
    cholmod_factor* L = nullptr;
    cholmod_dense *X = nullptr, *Yw = nullptr, *Ew = nullptr, *B = nullptr;
    bool factored = false, always_refactorise = false;
    long updated_rank_since_factor = 0;
    PrimalStats stats_;

    // the structure
    int n = 0, nz = 0, m = 0;
    std::vector<int> zidx, zdof;   // DOF -> leaf index (or -1); leaf index -> DOF
    std::vector<int> layer_dof;    // row -> its layer DOF, or -1
    std::vector<double> layer_e, layer_k, layer_c;  // G'(r, u), K'(u, u), c = e^2 / k [m/N]
    int nlayer = 0;
    SpMat Kzz;                     // K' on the leaves' DOFs
    RowMat Gz;                     // G' on the leaves' DOFs (rows: contact rows)
    SpMat Gzt;                     // its transpose
    Eigen::VectorXd dzz;           // column scaling on the leaves' DOFs: diag(K)^-1/2
    Eigen::VectorXd row_h;         // the rows' scaling (SparseStiffness::row_h)
    std::vector<double> base_values;                      // A's values from K_zz
    std::vector<std::vector<std::pair<int, double>>> row_terms;  // per layer row: (A position, g_a g_b)
    std::vector<int> iperm;        // leaf index -> its position in L's ordering

    // the current set
    std::vector<char> in_factor;   // layer rows whose spring is in L
    std::vector<int> rigid;        // held rigid rows (lin.S order)
    Eigen::MatrixXd Y;             // P^-1 Gh_R^T
    Eigen::PartialPivLU<Eigen::MatrixXd> Mlu;  // G_R Y
    Eigen::VectorXd rs;            // rigid rows' scaling (1 / row_h)

    explicit CholmodPrimal(PrimalOrdering o) : ordering(o) {
        cholmod_start(&cc);
        cc.supernodal = CHOLMOD_SIMPLICIAL;
        cc.final_ll = 0;
        cc.print = 0;
        cc.error_handler = nullptr;
        switch (o) {
            case PrimalOrdering::amd: cc.nmethods = 1; cc.method[0].ordering = CHOLMOD_AMD; break;
            case PrimalOrdering::metis: cc.nmethods = 1; cc.method[0].ordering = CHOLMOD_METIS; break;
            case PrimalOrdering::nesdis: cc.nmethods = 1; cc.method[0].ordering = CHOLMOD_NESDIS; break;
            case PrimalOrdering::cholmod_default: break;
        }
        cc.postorder = 1;
    }
    ~CholmodPrimal() override {
        release();
        cholmod_finish(&cc);
    }
    void release() {
        if (A) cholmod_free_sparse(&A, &cc);
        if (L) cholmod_free_factor(&L, &cc);
        if (X) cholmod_free_dense(&X, &cc);
        if (Yw) cholmod_free_dense(&Yw, &cc);
        if (Ew) cholmod_free_dense(&Ew, &cc);
        if (B) cholmod_free_dense(&B, &cc);
        factored = false;
    }
    // CHOLMOD fails only out of memory or on invalid arguments (a bug here): neither a user's
    // input nor a step's convergence, so a plain runtime_error with CHOLMOD's status
    void check(bool ok, const char* what) const {
        if (!ok || cc.status < CHOLMOD_OK)
            throw std::runtime_error(std::string("CHOLMOD ") + what + " failed (status " + std::to_string(cc.status) +
                                     ")");
    }

    void reset(const SparseStiffness& st) override;
    int layer_rows() const override { return nlayer; }
    bool is_layer(int row) const override { return layer_dof[static_cast<std::size_t>(row)] >= 0; }
    bool factor(const modes::ModeLinearization& lin, const std::vector<int>& pos) override;
    bool solve(const modes::ModeLinearization& lin, const std::vector<int>& pos, const Eigen::VectorXd& f,
               const Eigen::VectorXd& dS, Eigen::VectorXd& pS, Eigen::VectorXd& z) override;
    void refresh() override {
        if (factored && updated_rank_since_factor > 0) numeric_factor();
    }
    void set_always_refactorise(bool on) override { always_refactorise = on; }
    const PrimalStats& stats() const override { return stats_; }
    void reset_stats() override { stats_ = PrimalStats{}; }

    void numeric_factor();
    void updown(const std::vector<int>& rows, bool add);
    void solve_P(Eigen::Ref<Eigen::MatrixXd> rhs_in_out);
};

void CholmodPrimal::reset(const SparseStiffness& st) {
    release();
    stats_ = PrimalStats{};
    const SpMat& K = st.K;
    const SpMat& G = st.G;
    n = static_cast<int>(K.rows());
    m = static_cast<int>(G.rows());
    // layer DOFs (layer_dofs, mode_solver.hpp)
    layer_e.assign(static_cast<std::size_t>(m), 0.0);
    layer_k.assign(static_cast<std::size_t>(m), 0.0);
    layer_c.assign(static_cast<std::size_t>(m), 0.0);
    zidx.assign(static_cast<std::size_t>(n), -1);
    zdof.clear();
    nlayer = 0;
    layer_dof = layer_dofs(K, G);
    std::vector<char> on_layer(static_cast<std::size_t>(n), 0);
    for (int r = 0; r < m; ++r) {
        const int j = layer_dof[static_cast<std::size_t>(r)];
        if (j < 0) continue;
        const auto ru = static_cast<std::size_t>(r);
        layer_e[ru] = G.coeff(r, j);
        layer_k[ru] = K.coeff(j, j);
        layer_c[ru] = layer_e[ru] * layer_e[ru] / layer_k[ru];
        on_layer[static_cast<std::size_t>(j)] = 1;
        ++nlayer;
    }
    for (int j = 0; j < n; ++j)
        if (!on_layer[static_cast<std::size_t>(j)]) {
            zidx[static_cast<std::size_t>(j)] = static_cast<int>(zdof.size());
            zdof.push_back(j);
        }
    nz = static_cast<int>(zdof.size());
    in_factor.assign(static_cast<std::size_t>(m), 0);
    if (nlayer == 0) return;
    // K_zz, G_z
    std::vector<Eigen::Triplet<double>> t;
    for (int j = 0; j < n; ++j) {
        const int cj = zidx[static_cast<std::size_t>(j)];
        if (cj < 0) continue;
        for (SpMat::InnerIterator it(K, j); it; ++it) {
            const int ri = zidx[static_cast<std::size_t>(it.row())];
            if (ri >= 0) t.emplace_back(ri, cj, it.value());
        }
    }
    Kzz.resize(nz, nz);
    Kzz.setFromTriplets(t.begin(), t.end());
    Kzz.makeCompressed();
    t.clear();
    for (int j = 0; j < n; ++j) {
        const int cj = zidx[static_cast<std::size_t>(j)];
        if (cj < 0) continue;
        for (SpMat::InnerIterator it(G, j); it; ++it) t.emplace_back(static_cast<int>(it.row()), cj, it.value());
    }
    Gz.resize(m, nz);
    Gz.setFromTriplets(t.begin(), t.end());
    Gz.makeCompressed();
    Gzt = SpMat(Gz.transpose());
    dzz.resize(nz);
    for (int i = 0; i < nz; ++i) dzz[i] = st.dz[zdof[static_cast<std::size_t>(i)]];
    row_h = st.row_h;
    // the pattern of P with every layer row held: K_zz's upper triangle plus g^T g per row
    t.clear();
    for (int j = 0; j < nz; ++j)
        for (SpMat::InnerIterator it(Kzz, j); it; ++it)
            if (it.row() <= j) t.emplace_back(static_cast<int>(it.row()), j, 0.0);
    for (int r = 0; r < m; ++r) {
        if (layer_dof[static_cast<std::size_t>(r)] < 0) continue;
        for (RowMat::InnerIterator a(Gz, r); a; ++a)
            for (RowMat::InnerIterator b(Gz, r); b; ++b)
                if (a.col() <= b.col()) t.emplace_back(static_cast<int>(a.col()), static_cast<int>(b.col()), 0.0);
    }
    SpMat pattern(nz, nz);
    pattern.setFromTriplets(t.begin(), t.end());
    pattern.makeCompressed();
    const auto nnz = static_cast<std::size_t>(pattern.nonZeros());
    A = cholmod_allocate_sparse(static_cast<std::size_t>(nz), static_cast<std::size_t>(nz), nnz, 1, 1, 1, CHOLMOD_REAL,
                                &cc);
    check(A != nullptr, "allocate");
    auto* Ap = static_cast<int*>(A->p);
    auto* Ai = static_cast<int*>(A->i);
    std::copy(pattern.outerIndexPtr(), pattern.outerIndexPtr() + nz + 1, Ap);
    std::copy(pattern.innerIndexPtr(), pattern.innerIndexPtr() + nnz, Ai);
    auto position = [&](int row, int col) {  // index of (row, col), row <= col, in A
        const int* first = Ai + Ap[col];
        const int* last = Ai + Ap[col + 1];
        return static_cast<int>(std::lower_bound(first, last, row) - Ai);
    };
    base_values.assign(nnz, 0.0);
    for (int j = 0; j < nz; ++j)
        for (SpMat::InnerIterator it(Kzz, j); it; ++it)
            if (it.row() <= j) base_values[static_cast<std::size_t>(position(static_cast<int>(it.row()), j))] += it.value();
    row_terms.assign(static_cast<std::size_t>(m), {});
    for (int r = 0; r < m; ++r) {
        if (layer_dof[static_cast<std::size_t>(r)] < 0) continue;
        for (RowMat::InnerIterator a(Gz, r); a; ++a)
            for (RowMat::InnerIterator b(Gz, r); b; ++b)
                if (a.col() <= b.col())
                    row_terms[static_cast<std::size_t>(r)].emplace_back(
                        position(static_cast<int>(a.col()), static_cast<int>(b.col())), a.value() * b.value());
    }
    L = cholmod_analyze(A, &cc);
    check(L != nullptr, "analyze");
    iperm.assign(static_cast<std::size_t>(nz), 0);
    const auto* perm = static_cast<const int*>(L->Perm);
    for (int i = 0; i < nz; ++i) iperm[static_cast<std::size_t>(perm[i])] = i;
}

/// P of the rows in in_factor, factorised on the analysed ordering.
void CholmodPrimal::numeric_factor() {
    auto* Ax = static_cast<double*>(A->x);
    std::copy(base_values.begin(), base_values.end(), Ax);
    for (int r = 0; r < m; ++r) {
        if (!in_factor[static_cast<std::size_t>(r)]) continue;
        const double w = 1.0 / layer_c[static_cast<std::size_t>(r)];
        for (const auto& [p, v] : row_terms[static_cast<std::size_t>(r)]) Ax[p] += w * v;
    }
    // (P is K_zz, positive definite, checked by SparseStiffness::build, plus springs)
    check(cholmod_factorize(A, L, &cc) != 0, "factorize");
    factored = true;
    updated_rank_since_factor = 0;
    ++stats_.factorisations;
}

/// L D L^T +- C C^T with C's columns g_r^T / sqrt(c_r) for `rows` (in L's ordering).
void CholmodPrimal::updown(const std::vector<int>& rows, bool add) {
    if (rows.empty()) return;
    std::size_t nnz = 0;
    for (int r : rows) nnz += static_cast<std::size_t>(Gz.row(r).nonZeros());
    cholmod_sparse* C =
        cholmod_allocate_sparse(static_cast<std::size_t>(nz), rows.size(), nnz, 1, 1, 0, CHOLMOD_REAL, &cc);
    check(C != nullptr, "allocate");
    auto* Cp = static_cast<int*>(C->p);
    auto* Ci = static_cast<int*>(C->i);
    auto* Cx = static_cast<double*>(C->x);
    int q = 0;
    std::vector<std::pair<int, double>> col;
    for (std::size_t k = 0; k < rows.size(); ++k) {
        Cp[k] = q;
        const int r = rows[k];
        const double s = 1.0 / std::sqrt(layer_c[static_cast<std::size_t>(r)]);
        col.clear();
        for (RowMat::InnerIterator it(Gz, r); it; ++it)
            col.emplace_back(iperm[static_cast<std::size_t>(it.col())], s * it.value());
        std::sort(col.begin(), col.end());
        for (const auto& [i, v] : col) {
            Ci[q] = i;
            Cx[q] = v;
            ++q;
        }
    }
    Cp[rows.size()] = q;
    const int ok = cholmod_updown(add ? 1 : 0, C, L, &cc);
    cholmod_free_sparse(&C, &cc);
    check(ok != 0, "updown");
    updated_rank_since_factor += static_cast<long>(rows.size());
    stats_.rank += static_cast<long>(rows.size());
}

/// rhs <- P^-1 rhs, column by column block (nz rows).
void CholmodPrimal::solve_P(Eigen::Ref<Eigen::MatrixXd> rhs) {
    const auto cols = static_cast<std::size_t>(rhs.cols());
    if (cols == 0) return;
    if (!B || B->ncol != cols) {
        if (B) cholmod_free_dense(&B, &cc);
        B = cholmod_allocate_dense(static_cast<std::size_t>(nz), cols, static_cast<std::size_t>(nz), CHOLMOD_REAL, &cc);
        check(B != nullptr, "allocate");
    }
    Eigen::Map<Eigen::MatrixXd>(static_cast<double*>(B->x), nz, rhs.cols()) = rhs;
    check(cholmod_solve2(CHOLMOD_A, L, B, nullptr, &X, nullptr, &Yw, &Ew, &cc) != 0, "solve");
    rhs = Eigen::Map<const Eigen::MatrixXd>(static_cast<const double*>(X->x), nz, rhs.cols());
}

std::shared_ptr<PrimalSolver> make_primal_solver(PrimalOrdering ordering) {
    return std::make_shared<CholmodPrimal>(ordering);
}

bool CholmodPrimal::factor(const modes::ModeLinearization& lin, const std::vector<int>& pos) {
    CholmodPrimal& s = *this;
    std::vector<int> added, removed;
    s.rigid.clear();
    for (int r : lin.S) {
        if (s.layer_dof[static_cast<std::size_t>(r)] < 0) s.rigid.push_back(r);
        else if (!s.in_factor[static_cast<std::size_t>(r)]) added.push_back(r);
    }
    for (int r = 0; r < s.m; ++r)
        if (s.in_factor[static_cast<std::size_t>(r)] && pos[static_cast<std::size_t>(r)] < 0) removed.push_back(r);
    for (int r : added) s.in_factor[static_cast<std::size_t>(r)] = 1;
    for (int r : removed) s.in_factor[static_cast<std::size_t>(r)] = 0;
    const auto k = static_cast<int>(added.size() + removed.size());
    if (!s.factored || s.always_refactorise || k > kMaxUpdateRank) {
        s.numeric_factor();
    } else if (k > 0) {
        s.updown(added, true);  // updates first: the factor stays positive definite throughout
        s.updown(removed, false);
        ++s.stats_.updates;
    }
    // the held rigid rows: Y = P^-1 Gh_R^T, M = G_R Y
    const int nr = static_cast<int>(s.rigid.size());
    s.rs.resize(nr);
    for (int i = 0; i < nr; ++i) s.rs[i] = 1.0 / s.row_h[s.rigid[static_cast<std::size_t>(i)]];
    if (nr == 0) return true;
    std::vector<int> rcol(static_cast<std::size_t>(s.m), -1);
    for (int i = 0; i < nr; ++i) rcol[static_cast<std::size_t>(s.rigid[static_cast<std::size_t>(i)])] = i;
    s.Y.setZero(s.nz, nr);
    for (int i = 0; i < nr; ++i)
        for (RowMat::InnerIterator it(s.Gz, s.rigid[static_cast<std::size_t>(i)]); it; ++it) s.Y(it.col(), i) += it.value();
    for (std::size_t a = 0; a < lin.coupled.size(); ++a) {
        const int i = rcol[static_cast<std::size_t>(lin.coupled[a].second)];
        if (i < 0) continue;
        for (RowMat::InnerIterator it(s.Gz, lin.coupled[a].first); it; ++it) s.Y(it.col(), i) += lin.coef[a] * it.value();
    }
    s.solve_P(s.Y);
    Eigen::MatrixXd M(nr, nr);
    for (int i = 0; i < nr; ++i)
        for (int c = 0; c < nr; ++c) {
            double v = 0.0;
            for (RowMat::InnerIterator it(s.Gz, s.rigid[static_cast<std::size_t>(i)]); it; ++it) v += it.value() * s.Y(it.col(), c);
            M(i, c) = v * s.rs[i] * s.rs[c];  // scaled as the sparse LU's rows
        }
    s.Mlu.compute(M);
    (void)pos;
    return M.allFinite() && s.Mlu.rcond() > 1e-14;
}

bool CholmodPrimal::solve(const modes::ModeLinearization& lin, const std::vector<int>& pos, const Eigen::VectorXd& f,
                         const Eigen::VectorXd& dS, Eigen::VectorXd& pS, Eigen::VectorXd& z) {
    CholmodPrimal& s = *this;
    ++s.stats_.solves;
    const int nz = s.nz, nr = static_cast<int>(s.rigid.size()), ms = static_cast<int>(lin.S.size());
    // the held layer rows' offsets with their layer DOF's load: d~_r = d_r - e_r f_u / k_r
    Eigen::VectorXd dt = Eigen::VectorXd::Zero(s.m);  // d~ / c on held layer rows
    for (int i = 0; i < ms; ++i) {
        const auto r = static_cast<std::size_t>(lin.S[static_cast<std::size_t>(i)]);
        if (s.layer_dof[r] < 0) continue;
        dt[static_cast<Eigen::Index>(r)] =
            (dS[i] - s.layer_e[r] * f[s.layer_dof[r]] / s.layer_k[r]) / s.layer_c[r];
    }
    // couplings: (t, n, coef) with n held; layer normal (N, in h) or rigid normal (in Gh)
    std::vector<int> rcol(static_cast<std::size_t>(s.m), -1);
    for (int i = 0; i < nr; ++i) rcol[static_cast<std::size_t>(s.rigid[static_cast<std::size_t>(i)])] = i;
    struct Coupling {
        int t, n, rigid_col;
        double coef;
    };
    std::vector<Coupling> cpl;
    for (std::size_t a = 0; a < lin.coupled.size(); ++a) {
        const int t = lin.coupled[a].first, nrow = lin.coupled[a].second;
        if (pos[static_cast<std::size_t>(nrow)] < 0) continue;  // the normal force is fixed (e)
        cpl.push_back({t, nrow, rcol[static_cast<std::size_t>(nrow)], lin.coef[a]});
    }
    // h = f_z + G_z^T v, v = d~/c on held layer rows plus the layer-normal couplings
    Eigen::VectorXd v = dt;
    for (const auto& c : cpl)
        if (c.rigid_col < 0) v[c.t] += c.coef * dt[c.n];
    Eigen::VectorXd h(nz);
    for (int i = 0; i < nz; ++i) h[i] = f[s.zdof[static_cast<std::size_t>(i)]];
    h += s.Gzt * v;
    Eigen::VectorXd dR(nr);
    for (int i = 0; i < nr; ++i) dR[i] = dS[pos[static_cast<std::size_t>(s.rigid[static_cast<std::size_t>(i)])]];

    // the scaled operator T^ and preconditioner B^-1 on x^ = (z / dz, q / rs)
    const int N = nz + nr;
    auto apply_T = [&](const Eigen::VectorXd& xh, Eigen::VectorXd& yh) {
        const Eigen::VectorXd zz = s.dzz.cwiseProduct(xh.head(nz));
        const Eigen::VectorXd w = s.Gz * zz;
        Eigen::VectorXd u = Eigen::VectorXd::Zero(s.m);
        for (int i = 0; i < ms; ++i) {
            const int r = lin.S[static_cast<std::size_t>(i)];
            if (s.layer_dof[static_cast<std::size_t>(r)] >= 0) u[r] += w[r] / s.layer_c[static_cast<std::size_t>(r)];
        }
        for (int i = 0; i < nr; ++i) u[s.rigid[static_cast<std::size_t>(i)]] -= s.rs[i] * xh[nz + i];
        for (const auto& c : cpl) {
            if (c.rigid_col < 0) u[c.t] += c.coef * w[c.n] / s.layer_c[static_cast<std::size_t>(c.n)];
            else u[c.t] -= c.coef * s.rs[c.rigid_col] * xh[nz + c.rigid_col];
        }
        yh.resize(N);
        yh.head(nz) = s.dzz.cwiseProduct(s.Kzz * zz + s.Gzt * u);
        for (int i = 0; i < nr; ++i) yh[nz + i] = s.rs[i] * w[s.rigid[static_cast<std::size_t>(i)]];
    };
    auto apply_Binv = [&](const Eigen::VectorXd& vh, Eigen::VectorXd& xh) {
        Eigen::VectorXd z0 = vh.head(nz).cwiseQuotient(s.dzz);
        s.solve_P(z0);
        xh.resize(N);
        if (nr > 0) {
            Eigen::VectorXd r(nr);
            for (int i = 0; i < nr; ++i) r[i] = vh[nz + i] - s.rs[i] * s.Gz.row(s.rigid[static_cast<std::size_t>(i)]).dot(z0);
            const Eigen::VectorXd qh = s.Mlu.solve(r);  // scaled forces q / rs
            z0 += s.Y * qh.cwiseProduct(s.rs);
            xh.tail(nr) = qh;
        }
        xh.head(nz) = z0.cwiseQuotient(s.dzz);
    };
    Eigen::VectorXd rhs(N);
    rhs.head(nz) = s.dzz.cwiseProduct(h);
    for (int i = 0; i < nr; ++i) rhs[nz + i] = s.rs[i] * dR[i];
    const double rhs_norm = rhs.norm();
    Eigen::VectorXd xh, tmp;
    apply_Binv(rhs, xh);
    int iterations = 0;
    bool converged = restarted_gmres(apply_T, apply_Binv, rhs, rhs_norm, xh, iterations);
    s.stats_.krylov_iterations += iterations;
    if (!converged) {
        apply_T(xh, tmp);
        converged = (rhs - tmp).norm() <= kKrylovAccept * std::max(rhs_norm, 1e-300);
        if (!converged) {
            ++s.stats_.fallbacks;
            return false;
        }
    }
    // the answer: z on the leaves, the held rows' forces, the layer DOFs
    const Eigen::VectorXd zz = s.dzz.cwiseProduct(xh.head(nz));
    const Eigen::VectorXd w = s.Gz * zz;
    pS.resize(ms);
    Eigen::VectorXd Q = Eigen::VectorXd::Zero(s.m);  // forces added to e per row
    for (int i = 0; i < ms; ++i) {
        const int rr = lin.S[static_cast<std::size_t>(i)];
        if (s.layer_dof[static_cast<std::size_t>(rr)] >= 0) pS[i] = dt[rr] - w[rr] / s.layer_c[static_cast<std::size_t>(rr)];
        else pS[i] = s.rs[rcol[static_cast<std::size_t>(rr)]] * xh[nz + rcol[static_cast<std::size_t>(rr)]];
        Q[rr] = pS[i];
    }
    for (const auto& c : cpl) Q[c.t] += c.coef * Q[c.n];
    z.resize(s.n);
    for (int i = 0; i < nz; ++i) z[s.zdof[static_cast<std::size_t>(i)]] = zz[i];
    for (int rr = 0; rr < s.m; ++rr) {
        const int u = s.layer_dof[static_cast<std::size_t>(rr)];
        if (u >= 0) z[u] = (f[u] + s.layer_e[static_cast<std::size_t>(rr)] * Q[rr]) / s.layer_k[static_cast<std::size_t>(rr)];
    }
    return true;
}

}  // namespace stackbeam::detail::sparse
