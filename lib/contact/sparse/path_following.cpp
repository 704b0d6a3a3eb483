// The parametric (homotopy) active-set transition of the sparse path (transitions.hpp,
// path_following; Switches::path_following, docs/decisions/040).
//
// The previous step's problem (b0, d0) was solved with modes M0; this step's is (b1, d1) on
// the same K, G and pairs. Along data(t) = data0 + t (data1 - data0), t in [0, 1], the
// solution of one set of modes is affine in t. Starting from M0 (valid at t = 0), a ratio
// test over the pairs' mode conditions finds the first t* where a mode stops being valid,
// that pair switches, and the path goes on from t*; at t = 1 the modes are this step's
// (Murty, Linear Complementarity, ch. 5: parametric principal pivoting).
//
// Every set of modes on the path is solved as a low-rank change of the base modes' linear
// problem (M0's, or the current modes' after a new base), whose factorisation (the mode
// solver's, one key) is made once: the full system in x = (z, p) is
//     K z - G^T p = b,   per contact row r one equation a_r x = f_r:
//       held (closed normal, stick)   g_r z = d_r
//       zero force (open, free)       p_r = 0
//       slip (p_t = e_t + c p_n)      p_t - c p_n = e_t
// and a set M differs from the base in the equations of a few rows C. With y_r = A0^-1 u_r
// (u_r the unit right-hand side of row r's base equation, scaled to about a metre of
// motion: one column per row that ever changes, solved with the base's factorisation,
// several in one multi-column solve where they are known together, without refinement)
// and x^(t) = A0^-1 f0(t) (the base's solution along the path),
//     x(t) = x^(t) + Y lambda(t),   H lambda = f^M_C(t) - a^M_C x^(t),   H = a^M_C Y,
// i.e. the base's equations hold on the rows outside C and M's on C (Woodbury / bordering;
// slip couplings are ordinary rows here). H is |C| x |C|, dense.
//
// The ratio test needs every pair's conditions at t = 1, but one breakpoint moves lambda
// only: a pair's condition at t = 1 moves by at most kappa_k ||d lambda_1|| (Cauchy-Schwarz
// on the rows of Y its condition reads), so a pair is evaluated exactly (its few entries of
// x^ + Y lambda, O(|C|) each) only where the accumulated bound reaches its slack to the
// acceptance; the others cannot switch.
//
// The answer at t = 1 is confirmed by the caller's active-set passes (so it is the exact
// solver's, solved with refinement); on any failure (no progress in t, too many breakpoints
// or changed rows, a singular H, or too many of the start modes' conditions failing at the
// first ratio test: a broad change, cheaper by the Newton methods; and where the switches say
// so, a pair switching back at the same t or switching too often: Switches::path_fold_ends,
// path_max_pair_switches) the caller falls back to the Newton methods.
//
// The path stays continuous where a pair takes friction with a friction limit of 0 (a pair
// that closes, a clamp back below its preload: Switches::path_clamp_slip): it slips against
// its tangential motion there, and sticks where that comes back to 0 (docs/decisions/042).
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>

#include "contact/sparse/common.hpp"
#include "contact/sparse/trace.hpp"
#include "contact/sparse/transitions.hpp"

