// The saddle-point system of a set of modes on one fixed pattern (fixed_pattern_lu.hpp).
#include "contact/sparse/linear/fixed_pattern_lu.hpp"

#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>

#include "contact/sparse/linear/mode_solver.hpp"

#ifdef STACKBEAM_HAVE_KLU
#include <klu.h>
#endif

namespace stackbeam::detail::sparse {

namespace {

/// The index in A's value array of the entry (r, c) (it is in the pattern).
int slot(const SpMat& A, int r, int c) {
    const int* begin = A.innerIndexPtr() + A.outerIndexPtr()[c];
    const int* end = A.innerIndexPtr() + A.outerIndexPtr()[c + 1];
    return static_cast<int>(std::lower_bound(begin, end, r) - A.innerIndexPtr());
}

/// Eigen's supernodal sparse LU: analyzePattern (COLAMD, elimination tree) once,
/// factorize per set (partial pivoting by rows on the fixed column order).
class EigenPatternLu final : public PatternLu {
    Eigen::SparseLU<SpMat, Eigen::COLAMDOrdering<int>> lu_;

public:
    void analyze(const SpMat& A) override { lu_.analyzePattern(A); }
    bool factorize(const SpMat& A) override {
        norm_valid_ = false;
        lu_.factorize(A);
        ++pivoted;
        return lu_.info() == Eigen::Success;
    }
    void solve_in_place(Eigen::VectorXd& x) override {
        const Eigen::VectorXd b = x;
        x = lu_.solve(b);
    }
    void solve_in_place(Eigen::MatrixXd& X) override {
        const Eigen::MatrixXd B = X;
        X = lu_.solve(B);
    }
};

#ifdef STACKBEAM_HAVE_KLU
/// SuiteSparse's KLU (Gilbert-Peierls left-looking LU with partial pivoting): klu_analyze
/// (block triangular form and AMD) once per pattern. Each new matrix is first refactorised
/// on the last factorisation's pivot sequence (klu_refactor: no pivot search, no symbolic
/// work, about half a klu_factor); that factor is kept when its pivots are as good as those
/// of the last factorisation with pivoting: reciprocal pivot growth (klu_rgrowth) and
/// pivot ratio (klu_rcond: min / max |u_ii|) at least kRefactorKeep of that one's. Else
/// (a held set whose new rows the old pivots do not suit) klu_factor pivots afresh.
/// The solves are refined against the explicit matrix by the caller either way.
/// With `residual_check` (Switches::residual_refactor_check, the default) a refactorisation
/// is kept on its pivot ratio alone (klu_rcond, O(n)) and marked unchecked: its solves'
/// backward error decides (PatternLu::refined_solve), instead of klu_rgrowth's O(nnz(U))
/// pass per factorisation (7 % of the 10 x 400 runs, docs/decisions/035).
class KluPatternLu final : public PatternLu {
public:
    explicit KluPatternLu(bool residual_check) : residual_check_(residual_check) { klu_defaults(&common_); }
    ~KluPatternLu() override { release(); }
    KluPatternLu(const KluPatternLu&) = delete;
    KluPatternLu& operator=(const KluPatternLu&) = delete;

private:
    // a refactorisation is kept while its growth and pivot ratio are within this factor of
    // the last pivoted factorisation's (measured on the 10 x 400 stacks: the same to 3 digits
    // across held sets, so the factor 1e-2 only rejects a pivot sequence that no longer fits)
    static constexpr double kRefactorKeep = 1e-2;
    klu_common common_{};
    klu_symbolic* symbolic_ = nullptr;
    klu_numeric* numeric_ = nullptr;
    double fresh_rgrowth_ = 0.0, fresh_rcond_ = 0.0;  // of the last klu_factor
    bool residual_check_ = true;
    bool unchecked_ = false;  // the current factor: a refactorisation kept on klu_rcond alone
    // the current factor in compressed columns (klu_extract), for solve_sparse_in_place: made
    // at its first use after each factorisation
    bool extracted_ = false;
    std::vector<int> lp_, li_, up_, ui_, p_, q_, pinv_;  // (pinv_: P's inverse, for sparse right-hand sides)
    std::vector<double> lx_, ux_, udiag_, rs_, y_;
    void release() {
        extracted_ = false;
        if (numeric_) klu_free_numeric(&numeric_, &common_);
        if (symbolic_) klu_free_symbolic(&symbolic_, &common_);
    }
    /// The factor as L (unit diagonal first in each column), U (diagonal last), P, Q and the
    /// row scaling, one block only (false: a block triangular form, left to klu_solve).
    bool extract() {
        if (extracted_) return true;
        if (!numeric_ || symbolic_->nblocks != 1 || numeric_->nzoff != 0) return false;
        const int n = symbolic_->n;
        lp_.resize(static_cast<std::size_t>(n) + 1);
        up_.resize(static_cast<std::size_t>(n) + 1);
        li_.resize(static_cast<std::size_t>(numeric_->lnz));
        lx_.resize(static_cast<std::size_t>(numeric_->lnz));
        ui_.resize(static_cast<std::size_t>(numeric_->unz));
        ux_.resize(static_cast<std::size_t>(numeric_->unz));
        p_.resize(static_cast<std::size_t>(n));
        q_.resize(static_cast<std::size_t>(n));
        rs_.resize(static_cast<std::size_t>(n));
        if (klu_extract(numeric_, symbolic_, lp_.data(), li_.data(), lx_.data(), up_.data(), ui_.data(), ux_.data(),
                        nullptr, nullptr, nullptr, p_.data(), q_.data(), rs_.data(), nullptr, &common_) == 0)
            return false;
        // the diagonals out of the columns (L's unit first, U's last): strictly triangular
        // parts in place, U's diagonal apart
        udiag_.resize(static_cast<std::size_t>(n));
        int wl = 0, wu = 0;
        for (int k = 0; k < n; ++k) {
            const int l0 = lp_[static_cast<std::size_t>(k)] + 1, l1 = lp_[static_cast<std::size_t>(k) + 1];
            const int u0 = up_[static_cast<std::size_t>(k)], u1 = up_[static_cast<std::size_t>(k) + 1] - 1;
            lp_[static_cast<std::size_t>(k)] = wl;
            for (int q = l0; q < l1; ++q, ++wl) {
                li_[static_cast<std::size_t>(wl)] = li_[static_cast<std::size_t>(q)];
                lx_[static_cast<std::size_t>(wl)] = lx_[static_cast<std::size_t>(q)];
            }
            up_[static_cast<std::size_t>(k)] = wu;
            udiag_[static_cast<std::size_t>(k)] = ux_[static_cast<std::size_t>(u1)];
            for (int q = u0; q < u1; ++q, ++wu) {
                ui_[static_cast<std::size_t>(wu)] = ui_[static_cast<std::size_t>(q)];
                ux_[static_cast<std::size_t>(wu)] = ux_[static_cast<std::size_t>(q)];
            }
        }
        lp_[static_cast<std::size_t>(n)] = wl;
        up_[static_cast<std::size_t>(n)] = wu;
        pinv_.resize(static_cast<std::size_t>(n));
        for (int k = 0; k < n; ++k) pinv_[static_cast<std::size_t>(p_[static_cast<std::size_t>(k)])] = k;
        extracted_ = true;
        return true;
    }
    // (SpMat's outer and inner indices are int, as KLU's int version takes them; KLU does
    // not write through its non-const pointers)
    static int* ip(const int* p) { return const_cast<int*>(p); }
    static double* vp(const double* p) { return const_cast<double*>(p); }
    /// The pivot quality of the current factor of A: (rgrowth, rcond), or false.
    bool quality(const SpMat& A, double& rgrowth, double& rcond) {
        if (!klu_rcond(symbolic_, numeric_, &common_)) return false;
        rcond = common_.rcond;
        rgrowth = 1.0;
        if (!residual_check_) {
            if (!klu_rgrowth(ip(A.outerIndexPtr()), ip(A.innerIndexPtr()), vp(A.valuePtr()), symbolic_, numeric_,
                             &common_))
                return false;
            rgrowth = common_.rgrowth;
        }
        return std::isfinite(rgrowth) && std::isfinite(rcond);
    }
    bool pivot(const SpMat& A) {
        double rgrowth = 0.0, rcond = 0.0;
        extracted_ = false;
        if (numeric_) klu_free_numeric(&numeric_, &common_);
        numeric_ = klu_factor(ip(A.outerIndexPtr()), ip(A.innerIndexPtr()), vp(A.valuePtr()), symbolic_, &common_);
        if (numeric_ == nullptr || common_.status != KLU_OK || !quality(A, rgrowth, rcond)) {
            if (numeric_) klu_free_numeric(&numeric_, &common_);
            return false;
        }
        fresh_rgrowth_ = rgrowth;
        fresh_rcond_ = rcond;
        ++pivoted;
        return true;
    }

public:
    void analyze(const SpMat& A) override {
        release();
        symbolic_ = klu_analyze(static_cast<int>(A.rows()), ip(A.outerIndexPtr()), ip(A.innerIndexPtr()), &common_);
    }
    bool factorize(const SpMat& A) override {
        if (!symbolic_) return false;
        norm_valid_ = false;
        unchecked_ = false;
        extracted_ = false;
        double rgrowth = 0.0, rcond = 0.0;
        if (numeric_ && klu_refactor(ip(A.outerIndexPtr()), ip(A.innerIndexPtr()), vp(A.valuePtr()), symbolic_,
                                     numeric_, &common_) &&
            common_.status == KLU_OK && quality(A, rgrowth, rcond) && rgrowth >= kRefactorKeep * fresh_rgrowth_ &&
            rcond >= kRefactorKeep * fresh_rcond_) {
            ++reused;
            unchecked_ = residual_check_;
            return true;
        }
        return pivot(A);
    }
    /// klu_held: the set's own system under the given order (no BTF: one block in that order).
    void analyze_given(const SpMat& A, const std::vector<int>& order) override {
        release();
        const int btf = common_.btf;
        common_.btf = 0;
        const int n = static_cast<int>(A.rows());
        int* q = order.empty() ? nullptr : const_cast<int*>(order.data());
        symbolic_ = q ? klu_analyze_given(n, ip(A.outerIndexPtr()), ip(A.innerIndexPtr()), q, q, &common_)
                      : klu_analyze(n, ip(A.outerIndexPtr()), ip(A.innerIndexPtr()), &common_);
        common_.btf = btf;
    }
    /// AMD's ordering of A + A^T (klu_analyze without BTF: one block).
    std::vector<int> ordering(const SpMat& A) override {
        const int btf = common_.btf;
        common_.btf = 0;
        const int n = static_cast<int>(A.rows());
        klu_symbolic* sym = klu_analyze(n, ip(A.outerIndexPtr()), ip(A.innerIndexPtr()), &common_);
        common_.btf = btf;
        std::vector<int> order;
        if (sym) {
            order.assign(sym->Q, sym->Q + n);
            klu_free_symbolic(&sym, &common_);
        }
        return order;
    }
    bool unchecked() const override { return unchecked_; }
    bool repivot(const SpMat& A) override {
        unchecked_ = false;
        ++repivoted;
        return pivot(A);
    }
    void solve_in_place(Eigen::VectorXd& x) override {
        klu_solve(symbolic_, numeric_, static_cast<int>(x.size()), 1, x.data(), &common_);
    }
    void solve_in_place(Eigen::MatrixXd& X) override {
        if (X.cols() == 0) return;
        klu_solve(symbolic_, numeric_, static_cast<int>(X.rows()), static_cast<int>(X.cols()), X.data(), &common_);
    }
    /// klu_solve's arithmetic (X = Q U^-1 L^-1 P (R \ X), each column's own) on the extracted
    /// factor, skipping each column of L and U whose multipliers are all zero: a unit right-hand
    /// side's forward solve touches only the factor's columns it reaches (docs/decisions/043).
    /// Up to four columns go through the factor together, their entries side by side (y:
    /// row k's entries at NB k .. NB k + NB - 1): the backward solve is a chain of dependent
    /// rows (a row's division waits for the update from the row solved just before it), and
    /// independent columns fill that chain's latency (docs/decisions/047). A column's
    /// arithmetic stays its own: where its multiplier is zero and another's is not, it
    /// subtracts zero products, which change no value (only, at most, the sign of a zero).
    void solve_sparse_in_place(Eigen::MatrixXd& X) override {
        if (X.cols() == 0) return;
        if (!extract()) {
            solve_in_place(X);
            return;
        }
        Eigen::Index c = 0;
        for (; c + 4 <= X.cols(); c += 4) sparse_columns<4>(X, c);
        for (; c + 2 <= X.cols(); c += 2) sparse_columns<2>(X, c);
        if (c < X.cols()) sparse_columns<1>(X, c);
    }
    /// The same for B given by its nonzeros: the permuted, scaled right-hand side made from
    /// them alone (the dense B's gather read n entries per column, nearly all zero, and the
    /// caller zeroed them first: two O(n) passes per column, decision 049); X written whole by
    /// the final permutation.
    void solve_sparse_columns(const SparseColumns& B, int n, Eigen::MatrixXd& X) override {
        if (B.cols() == 0) {
            X.resize(n, 0);
            return;
        }
        if (!extract() || symbolic_->n != n) {
            PatternLu::solve_sparse_columns(B, n, X);
            return;
        }
        X.resize(n, B.cols());
        Eigen::Index c = 0;
        for (; c + 4 <= X.cols(); c += 4) sparse_columns<4>(X, c, &B);
        for (; c + 2 <= X.cols(); c += 2) sparse_columns<2>(X, c, &B);
        if (c < X.cols()) sparse_columns<1>(X, c, &B);
    }

private:
    /// Columns c0 .. c0 + NB - 1 of X = A^-1 X, or (B given) of X = A^-1 B.
    template <int NB>
    void sparse_columns(Eigen::MatrixXd& X, Eigen::Index c0, const SparseColumns* B = nullptr) {
        const int n = symbolic_->n;
        const int* lp = lp_.data();
        const int* li = li_.data();
        const double* lx = lx_.data();
        const int* up = up_.data();
        const int* ui = ui_.data();
        const double* ux = ux_.data();
        const double* ud = udiag_.data();
        const int* perm = p_.data();
        const int* qperm = q_.data();
        const double* rs = rs_.data();
        y_.resize(static_cast<std::size_t>(NB) * static_cast<std::size_t>(n));
        double* y = y_.data();
        double* b[NB];
        for (int c = 0; c < NB; ++c) b[c] = X.col(c0 + c).data();
        if (B) {  // the same entries: 0.0 where B's is zero, else B's / rs at its permuted row
            std::fill(y, y + static_cast<std::size_t>(NB) * static_cast<std::size_t>(n), 0.0);
            const int* pinv = pinv_.data();
            for (int c = 0; c < NB; ++c) {
                const std::size_t col = static_cast<std::size_t>(c0 + c);
                for (int p = B->start[col]; p < B->start[col + 1]; ++p) {
                    const int k = pinv[B->row[static_cast<std::size_t>(p)]];
                    const double v = B->value[static_cast<std::size_t>(p)];
                    y[NB * k + c] = v == 0.0 ? 0.0 : v / rs[k];
                }
            }
        } else {
            for (int k = 0; k < n; ++k) {
                const int i = perm[k];
                for (int c = 0; c < NB; ++c) {
                    const double v = b[c][i];
                    y[NB * k + c] = v == 0.0 ? 0.0 : v / rs[k];
                }
            }
        }
        for (int k = 0; k < n; ++k) {  // L (unit diagonal)
            double x[NB];
            bool any = false;
            for (int c = 0; c < NB; ++c) {
                x[c] = y[NB * k + c];
                any = any || x[c] != 0.0;
            }
            if (!any) continue;
            for (int q = lp[k]; q < lp[k + 1]; ++q) {
                const double l = lx[q];
                double* t = y + NB * li[q];
                for (int c = 0; c < NB; ++c) t[c] -= l * x[c];
            }
        }
        for (int k = n - 1; k >= 0; --k) {  // U
            bool any = false;
            for (int c = 0; c < NB; ++c) any = any || y[NB * k + c] != 0.0;
            if (!any) continue;
            double x[NB];
            for (int c = 0; c < NB; ++c) {
                x[c] = y[NB * k + c] / ud[k];
                y[NB * k + c] = x[c];
            }
            for (int q = up[k]; q < up[k + 1]; ++q) {
                const double u = ux[q];
                double* t = y + NB * ui[q];
                for (int c = 0; c < NB; ++c) t[c] -= u * x[c];
            }
        }
        for (int k = 0; k < n; ++k)
            for (int c = 0; c < NB; ++c) b[c][qperm[k]] = y[NB * k + c];
    }
};
#endif

}  // namespace

bool klu_built() {
#ifdef STACKBEAM_HAVE_KLU
    return true;
#else
    return false;
#endif
}

std::unique_ptr<PatternLu> make_pattern_lu(FixedPatternLu lu, bool residual_check) {
#ifdef STACKBEAM_HAVE_KLU
    if (lu == FixedPatternLu::klu) return std::make_unique<KluPatternLu>(residual_check);
    // the held set's own system: a fresh pattern per set, so every factorisation pivots (and
    // no klu_rgrowth: it only judges refactorisations)
    if (lu == FixedPatternLu::klu_held || lu == FixedPatternLu::klu_held_amd)
        return std::make_unique<KluPatternLu>(true);
#endif
    (void)lu;
    (void)residual_check;
    return std::make_unique<EigenPatternLu>();
}

bool PatternLu::accept_solve(const SpMat& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& X) {
    if (!unchecked()) return true;
    if (!norm_valid_) {  // ||A||_inf: the largest row sum of |A|
        Eigen::VectorXd rows = Eigen::VectorXd::Zero(A.rows());
        for (int j = 0; j < A.outerSize(); ++j)
            for (SpMat::InnerIterator it(A, j); it; ++it) rows[it.row()] += std::abs(it.value());
        a_norm_ = rows.size() > 0 ? rows.maxCoeff() : 0.0;
        norm_valid_ = true;
    }
    for (Eigen::Index c = 0; c < X.cols(); ++c) {
        const double r = (B.col(c) - A * X.col(c)).lpNorm<Eigen::Infinity>();
        const double scale = a_norm_ * X.col(c).lpNorm<Eigen::Infinity>() + B.col(c).lpNorm<Eigen::Infinity>();
        if (!(r <= kMaxBackwardError * scale)) return false;
    }
    return true;
}

bool PatternLu::refined_solve(const SpMat& A, Eigen::VectorXd& x) {
    Eigen::MatrixXd X = x;  // (one column: the same code as the multi-column solve)
    if (!refined_solve(A, X)) return false;
    x = X.col(0);
    return true;
}

bool PatternLu::refined_solve(const SpMat& A, Eigen::MatrixXd& X) {
    const Eigen::MatrixXd B = X;
    solve_in_place(X);
    if (!accept_solve(A, B, X)) {  // the old pivots no longer suit this matrix: pivot afresh
        if (!repivot(A)) return false;
        X = B;
        solve_in_place(X);
    }
    Eigen::MatrixXd res = B - A * X;  // one step of iterative refinement
    solve_in_place(res);
    X += res;
    return true;
}

void FixedSaddle::reset(const SparseStiffness& st, const std::vector<std::pair<int, int>>& couplings) {
    st_ = &st;
    couplings_ = couplings;
    analysed_ = false;
    analyses_ = 0;
    build_pattern();
}

/// The pattern: Dz K Dz; per contact row i its column -Dz g_i^T and row g_i Dz at n + i and
/// its diagonal; per coupling (t, n_r) g_t's entries in column n + n_r. K's values once, then
/// the slot of each contact entry in A_'s value array, so that each set fills its values in O(nnz(G)).
void FixedSaddle::build_pattern() {
    const SparseStiffness& st = *st_;
    const int n = st.dofs(), m = st.rows();
    coupling_of_t_.assign(static_cast<std::size_t>(m), -1);
    for (std::size_t a = 0; a < couplings_.size(); ++a)
        coupling_of_t_[static_cast<std::size_t>(couplings_[a].first)] = static_cast<int>(a);
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(static_cast<std::size_t>(st.K.nonZeros() + 2 * st.Gt_scaled.nonZeros() + m));
    for (int j = 0; j < st.K.outerSize(); ++j)
        for (SpMat::InnerIterator it(st.K, j); it; ++it) t.emplace_back(it.row(), it.col(), 1.0);
    for (int i = 0; i < m; ++i) {
        for (SpMat::InnerIterator it(st.Gt_scaled, i); it; ++it) {
            t.emplace_back(it.row(), n + i, 1.0);
            t.emplace_back(n + i, it.row(), 1.0);
        }
        t.emplace_back(n + i, n + i, 1.0);
    }
    for (const auto& c : couplings_)
        for (SpMat::InnerIterator it(st.Gt_scaled, c.first); it; ++it) t.emplace_back(it.row(), n + c.second, 1.0);
    A_.resize(n + m, n + m);
    A_.setFromTriplets(t.begin(), t.end());
    A_.makeCompressed();
    std::fill(A_.valuePtr(), A_.valuePtr() + A_.nonZeros(), 0.0);
    for (int j = 0; j < st.K.outerSize(); ++j)  // Dz K Dz: the same for every set
        for (SpMat::InnerIterator it(st.K, j); it; ++it)
            A_.valuePtr()[slot(A_, static_cast<int>(it.row()), j)] = it.value() * st.dz[it.row()] * st.dz[j];
    gcol_slot_.clear();
    grow_slot_.clear();
    diag_slot_.assign(static_cast<std::size_t>(m), 0);
    for (int i = 0; i < m; ++i) {
        for (SpMat::InnerIterator it(st.Gt_scaled, i); it; ++it) {
            gcol_slot_.push_back(slot(A_, static_cast<int>(it.row()), n + i));
            grow_slot_.push_back(slot(A_, n + i, static_cast<int>(it.row())));
        }
        diag_slot_[static_cast<std::size_t>(i)] = slot(A_, n + i, n + i);
    }
    order_.clear();  // (klu_held: the ordering of this pattern, made at the first factor)
    cpl_slot_.assign(couplings_.size(), {});
    for (std::size_t a = 0; a < couplings_.size(); ++a)
        for (SpMat::InnerIterator it(st.Gt_scaled, couplings_[a].first); it; ++it)
            cpl_slot_[a].push_back(slot(A_, static_cast<int>(it.row()), n + couplings_[a].second));
    analysed_ = false;
}

bool FixedSaddle::factor(const modes::ModeLinearization& lin, const std::vector<int>& pos,
                         const Eigen::VectorXd& row_scale) {
    const SparseStiffness& st = *st_;
    const int m = st.rows();
    // a coupling outside the pattern (not among the pairs given to reset): extend it
    bool extend = false;
    for (const auto& c : lin.coupled) {
        const int a = coupling_of_t_[static_cast<std::size_t>(c.first)];
        if (a < 0 || couplings_[static_cast<std::size_t>(a)].second != c.second) {
            if (a >= 0) couplings_[static_cast<std::size_t>(a)] = c;  // (never: one normal row per pair)
            else couplings_.push_back(c);
            extend = true;
        }
    }
    if (extend) build_pattern();
    double* v = A_.valuePtr();
    // K's values stay from build_pattern; the contact rows' columns (n..) are cleared and
    // their rows' entries in the DOF columns (one slot per entry of G) overwritten
    std::fill(v + A_.outerIndexPtr()[st.dofs()], v + A_.nonZeros(), 0.0);
    std::size_t j = 0;
    for (int i = 0; i < m; ++i) {
        const int at = pos[static_cast<std::size_t>(i)];
        const double s = at >= 0 ? row_scale[at] : 0.0;
        for (SpMat::InnerIterator it(st.Gt_scaled, i); it; ++it, ++j) {
            v[gcol_slot_[j]] += -it.value() * s;
            v[grow_slot_[j]] = it.value() * s;
        }
        v[diag_slot_[static_cast<std::size_t>(i)]] = at >= 0 ? 0.0 : 1.0;
    }
    for (std::size_t a = 0; a < lin.coupled.size(); ++a) {
        const int col = pos[static_cast<std::size_t>(lin.coupled[a].second)];
        if (col < 0) continue;  // the normal row is not held: its force is fixed (e)
        const auto& slots = cpl_slot_[static_cast<std::size_t>(coupling_of_t_[static_cast<std::size_t>(lin.coupled[a].first)])];
        std::size_t q = 0;
        for (SpMat::InnerIterator it(st.Gt_scaled, lin.coupled[a].first); it; ++it, ++q)
            v[slots[q]] += -lin.coef[a] * it.value() * row_scale[col];
    }
    held_ = lin.S;
    if (held_system_) {
        // the held set's own system under the fixed pattern's ordering restricted to its
        // unknowns: eliminating a subset of a graph's vertices in the induced order fills no
        // more than in the whole graph, and the rows not held add no fill at all
        if (!analysed_) {
            if (!held_amd_) order_ = lu_->ordering(A_);
            analysed_ = true;
            ++analyses_;
        }
        extract_held(pos);
        std::vector<int> order;
        if (!held_amd_) {
            order.reserve(static_cast<std::size_t>(As_.rows()));
            for (const int k : order_)
                if (sub_of_[static_cast<std::size_t>(k)] >= 0) order.push_back(sub_of_[static_cast<std::size_t>(k)]);
        }
        lu_->analyze_given(As_, order);
        return lu_->factorize(As_);
    }
    if (!analysed_) {
        lu_->analyze(A_);
        analysed_ = true;
        ++analyses_;
    }
    return lu_->factorize(A_);
}

/// As_: the rows and columns of A_ of the DOFs and the held rows (in held_'s order), its
/// explicit zeros (the rows not held, the couplings not slipping, the held rows' diagonal) left
/// out. Written straight into As_'s arrays, whose storage the next set reuses (no allocation
/// per set once As_ has held the largest set; docs/decisions/047). A column's rows come out
/// sorted as A_'s are where held_ is ascending; else that column is sorted.
void FixedSaddle::extract_held(const std::vector<int>& pos) {
    const int n = st_->dofs(), m = st_->rows();
    const int ms = static_cast<int>(held_.size());
    sub_of_.resize(static_cast<std::size_t>(n + m));
    for (int i = 0; i < n; ++i) sub_of_[static_cast<std::size_t>(i)] = i;
    for (int r = 0; r < m; ++r) {
        const int at = pos[static_cast<std::size_t>(r)];
        sub_of_[static_cast<std::size_t>(n + r)] = at >= 0 ? n + at : -1;
    }
    const int ns = n + ms;
    As_.resize(ns, ns);
    As_.resizeNonZeros(A_.nonZeros());  // (a bound: the set's entries are among A_'s)
    int* outer = As_.outerIndexPtr();
    int* inner = As_.innerIndexPtr();
    double* values = As_.valuePtr();
    const int* a_outer = A_.outerIndexPtr();
    const int* a_inner = A_.innerIndexPtr();
    const double* a_values = A_.valuePtr();
    int w = 0;
    outer[0] = 0;
    for (int c = 0; c < ns; ++c) {
        const int full = c < n ? c : n + held_[static_cast<std::size_t>(c - n)];
        const int start = w;
        bool sorted = true;
        for (int q = a_outer[full]; q < a_outer[full + 1]; ++q) {
            const int r = sub_of_[static_cast<std::size_t>(a_inner[q])];
            if (r < 0 || a_values[q] == 0.0) continue;
            if (w > start && r < inner[w - 1]) sorted = false;
            inner[w] = r;
            values[w] = a_values[q];
            ++w;
        }
        if (!sorted) {
            col_.clear();
            for (int q = start; q < w; ++q) col_.emplace_back(inner[q], values[q]);
            std::sort(col_.begin(), col_.end());
            for (int q = start; q < w; ++q) {
                inner[q] = col_[static_cast<std::size_t>(q - start)].first;
                values[q] = col_[static_cast<std::size_t>(q - start)].second;
            }
        }
        outer[c + 1] = w;
    }
    As_.resizeNonZeros(w);
}

/// The variable system's layout (n DOFs, then the held rows in lin.S's order) to the fixed
/// one's (n DOFs, then every contact row; zero outside S), and back.
Eigen::VectorXd FixedSaddle::scatter(const Eigen::VectorXd& x) const {
    const int n = st_->dofs(), m = st_->rows();
    Eigen::VectorXd full = Eigen::VectorXd::Zero(n + m);
    full.head(n) = x.head(n);
    for (std::size_t i = 0; i < held_.size(); ++i) full[n + held_[i]] = x[n + static_cast<Eigen::Index>(i)];
    return full;
}

Eigen::VectorXd FixedSaddle::gather(const Eigen::VectorXd& full) const {
    const int n = st_->dofs();
    Eigen::VectorXd x(n + static_cast<Eigen::Index>(held_.size()));
    x.head(n) = full.head(n);
    for (std::size_t i = 0; i < held_.size(); ++i) x[n + static_cast<Eigen::Index>(i)] = full[n + held_[i]];
    return x;
}

Eigen::VectorXd FixedSaddle::multiply(const Eigen::VectorXd& x) const {
    if (held_system_) return As_ * x;
    return gather(A_ * scatter(x));
}

Eigen::VectorXd FixedSaddle::solve(const Eigen::VectorXd& r) {
    if (held_system_) {
        Eigen::VectorXd x = r;
        if (!lu_->refined_solve(As_, x)) throw SingularModes{};
        return x;
    }
    Eigen::VectorXd x = scatter(r);
    if (!lu_->refined_solve(A_, x)) throw SingularModes{};
    return gather(x);
}

void FixedSaddle::solve_in_place(Eigen::MatrixXd& R, bool refine) {
    if (!held_system_) {
        R = solve(R, refine);
        return;
    }
    if (!refine) lu_->solve_sparse_in_place(R);
    else if (!lu_->refined_solve(As_, R)) throw SingularModes{};
}

void FixedSaddle::solve_unit_columns(const SparseColumns& B, Eigen::MatrixXd& X) {
    if (held_system_) {
        lu_->solve_sparse_columns(B, static_cast<int>(As_.rows()), X);
        return;
    }
    X = B.dense(st_->dofs() + static_cast<int>(held_.size()));
    solve_in_place(X, false);
}

Eigen::MatrixXd FixedSaddle::solve(const Eigen::MatrixXd& R, bool refine) {
    if (held_system_) {
        Eigen::MatrixXd X = R;
        solve_in_place(X, refine);
        return X;
    }
    const int n = st_->dofs(), m = st_->rows();
    Eigen::MatrixXd X = Eigen::MatrixXd::Zero(n + m, R.cols());
    X.topRows(n) = R.topRows(n);
    for (std::size_t i = 0; i < held_.size(); ++i) X.row(n + held_[i]) = R.row(n + static_cast<Eigen::Index>(i));
    if (!refine) lu_->solve_sparse_in_place(X);
    else if (!lu_->refined_solve(A_, X)) throw SingularModes{};
    Eigen::MatrixXd out(n + static_cast<Eigen::Index>(held_.size()), R.cols());
    out.topRows(n) = X.topRows(n);
    for (std::size_t i = 0; i < held_.size(); ++i) out.row(n + static_cast<Eigen::Index>(i)) = X.row(n + held_[i]);
    return out;
}

}  // namespace stackbeam::detail::sparse
