#pragma once
// Internal to the homotopy (path_following.cpp, path_base.cpp; docs/decisions/040-045): the
// equations of a set of modes, the columns y_r of the rows that differ from the base, the
// bordered system on them, and the base kept across steps (KeptBase).
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>

#include "contact/sparse/driver/common.hpp"
#include "contact/sparse/driver/trace.hpp"
#include "contact/sparse/transitions/transitions.hpp"

namespace stackbeam::detail::sparse {

constexpr int kMaxBreakpoints = 400;   // then the caller's fallback
constexpr int kMaxChangedRows = 400;   // |C|: the dense H's size (and the columns' memory)
constexpr int kMaxStalls = 20;         // breakpoints in a row that do not advance t
constexpr double kSameT = 1e-12;       // hits within this of the first are simultaneous (and a pair back
                                       // in the mode it left within this of t: a fold)

/// One contact row's equation under a set of modes.
struct Eq {
    enum Kind : signed char { held, zero, slip } kind = zero;
    int other = -1;      ///< slip: the coupled normal row (or -1)
    double coef = 0.0;   ///< slip: p_t - coef p_n = e
    double e = 0.0;      ///< slip: its right-hand side [N]
    bool operator==(const Eq& o) const { return kind == o.kind && other == o.other && coef == o.coef && e == o.e; }
    bool operator!=(const Eq& o) const { return !(*this == o); }
    /// a_r x for x given by an accessor of its force (row) and G z (m + row) entries.
    template <class F>
    double apply(int r, int m, const F& x) const {
        if (kind == held) return x(m + r);
        if (kind == zero) return x(r);
        return x(r) - (other >= 0 ? coef * x(other) : 0.0);
    }
    double rhs(int r, const Eigen::VectorXd& d) const { return kind == held ? d[r] : kind == slip ? e : 0.0; }
};

/// The equations of pair k's rows under (nmode, tmode), as ModeSet::linearize writes them
/// (TauRule::current only).
inline void pair_equations(const ContactPair& c, signed char nm, signed char tm, Eq& en, Eq& et) {
    en = Eq{};
    et = Eq{};
    if (c.row_n >= 0 && nm == modes::CLOSED) en.kind = Eq::held;
    if (c.row_t < 0) return;
    if (tm == modes::STICK) {
        et.kind = Eq::held;
    } else if (tm == modes::SLIP_POS || tm == modes::SLIP_NEG) {
        const double sigma = tm == modes::SLIP_POS ? 1.0 : -1.0, mu = c.friction_coefficient;
        et.kind = Eq::slip;
        if (c.kind == PairKind::clamp) {
            et.e = sigma * mu * c.preload_n;
            if (c.row_n >= 0) {
                et.other = c.row_n;
                et.coef = -sigma * mu;
            }
        } else {
            et.other = c.row_n;
            et.coef = -sigma * mu;
        }
    }
}

/// The columns y_r of the path (2m rows: the forces, then G z), stored in panels of kWidth
/// columns, each panel row-major: one row's entries of a panel share a cache line. A row's
/// dot product with lambda (the ratio test's x0 / x1) reads ncol / kWidth lines (decision 043).
/// The columns of the last, incomplete panel are kept apart, each contiguous (the stage), and
/// go into their panel together when it is complete (one sequential pass): written into the
/// panel one by one, each new column touched one cache line per row (2m lines, the panel's
/// whole 0.55 MB at 10 x 400 for 69 KB of values, the lines mostly out of cache after the
/// solves between two columns), and each new panel was zeroed first (decision 049). The sums
/// are the same to the last bit: the stage's row is read in the panel's slot order, with the
/// panel's 0.0 in the slots of columns not added yet.
class ColumnStore {
public:
    static constexpr int kWidth = 8;
    explicit ColumnStore(int rows)
        : rows_(rows), stage_(static_cast<std::size_t>(rows) * kWidth) {}
    int size() const { return ncol_; }
    /// the columns rounded up to whole panels (lambda's padded length)
    int padded() const { return (ncol_ + kWidth - 1) / kWidth * kWidth; }
    double operator()(int q, int c) const {
        if (c / kWidth < full_) return panels_[static_cast<std::size_t>(c / kWidth)][slot(q, c)];
        return stage_[static_cast<std::size_t>(c % kWidth) * static_cast<std::size_t>(rows_) + static_cast<std::size_t>(q)];
    }
    /// sum_c Y(q, c) L[c] over the columns (L: padded() entries, zero past size())
    double dot(int q, const Eigen::VectorXd& L) const {
        double sum = 0.0;
        const double* l = L.data();
        for (int p = 0; p < full_; ++p, l += kWidth) {
            const double* y = panels_[static_cast<std::size_t>(p)].get() + static_cast<std::size_t>(q) * kWidth;
            double s = 0.0;
            for (int i = 0; i < kWidth; ++i) s += y[i] * l[i];
            sum += s;
        }
        if (staged_ > 0) {
            double s = 0.0;
            for (int i = 0; i < kWidth; ++i) s += staged(q, i) * l[i];
            sum += s;
        }
        return sum;
    }
    /// dot(q, L0) and dot(q, L1) in one pass over the row (the same sums)
    void dot2(int q, const Eigen::VectorXd& L0, const Eigen::VectorXd& L1, double& a, double& b) const {
        a = b = 0.0;
        const double* l0 = L0.data();
        const double* l1 = L1.data();
        for (int p = 0; p < full_; ++p, l0 += kWidth, l1 += kWidth) {
            const double* y = panels_[static_cast<std::size_t>(p)].get() + static_cast<std::size_t>(q) * kWidth;
            double s0 = 0.0, s1 = 0.0;
            for (int i = 0; i < kWidth; ++i) {
                s0 += y[i] * l0[i];
                s1 += y[i] * l1[i];
            }
            a += s0;
            b += s1;
        }
        if (staged_ > 0) {
            double s0 = 0.0, s1 = 0.0;
            for (int i = 0; i < kWidth; ++i) {
                const double y = staged(q, i);
                s0 += y * l0[i];
                s1 += y * l1[i];
            }
            a += s0;
            b += s1;
        }
    }
    /// A new column: its `rows` entries to be written at the pointer returned, then commit()
    /// (which returns its index).
    double* next() { return stage_.data() + static_cast<std::size_t>(staged_) * static_cast<std::size_t>(rows_); }
    int commit() {
        const int c = ncol_++;
        if (++staged_ == kWidth) flush();
        return c;
    }
    /// Forgets every column (a new base; the panels' memory is kept for the next ones).
    void clear() { ncol_ = full_ = staged_ = 0; }

private:
    static std::size_t slot(int q, int c) { return static_cast<std::size_t>(q) * kWidth + static_cast<std::size_t>(c % kWidth); }
    /// the stage's entry (q, i), 0.0 where column i of the panel is not added yet
    double staged(int q, int i) const {
        return i < staged_ ? stage_[static_cast<std::size_t>(i) * static_cast<std::size_t>(rows_) + static_cast<std::size_t>(q)]
                           : 0.0;
    }
    /// the complete stage into the next panel (every entry written: no zeroing), row by row
    void flush() {
        if (full_ == static_cast<int>(panels_.size()))
            panels_.emplace_back(new double[static_cast<std::size_t>(rows_) * kWidth]);  // (uninitialised)
        double* y = panels_[static_cast<std::size_t>(full_)].get();
        const double* st = stage_.data();
        const std::size_t n = static_cast<std::size_t>(rows_);
        for (std::size_t q = 0; q < n; ++q, y += kWidth)
            for (std::size_t i = 0; i < static_cast<std::size_t>(kWidth); ++i) y[i] = st[i * n + q];
        ++full_;
        staged_ = 0;
    }
    int rows_;
    int ncol_ = 0, full_ = 0, staged_ = 0;  // columns; complete panels; columns in the stage
    std::vector<std::unique_ptr<double[]>> panels_;
    std::vector<double> stage_;  // kWidth columns of `rows_` entries each
};

/// A pair whose mode condition fails on the rest of the path, its new mode (normal or
/// tangential) and where. A condition g [m] is affine along the path (within one set of
/// modes) and valid while g <= the passes' acceptance (kAccept x tolerance_m).
struct Hit {
    int k;
    bool normal;
    signed char to;
    double t;
};

/// The equations of every contact row under the modes (n, t) into eq (m rows).
inline void mode_equations(const ContactProblem& laws, const std::vector<signed char>& n, const std::vector<signed char>& t,
                    std::vector<Eq>& eq) {
    eq.assign(static_cast<std::size_t>(laws.size()), Eq{});
    for (int k = 0; k < static_cast<int>(laws.pairs.size()); ++k) {
        const auto& c = laws.pairs[k];
        Eq en, et;
        pair_equations(c, n[k], t[k], en, et);
        if (c.row_n >= 0) eq[c.row_n] = en;
        if (c.row_t >= 0) eq[c.row_t] = et;
    }
}

/// The rows whose equation in eq differs from the base's, ascending, into C.
inline void changed_rows(const std::vector<Eq>& eq, const std::vector<Eq>& base, std::vector<int>& C) {
    C.clear();
    for (int row = 0; row < static_cast<int>(eq.size()); ++row)
        if (eq[static_cast<std::size_t>(row)] != base[static_cast<std::size_t>(row)]) C.push_back(row);
}

/// The bordered system on the rows C that differ from the base (metres both ways: a force
/// equation's row scaled by W_rr; the columns are scaled): H(i, j) = row C[i]'s equation applied to
/// the column of C[j], and F[i] = its right-hand side target(C[i]) minus the equation applied to x.
inline double bordered_row_scale(const Eq& e, int row, const Eigen::VectorXd& W) { return e.kind == Eq::held ? 1.0 : W[row]; }
inline Eigen::MatrixXd bordered_matrix(const std::vector<Eq>& eq, const std::vector<int>& C, const ColumnStore& Y,
                                const std::vector<int>& col, const Eigen::VectorXd& W, int m) {
    const int nc = static_cast<int>(C.size());
    Eigen::MatrixXd H(nc, nc);
    for (int i = 0; i < nc; ++i) {
        const int ri = C[i];
        const double sr = bordered_row_scale(eq[ri], ri, W);
        for (int j = 0; j < nc; ++j) {
            const int cj = col[C[j]];
            H(i, j) = sr * eq[ri].apply(ri, m, [&](int q) { return Y(q, cj); });
        }
    }
    return H;
}
template <class Target>
Eigen::VectorXd bordered_rhs(const std::vector<Eq>& eq, const std::vector<int>& C, const Eigen::VectorXd& W, int m,
                             const Target& target, const Eigen::VectorXd& x) {
    Eigen::VectorXd F(static_cast<int>(C.size()));
    for (int i = 0; i < F.size(); ++i) {
        const int ri = C[i];
        F[i] = bordered_row_scale(eq[ri], ri, W) * (target(ri) - eq[ri].apply(ri, m, [&](int q) { return x[q]; }));
    }
    return F;
}

// the kept base's refinement (solve_on_kept_base): at most this many corrections, while each
// at least halves the held rows' residual |G z - d|, until it is at most kKeptResidual x the
// round-off of s = G z - d (SparseStiffness::roundoff, 1e-13 of its terms: the passes' own
// floor), 1e-16 relative, what a direct solve of the whole system reaches (measured, graduated
// 10 x 400, 100 ms: KLU's and Eigen's refined solves 4e-18 to 2e-17 m, the kept solves 1e-18 to
// 6e-17 m after 0 or 1 correction); where it stops decreasing first, taken at most kKeptStall x
// the round-off, else the caller factorises
constexpr int kKeptCorrections = 4;
constexpr double kKeptResidual = 1e-3;
constexpr double kKeptStall = 1e-2;
constexpr double kKeptRcond = 1e-12;  // the bordered system's (H's) reciprocal condition: below, a factorisation


/// The homotopy's base (Switches::path_keep_base, docs/decisions/045): the base modes' linear
/// problem, key and equations, the columns y_r solved on its factorisation (ColumnStore, scaled
/// to about a metre of motion) and its solutions x^ = [forces; G z] for the last two data. The
/// columns depend on the base's system only (K, G, the base modes' equations: a slip row's
/// coupling -sigma mu and a clamp's sigma mu F_c are the pair's data), not on a step's b and d, so
/// they stay valid while the mode solver's current factorisation is the base's key (the same K
/// and G: SparsePath::reset drops this).
struct KeptBase {
    explicit KeptBase(int m) : eqs(static_cast<std::size_t>(m)), Y(2 * m), col(static_cast<std::size_t>(m), -1), rn2(Eigen::VectorXd::Zero(2 * m)) {}
    modes::ModeLinearization lin;  ///< the base modes' linear problem
    std::vector<signed char> key;  ///< its key (the mode solver's)
    std::vector<Eq> eqs;           ///< per contact row its base equation
    ColumnStore Y;                 ///< the columns y_r (2m rows: forces, then G z)
    /// their displacement parts, scaled alike (with path_keep_base): the first n rows of the
    /// first nzc of zc (one column each; the matrices past nzc kept for the next base's columns:
    /// no allocation per column)
    std::vector<Eigen::MatrixXd> zc;
    int nzc = 0;
    /// column j of Z (at least n rows) times s as the next one; where Z is that one column, it
    /// is scaled in place and swapped in (no copy: Z takes an old one's storage, which the
    /// next unit_solves of the same size reuses)
    void add_zc(double s, Eigen::MatrixXd& Z, int j, int n) {
        if (nzc == static_cast<int>(zc.size())) zc.emplace_back();
        Eigen::MatrixXd& out = zc[static_cast<std::size_t>(nzc++)];
        if (Z.cols() == 1) {
            Z.col(0) *= s;  // (the same products as s * Z)
            out.swap(Z);
        } else {
            out = s * Z.col(j).head(n);  // (same size: no reallocation)
        }
    }
    /// the kept displacement part of column c
    Eigen::Map<const Eigen::VectorXd> z_of(int c, int n) const {
        return Eigen::Map<const Eigen::VectorXd>(zc[static_cast<std::size_t>(c)].data(), n);
    }
    std::vector<int> col;          ///< per contact row its column in Y, or -1
    Eigen::VectorXd rn2;           ///< the squared norms of Y's rows (the ratio test's bound)
    struct Solution {
        Eigen::VectorXd b, d, X;   ///< x^ = [forces; G z] for the data (b, d); X empty: none
        Eigen::VectorXd z;         ///< its displacements
    };
    Solution sol[2];
    int next_sol = 0;
    std::shared_ptr<ModeSolver> check[2];  ///< TransitionTrace::check_kept's own mode solvers (tests)
    /// whether the base's factorisation is the mode solver's current one
    bool current(const SparsePath& path) const {
        return !key.empty() && static_cast<int>(col.size()) == path.laws.size() && path.solver.is_current(key) &&
               path.laws.tau_rule == TauRule::current;
    }
    /// the modes (n, t) as the base: their linear problem, key, equations; no columns, no solutions
    void set(const ContactProblem& laws, const modes::ModeSet& modes) {
        modes.linearize(laws, lin);
        key = solver_key(laws, modes);
        mode_equations(laws, modes.nmode, modes.tmode, eqs);
        Y.clear();
        nzc = 0;
        std::fill(col.begin(), col.end(), -1);
        rn2.setZero();
        for (auto& s : sol) s.X.resize(0);
    }
    const Solution* solution(const Eigen::VectorXd& b, const Eigen::VectorXd& d) const {
        for (const auto& s : sol)
            if (s.X.size() > 0 && s.b.size() == b.size() && s.d.size() == d.size() && s.b == b && s.d == d) return &s;
        return nullptr;
    }
};

/// Whether the homotopy keeps its base here (SparsePathMethods::path_keep_base: on, and enough unknowns).
bool keeps_base(const SparsePath& path);

/// x^ of the base for the data (b_j, d_j), j < k (k <= 2), and its displacements into zx[j] where
/// zx is not null: the kept ones reused, the others in one multi-column refined solve with the
/// base's factorisation (ModeSolver::solve_block) and kept. Returns the factorisations (0 where
/// the base is current). Throws SingularModes.
int base_solutions(SparsePath& path, KeptBase& kb, int k, const Eigen::VectorXd* const* b, const Eigen::VectorXd* const* d,
                   Eigen::VectorXd* const* X, Eigen::VectorXd* const* zx = nullptr);

/// The columns y_r of `rows` not in kb yet, solved on the base's factorisation (one multi-column
/// solve without refinement, ModeSolver::unit_solves); where the factorisation is a bordered update
/// or the primal route's, one solve() per column if `per_column`, else nothing (returns -1).
/// Returns the factorisations (0 where the base is current); counts into stats.
int add_columns(SparsePath& path, KeptBase& kb, std::vector<int> rows, bool per_column, PathStats& stats);

}  // namespace stackbeam::detail::sparse