namespace stackbeam::detail::sparse {

namespace {

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
void pair_equations(const ContactPair& c, signed char nm, signed char tm, Eq& en, Eq& et) {
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
void mode_equations(const ContactProblem& laws, const std::vector<signed char>& n, const std::vector<signed char>& t,
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
void changed_rows(const std::vector<Eq>& eq, const std::vector<Eq>& base, std::vector<int>& C) {
    C.clear();
    for (int row = 0; row < static_cast<int>(eq.size()); ++row)
        if (eq[static_cast<std::size_t>(row)] != base[static_cast<std::size_t>(row)]) C.push_back(row);
}

/// The bordered system on the rows C that differ from the base (metres both ways: a force
/// equation's row scaled by W_rr; the columns are scaled): H(i, j) = row C[i]'s equation applied to
/// the column of C[j], and F[i] = its right-hand side target(C[i]) minus the equation applied to x.
double bordered_row_scale(const Eq& e, int row, const Eigen::VectorXd& W) { return e.kind == Eq::held ? 1.0 : W[row]; }
Eigen::MatrixXd bordered_matrix(const std::vector<Eq>& eq, const std::vector<int>& C, const ColumnStore& Y,
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

}  // namespace

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

namespace {

/// Whether the homotopy keeps its base here (Switches::path_keep_base: on, and enough unknowns).
bool keeps_base(const SparsePath& path) {
    return path.switches.path_keep_base > 0 && path.stiffness().dofs() >= path.switches.path_keep_base;
}

/// x^ of the base for the data (b_j, d_j), j < k (k <= 2), and its displacements into zx[j] where
/// zx is not null: the kept ones reused, the others in one multi-column refined solve with the
/// base's factorisation (ModeSolver::solve_block) and kept. Returns the factorisations (0 where
/// the base is current). Throws SingularModes.
int base_solutions(SparsePath& path, KeptBase& kb, int k, const Eigen::VectorXd* const* b, const Eigen::VectorXd* const* d,
                   Eigen::VectorXd* const* X, Eigen::VectorXd* const* zx = nullptr) {
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

/// One run of path_following: the state its named steps share (the base and its solutions
/// x^ at t = 0 and 1, the current modes and equations, the columns' multipliers lambda at both
/// ends, the ratio test's bound) and the steps themselves, in the order the run takes them.
struct PathRun {
    SparsePath& path;
    const Step& step;
    const PathStart& start;
    SolveResult& r;
    PathStats& stats;
    const ContactProblem& laws;
    const int m, np;
    const Eigen::VectorXd& W;
    const double ts;                // the passes' acceptance [m]: a condition above it fails
    const int max_pair_switches;    // a pair switching more often: cycling
    const int rebase_rows, max_start_hits;
    modes::ModeSet cur;             // the current modes
    KeptBase* kb = nullptr;         // the base (path.kept)
    int upd0 = 0;                   // the mode solver's updates at the start
    // x^ at t = 0 and t = 1: [forces; G z] (2m entries each), both in one (multi-column,
    // refined) solve with the base's factorisation (or kept from the solves before on this base)
    Eigen::VectorXd X0h, X1h;
    std::vector<Eq> eq;             // the current set's equations
    std::vector<int> switches;      // per pair: its mode switches in this run
    std::vector<double> last_switch_t;
    std::vector<signed char> left_n, left_t;  // the modes a pair left last
    // the bound: A1 the sum of ||d lambda_1|| over the breakpoints; per pair the sum at its
    // last exact evaluation and its slack then (ts minus its largest condition at t = 1)
    double A1 = 0.0;
    std::vector<double> A1_at, slack;
    std::vector<char> dirty;
    Eigen::VectorXd L0, L1, L1_prev;  // lambda at t = 0 and 1 per column (0 outside C)
    double t = 0.0;
    int stalls = 0;
    std::vector<Hit> hits;
    std::vector<int> C;             // the rows whose equation differs from the base's
    double tmin = 2.0;              // the ratio test's first t' >= t where a condition fails
    double gmin = 0.0;              // the pair's slack (ts minus its largest condition at t = 1)

    PathRun(SparsePath& path_, const Step& step_, const PathStart& start_, SolveResult& r_, PathStats& stats_)
        : path(path_), step(step_), start(start_), r(r_), stats(stats_), laws(path_.laws), m(laws.size()),
          np(static_cast<int>(laws.pairs.size())), W(path_.diag()), ts(kAccept * path_.options.tolerance_m),
          max_pair_switches(path_.switches.path_max_pair_switches), rebase_rows(path_.switches.path_rebase_rows),
          max_start_hits(path_.switches.path_max_start_hits), X0h(2 * m), X1h(2 * m), switches(np, 0),
          last_switch_t(np, -1.0), left_n(np, modes::NONE), left_t(np, modes::NONE), A1_at(np, 0.0), slack(np, 0.0),
          dirty(np, 1) {
        cur.nmode = start.nmode;
        cur.tmode = start.tmode;
    }

    double rn(int q) const { return std::sqrt(kb->rn2[q]); }

    bool fail(PathStats::End end) {
        stats.end = end;
        return false;
    }

    void base_data() {
        const Eigen::VectorXd* b[2] = {&start.b, &step.b};
        const Eigen::VectorXd* d[2] = {&start.d, &step.d};
        Eigen::VectorXd* X[2] = {&X0h, &X1h};
        const int f = base_solutions(path, *kb, 2, b, d, X);
        r.factorizations += f;
        stats.factorizations += f;
    }

    void make_base() {
        const double c0 = thread_cpu_s();
        kb->set(laws, cur);
        base_data();
        stats.base_s += thread_cpu_s() - c0;
    }

    /// The base (KeptBase, path.kept): the start modes, their linear problem and key (as
    /// SparsePath::solve_modes names them, so a factorisation of M0 still current is reused), or
    /// the base kept from the last run where it is still current (path_keep_base: its columns
    /// kept, the start modes differing from it in a few rows). False where singular.
    bool start_base() {
        if (!path.kept || static_cast<int>(path.kept->col.size()) != m) path.kept = std::make_shared<KeptBase>(m);
        kb = path.kept.get();
        upd0 = path.solver.updates();
        try {
            if (keeps_base(path) && kb->current(path)) {
                const double c0 = thread_cpu_s();
                base_data();
                stats.base_s += thread_cpu_s() - c0;
                stats.kept_base = true;
            } else {
                make_base();
            }
        } catch (const SingularModes&) {
            return fail(PathStats::singular_modes);
        }
        ++r.iterations;
        mode_equations(laws, cur.nmode, cur.tmode, eq);
        return true;
    }

    /// x's entry q (a force: q < m; G z: m + q) at t = 0 and t = 1 under the current set
    /// (both ends at once: one pass over the row of Y).
    void x01(int q, double& a, double& b) const {
        a = X0h[q];
        b = X1h[q];
        if (kb->Y.size() == 0) return;
        double ya, yb;
        kb->Y.dot2(q, L0, L1, ya, yb);
        a += ya;
        b += yb;
    }

    /// The current set's multipliers: its changed rows C (past rebase_rows a new base), their
    /// columns, and lambda at both ends from the bordered system. False where it ends.
    bool solve_changed_rows() {
        changed_rows(eq, kb->eqs, C);
        if (stats.start_rows < 0 && stats.kept_base) stats.start_rows = static_cast<int>(C.size());
        if (rebase_rows > 0 && static_cast<int>(C.size()) > rebase_rows) {
            // a new base: the current modes factorised (the columns and the bound start again)
            make_base();
            eq = kb->eqs;
            A1 = 0.0;
            std::fill(dirty.begin(), dirty.end(), 1);
            L1_prev.resize(0);
            C.clear();
            ++stats.rebases;
        }
        const int nc = static_cast<int>(C.size());
        stats.end_rows = nc;
        if (nc > kMaxChangedRows) return fail(PathStats::too_many_rows);
        const int fc = add_columns(path, *kb, C, true, stats);
        r.factorizations += fc;
        stats.factorizations += fc;
        L0.setZero(kb->Y.padded());
        L1.setZero(kb->Y.padded());
        if (nc > 0) {
            const auto& col = kb->col;
            const Eigen::MatrixXd H = bordered_matrix(eq, C, kb->Y, col, W, m);
            const Eigen::VectorXd F0 = bordered_rhs(eq, C, W, m, [&](int r) { return eq[r].rhs(r, start.d); }, X0h);
            const Eigen::VectorXd F1 = bordered_rhs(eq, C, W, m, [&](int r) { return eq[r].rhs(r, step.d); }, X1h);
            const Eigen::PartialPivLU<Eigen::MatrixXd> lu(H);
            if (!(lu.rcond() > 1e-14)) return fail(PathStats::singular);
            const Eigen::VectorXd l0 = lu.solve(F0), l1 = lu.solve(F1);
            for (int j = 0; j < nc; ++j) {
                L0[col[C[j]]] = l0[j];
                L1[col[C[j]]] = l1[j];
            }
        }
        // the bound's step: lambda_1's change since the last breakpoint
        Eigen::VectorXd prev = Eigen::VectorXd::Zero(L1.size());
        prev.head(std::min(L1_prev.size(), L1.size())) = L1_prev.head(std::min(L1_prev.size(), L1.size()));
        A1 += (L1 - prev).norm();
        L1_prev = L1;
        return true;
    }

    /// One condition g [m], affine in t from g0 at t = 0 to g1 at t = 1: where it passes the
    /// acceptance on the rest of the path, a hit (pair k to mode `to`) at the first such t.
    void test(int k, bool normal, signed char to, double g0, double g1) {
        gmin = std::min(gmin, ts - g1);
        const double gc = g0 + t * (g1 - g0);
        if (!(g1 > ts) || !(g1 > gc)) return;  // valid at t = 1 and not rising
        const double th = gc >= ts ? t : t + (1.0 - t) * (ts - gc) / (g1 - gc);
        tmin = std::min(tmin, th);
        hits.push_back({k, normal, to, th});
    }

    /// Pair k's conditions moved by at most kappa x the bound's growth since its last exact
    /// evaluation: true where that stays within its slack then (no test needed).
    bool bounded_away(int k, bool nrow, bool trow) const {
        if (dirty[k]) return false;
        const auto& c = laws.pairs[k];
        const int rn_ = c.row_n, rt = c.row_t;
        const double mu = c.friction_coefficient;
        // the largest move of its conditions at t = 1 per unit of ||d lambda_1||
        double kappa = 0.0;
        if (nrow) kappa = cur.nmode[k] == modes::CLOSED ? W[rn_] * rn(rn_) : rn(m + rn_);
        if (trow) {
            const double Wt = W[rt], pn = rn_ >= 0 ? rn(rn_) : 0.0;
            double kt = c.kind == PairKind::clamp ? mu * Wt * pn : 0.0;
            if (cur.tmode[k] == modes::STICK) kt = std::max(kt, Wt * (rn(rt) + mu * pn));
            else if (cur.tmode[k] == modes::SLIP_POS || cur.tmode[k] == modes::SLIP_NEG) kt = std::max(kt, rn(m + rt));
            kappa = std::max(kappa, kt);
        }
        return kappa * (A1 - A1_at[k]) < slack[k];
    }

    /// Pair k's tangential conditions under its current mode (pn0, pn1: its normal force at both ends).
    void test_tangential(int k, double pn0, double pn1) {
        const auto& c = laws.pairs[k];
        const int rt = c.row_t;
        const bool clamp = c.kind == PairKind::clamp;
        const double mu = c.friction_coefficient;
        const double Wt = W[rt];
        // friction lost past the clamp's preload; the friction limit, affine in p_n
        const double rel0 = mu * (pn0 - c.preload_n) * Wt, rel1 = mu * (pn1 - c.preload_n) * Wt;
        const double lim0 = mu * (clamp ? c.preload_n - pn0 : -pn0), lim1 = mu * (clamp ? c.preload_n - pn1 : -pn1);
        switch (cur.tmode[k]) {
            case modes::STICK: {
                double pt0, pt1;
                x01(rt, pt0, pt1);
                if (clamp) test(k, false, modes::FREE, rel0, rel1);
                test(k, false, modes::SLIP_POS, (pt0 - lim0) * Wt, (pt1 - lim1) * Wt);
                test(k, false, modes::SLIP_NEG, (-pt0 - lim0) * Wt, (-pt1 - lim1) * Wt);
                break;
            }
            case modes::SLIP_POS:
            case modes::SLIP_NEG: {
                const double sigma = cur.tmode[k] == modes::SLIP_POS ? 1.0 : -1.0;
                double s0, s1;
                x01(m + rt, s0, s1);
                if (clamp) test(k, false, modes::FREE, rel0, rel1);
                test(k, false, modes::STICK, sigma * (s0 - start.d[rt]), sigma * (s1 - step.d[rt]));
                break;
            }
            case modes::FREE:
                if (clamp) test(k, false, modes::STICK, -rel0, -rel1);
                break;
            default: break;
        }
    }

    /// The ratio test: every pair's conditions on the rest of the path (those bounded away from
    /// their kinks skipped), its hits into `hits` and the first into tmin.
    void ratio_test() {
        tmin = 2.0;
        hits.clear();
        gmin = 0.0;
        for (int k = 0; k < np; ++k) {
            const auto& c = laws.pairs[k];
            const bool nrow = c.row_n >= 0 && modes::ModeSet::unilateral(c);
            const bool trow = !(c.row_t < 0 || c.kind == PairKind::bonded || c.friction_coefficient == 0.0 ||
                                (modes::ModeSet::unilateral(c) && cur.tmode[k] == modes::FREE));
            if (!nrow && !trow) continue;
            ++stats.pair_tests;
            if (bounded_away(k, nrow, trow)) continue;
            ++stats.evaluations;
            dirty[k] = 0;
            A1_at[k] = A1;
            gmin = std::numeric_limits<double>::infinity();
            const int rn_ = c.row_n;
            // the pair's normal force at both ends (its normal test, its friction limit)
            double pn0 = 0.0, pn1 = 0.0;
            if (rn_ >= 0 && (trow || (nrow && cur.nmode[k] == modes::CLOSED))) x01(rn_, pn0, pn1);
            if (nrow) {
                if (cur.nmode[k] == modes::CLOSED) {
                    test(k, true, modes::OPEN, pn0 * W[rn_], pn1 * W[rn_]);
                } else if (cur.nmode[k] == modes::OPEN) {
                    double g0, g1;
                    x01(m + rn_, g0, g1);
                    test(k, true, modes::CLOSED, g0 - start.d[rn_], g1 - step.d[rn_]);
                }
            }
            if (trow) test_tangential(k, pn0, pn1);
            slack[k] = gmin;
        }
    }

    /// The tangential mode of pair pc taking friction with a friction limit of 0 at tmin (one that
    /// closes, a clamp back below its preload, path_clamp_slip): it sticks only where its
    /// tangential position is at this step's anchor (s_t = 0), else it slips against s_t (the
    /// natural map's decision at p_t = 0): the path stays continuous, and sticks where s_t comes
    /// back to 0 (sticking at once would jump s_t to the anchor).
    signed char friction_from_zero(const ContactPair& pc) const {
        const int rt = pc.row_t;
        double s0, s1;
        x01(m + rt, s0, s1);
        const double stc = (1.0 - tmin) * (s0 - start.d[rt]) + tmin * (s1 - step.d[rt]);
        return std::abs(stc) <= ts ? modes::STICK : stc < 0.0 ? modes::SLIP_POS : modes::SLIP_NEG;
    }

    /// The breakpoint at tmin: the pairs that hit within kSameT of it switch (a pair's normal
    /// switch before its tangential), their equations updated. False where the run ends there
    /// (too many breakpoints, stalled, a fold, a cycle).
    bool switch_pairs() {
        if (++stats.breakpoints > kMaxBreakpoints) return fail(PathStats::too_many_breakpoints);
        stalls = tmin - t <= kSameT ? stalls + 1 : 0;
        if (stalls > kMaxStalls) return fail(PathStats::stalled);
        hits.erase(std::remove_if(hits.begin(), hits.end(), [&](const Hit& h) { return h.t > tmin + kSameT; }),
                   hits.end());
        std::stable_sort(hits.begin(), hits.end(), [](const Hit& a, const Hit& b) { return a.normal > b.normal; });
        std::vector<char> done(np, 0);
        for (const Hit& h : hits) {
            if (done[h.k]) continue;
            done[h.k] = 1;
            dirty[h.k] = 1;
            // back to the modes it left at the same t: the path folds, or a degenerate
            // vertex (several pairs at their kinks at one t) resolves by switching a pair
            // back (path_fold_ends false: it goes on, the stalls' limit bounds it)
            const signed char to_n = h.normal ? h.to : cur.nmode[h.k], to_t = h.normal ? cur.tmode[h.k] : h.to;
            if (path.switches.path_fold_ends && last_switch_t[h.k] >= 0.0 && tmin - last_switch_t[h.k] <= kSameT &&
                (h.normal ? to_n == left_n[h.k] : to_t == left_t[h.k]))
                return fail(PathStats::folded);
            if (++switches[h.k] > max_pair_switches && max_pair_switches > 0) return fail(PathStats::cycled);
            last_switch_t[h.k] = tmin;
            left_n[h.k] = cur.nmode[h.k];
            left_t[h.k] = cur.tmode[h.k];
            const auto& pc = laws.pairs[h.k];
            if (h.normal) {
                cur.nmode[h.k] = h.to;
                if (h.to == modes::CLOSED && pc.row_t >= 0) cur.tmode[h.k] = friction_from_zero(pc);
            } else if (h.to == modes::STICK && cur.tmode[h.k] == modes::FREE && path.switches.path_clamp_slip) {
                cur.tmode[h.k] = friction_from_zero(pc);
            } else {
                cur.tmode[h.k] = h.to;
            }
            cur.make_consistent(laws, h.k);
            Eq en, et;
            pair_equations(pc, cur.nmode[h.k], cur.tmode[h.k], en, et);
            if (pc.row_n >= 0) eq[pc.row_n] = en;
            if (pc.row_t >= 0) eq[pc.row_t] = et;
        }
        t = tmin;
        return true;
    }

    /// From the base to t = 1, one breakpoint at a time. False where it ends before.
    bool follow() {
        try {
            for (;;) {
                if (!solve_changed_rows()) return false;
                ratio_test();
                if (stats.breakpoints == 0 && stats.rebases == 0) {
                    stats.start_hits = static_cast<int>(hits.size());
                    if (max_start_hits > 0 && stats.start_hits > max_start_hits)
                        return fail(PathStats::too_many_start_hits);
                }
                if (hits.empty()) return true;  // the modes hold up to t = 1
                if (!switch_pairs()) return false;
            }
        } catch (const SingularModes&) {
            return fail(PathStats::singular_modes);
        }
    }

    /// The end: the modes at t = 1 into path.modes, the forces x at t = 1 into p.
    void finish(Eigen::VectorXd& p) {
        stats.updates += path.solver.updates() - upd0;
        stats.end = PathStats::reached;
        path.modes.nmode = cur.nmode;
        path.modes.tmode = cur.tmode;
        p = X1h.head(m);
        if (kb->Y.size() > 0)
            for (int q = 0; q < m; ++q) p[q] += kb->Y.dot(q, L1);
    }
};

}  // namespace

bool path_following(SparsePath& path, const Step& step, const PathStart& start, Eigen::VectorXd& p,
                    Eigen::VectorXd& z, SolveResult& r, PathStats& stats) {
    struct Clock {  // the whole run's CPU time, whatever the return
        double& total;
        double t0;
        ~Clock() { total += thread_cpu_s() - t0; }
    } clock{stats.total_s, thread_cpu_s()};
    if (path.laws.tau_rule != TauRule::current) {
        stats.end = PathStats::not_applicable;
        return false;
    }
    static_cast<void>(z);  // (not set: the passes after it solve the end modes again)
    path.solves_since_path = 0;
    PathRun run(path, step, start, r, stats);
    if (!run.start_base() || !run.follow()) return false;
    run.finish(p);
    return true;
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
