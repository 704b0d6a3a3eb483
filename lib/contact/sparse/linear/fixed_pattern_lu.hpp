#pragma once
// Internal: the saddle-point system of a set of modes on one pattern for every set
// (fixed_pattern_lu.cpp; docs/decisions/031-fixed-pattern-refactorisation.md).
//
// The mode solver's sparse LU factorised, per held set S, the scaled system
//     [ Dz K Dz                  -Dz (G_S^T + G_slip^T D) R ] [y  ]   [Dz f  ]
//     [ R G_S Dz                  0                         ] [pi ] = [R d_S ]
// whose size and pattern change with S, so its ordering (COLAMD) and symbolic analysis were
// redone at every set. Here the system has one row and one column per contact row, held or
// not: a row i outside S is the trivial equation pi_i = 0 (its entries of G stored as
// explicit zeros, its diagonal 1), a held row's diagonal an explicit zero, and every slip
// coupling the problem can have (each friction pair's tangential row on its normal row's
// column) has its entries in the pattern, zero when not slipping. The pattern then depends on
// (K, G) and the pairs only: the fill-reducing ordering and the symbolic analysis are made
// once, and each held set costs one numeric factorisation with partial pivoting (so a row
// whose value changed from 1 to 0 between sets is pivoted as it must be). The solution is
// the same as the variable system's: the rows outside S only add pi_i = 0, which the load
// f = b + G^T e already accounts for.
// That pattern's factor carries the fill of every contact row's coupling, held or not (on
// the identical 10 x 400 stack a two-dimensional grid of 10 leaves x 801 nodes). With
// FixedPatternLu::klu_held_amd (the default, docs/decisions/038) each set's own system is
// taken out of the pattern's values (the DOFs and the held rows only) and ordered by AMD and
// factorised by KLU per set: 13 ms per set there against 18 ms on the whole pattern.
#include <Eigen/Dense>
#include <memory>
#include <utility>
#include <vector>

#include "contact/active_set.hpp"
#include "contact/sparse/driver/common.hpp"

namespace stackbeam::detail::sparse {

struct SparseStiffness;

/// The sparse LU used on the fixed pattern (ModeSolverTuning::fixed_pattern).
enum class FixedPatternLu {
    off,    ///< the variable system of each held set, ordered and factorised from scratch (before)
    eigen,  ///< Eigen::SparseLU: COLAMD and the symbolic analysis once, factorize() per set
    klu,    ///< SuiteSparse's KLU (AMD ordering once; per set klu_refactor on the last pivot sequence
            ///< where its pivots stay good, else klu_factor; builds with KLU only)
    /// KLU on each held set's own system (the held rows only), ordered by the fixed pattern's
    /// AMD ordering (made once) restricted to the set's unknowns: no ordering per set, and no
    /// fill from the rows not held (docs/decisions/038; builds with KLU only)
    klu_held,
    klu_held_amd,  ///< the same, each set's own system ordered by AMD (a study: the ordering's cost and quality)
};

/// Whether this build has SuiteSparse's KLU (STACKBEAM_HAVE_KLU).
bool klu_built();

/// Right-hand sides given by their nonzeros, column c's at start[c] .. start[c + 1] - 1 of
/// (row, value), no row twice in a column (unit right-hand sides: the homotopy's columns).
struct SparseColumns {
    std::vector<int> start{0}, row;
    std::vector<double> value;
    int cols() const { return static_cast<int>(start.size()) - 1; }
    void add(int r, double v) {
        row.push_back(r);
        value.push_back(v);
    }
    void end_column() { start.push_back(static_cast<int>(row.size())); }
    /// the dense n x cols() matrix
    Eigen::MatrixXd dense(int n) const {
        Eigen::MatrixXd X = Eigen::MatrixXd::Zero(n, cols());
        for (int c = 0; c < cols(); ++c)
            for (int p = start[static_cast<std::size_t>(c)]; p < start[static_cast<std::size_t>(c) + 1]; ++p)
                X(row[static_cast<std::size_t>(p)], c) = value[static_cast<std::size_t>(p)];
        return X;
    }
};

/// A sparse LU with partial pivoting whose ordering and symbolic analysis are made once for
/// a pattern and reused by every numeric factorisation of a matrix of that pattern.
class PatternLu {
public:
    virtual ~PatternLu() = default;
    /// The ordering and symbolic analysis of A's pattern.
    virtual void analyze(const SpMat& A) = 0;
    /// The numeric factorisation of A (A's pattern is the analysed one); false if singular.
    virtual bool factorize(const SpMat& A) = 0;
    /// x = A^-1 x with the last factorisation.
    virtual void solve_in_place(Eigen::VectorXd& x) = 0;
    /// X = A^-1 X, every column (one pass over the factor for several columns where the LU can).
    virtual void solve_in_place(Eigen::MatrixXd& X) = 0;
    /// The same for columns with few nonzeros (unit right-hand sides): where the LU can, its
    /// triangular solves skip the columns of the factors that a zero entry would apply (the
    /// same arithmetic otherwise, so the same result). Default: solve_in_place.
    virtual void solve_sparse_in_place(Eigen::MatrixXd& X) { solve_in_place(X); }
    /// X = A^-1 B (n x B.cols(), X's entries all overwritten) for B given by its nonzeros:
    /// solve_sparse_in_place's arithmetic on the dense B, without B's zeros written and read
    /// where the LU can. Default: the dense B, solve_sparse_in_place.
    virtual void solve_sparse_columns(const SparseColumns& B, int n, Eigen::MatrixXd& X) {
        X = B.dense(n);
        solve_sparse_in_place(X);
    }
    /// Whether the current factor is a refactorisation on an old pivot sequence whose pivots
    /// were not checked (Switches::residual_refactor_check): its solves' backward error is.
    virtual bool unchecked() const { return false; }
    /// Factorises A (the matrix of the current factor) afresh with pivoting.
    virtual bool repivot(const SpMat& A) { return factorize(A); }
    /// The symbolic analysis of A's pattern under the given symmetric ordering (order[k]: the
    /// unknown eliminated k-th; empty: the LU's own ordering). Default: analyze(A).
    virtual void analyze_given(const SpMat& A, const std::vector<int>& order) {
        (void)order;
        analyze(A);
    }
    /// The fill-reducing ordering the LU makes for A's pattern (empty where it does not say).
    virtual std::vector<int> ordering(const SpMat& A) {
        (void)A;
        return {};
    }
    /// x = A^-1 x (A: the matrix last factorised) with one step of iterative refinement
    /// against A. On an unchecked refactorisation, a first solve whose normwise backward
    /// error ||x - A y|| / (||A|| ||y|| + ||x||) (infinity norms) exceeds kMaxBackwardError
    /// makes it pivot afresh (repivot) and solve again. False if that factorisation failed
    /// (A singular).
    bool refined_solve(const SpMat& A, Eigen::VectorXd& x);
    bool refined_solve(const SpMat& A, Eigen::MatrixXd& X);
    /// The largest backward error kept from an unchecked refactorisation: a pivoted LU's is
    /// a few eps times the growth; 1e-11 leaves the refinement step a contraction of at
    /// least that times the conditioning, the answers those of a fresh factor to round-off.
    static constexpr double kMaxBackwardError = 1e-11;
    long pivoted = 0;     ///< numeric factorisations with pivoting
    long reused = 0;      ///< refactorisations on the previous pivot sequence (KLU)
    long repivoted = 0;   ///< unchecked refactorisations rejected by the backward error (then pivoted)

protected:
    bool norm_valid_ = false;  ///< a_norm_ is the current factor's matrix's (reset by factorize)

private:
    bool accept_solve(const SpMat& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& X);
    double a_norm_ = 0.0;
};

/// A PatternLu on `lu` (not off; klu only when klu_built(), else Eigen's). `residual_check`:
/// KLU keeps a refactorisation on the last pivot sequence by its solves' backward error
/// (PatternLu::refined_solve) instead of its pivot growth (klu_rgrowth, an O(nnz(U)) pass
/// per factorisation; Switches::residual_refactor_check).
std::unique_ptr<PatternLu> make_pattern_lu(FixedPatternLu lu, bool residual_check = true);

/// The numeric factorisations of the fixed-pattern system of one (K, G, pairs).
class FixedSaddle {
public:
    explicit FixedSaddle(FixedPatternLu lu, bool residual_check = true)
        : lu_(make_pattern_lu(lu, residual_check)),
          held_system_(lu == FixedPatternLu::klu_held || lu == FixedPatternLu::klu_held_amd),
          held_amd_(lu == FixedPatternLu::klu_held_amd) {}
    /// A new structure: the pattern of K, of every contact row and of the couplings
    /// (tangential row, normal row) of `couplings`; the ordering is made at the first factor().
    void reset(const SparseStiffness& st, const std::vector<std::pair<int, int>>& couplings);
    /// Factorises the system of lin's held set (pos: row -> index in lin.S or -1; row_scale:
    /// the held rows' scaling). A coupling outside the pattern extends it (a new analysis).
    /// False if the matrix is singular.
    bool factor(const modes::ModeLinearization& lin, const std::vector<int>& pos, const Eigen::VectorXd& row_scale);
    /// x = A_S^-1 r for the variable system's layout (n DOFs, then the held rows in lin.S's
    /// order), with one step of iterative refinement against the fixed-pattern matrix.
    Eigen::VectorXd solve(const Eigen::VectorXd& r);
    /// The same for each column of R (one multi-column solve); refine false: without the
    /// refinement step (and without the backward-error check of an unchecked refactorisation:
    /// for a factor a refined solve has already checked; docs/decisions/040), for columns with
    /// few nonzeros (PatternLu::solve_sparse_in_place; docs/decisions/043).
    Eigen::MatrixXd solve(const Eigen::MatrixXd& R, bool refine = true);
    /// The same, R overwritten by the result (the held system's: in place, no copy).
    void solve_in_place(Eigen::MatrixXd& R, bool refine = true);
    /// solve_in_place(R, false) for R given by its nonzeros (SparseColumns; X: the solution,
    /// its entries all overwritten, no zeroed R needed on the held system's route)
    void solve_unit_columns(const SparseColumns& B, Eigen::MatrixXd& X);
    /// A_S x in the same layout (the rows outside S contribute nothing: their entries are zero).
    Eigen::VectorXd multiply(const Eigen::VectorXd& x) const;
    /// Orderings and symbolic analyses made since reset() (tests, benchmark).
    int analyses() const { return analyses_; }
    /// The LU's counts of factorisations (tests, benchmark).
    const PatternLu& lu() const { return *lu_; }

private:
    std::unique_ptr<PatternLu> lu_;
    void build_pattern();
    Eigen::VectorXd scatter(const Eigen::VectorXd& x) const;
    Eigen::VectorXd gather(const Eigen::VectorXd& full) const;
    const SparseStiffness* st_ = nullptr;
    std::vector<std::pair<int, int>> couplings_;  // (tangential row, normal row) in the pattern
    std::vector<int> coupling_of_t_;              // tangential row -> its index in couplings_, or -1
    SpMat A_;                                     // the pattern and the current values
    std::vector<int> gcol_slot_, grow_slot_;      // per nonzero of Gt_scaled: slots (dof, n + i), (n + i, dof)
    std::vector<int> diag_slot_;                  // per contact row: the slot (n + i, n + i)
    std::vector<std::vector<int>> cpl_slot_;      // per coupling: slots (dof, n + normal) for g_t's nonzeros
    bool analysed_ = false;
    int analyses_ = 0;
    std::vector<int> held_;                       // the held rows of the current factorisation
    // FixedPatternLu::klu_held(_amd): the held set's own system (n DOFs, then the held rows in
    // lin.S's order) taken from A_, and the fixed pattern's ordering (klu_held)
    bool held_system_ = false;
    bool held_amd_ = false;
    SpMat As_;
    std::vector<int> order_;                      // the fixed pattern's elimination order
    std::vector<int> sub_of_;                     // per unknown of A_: its index in As_, or -1
    std::vector<std::pair<int, double>> col_;     // extract_held's scratch (a column to sort)
    void extract_held(const std::vector<int>& pos);
};

}  // namespace stackbeam::detail::sparse
