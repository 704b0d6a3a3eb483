#pragma once
// Internal: the linear problem of a set of modes on the sparse stiffness (mode_solver.cpp).
//
// For a set of modes the contact conditions are linear: held rows (closed normal, stuck
// tangential, bonded) impose G_S z = d_S; slipping rows carry a force affine in their
// pair's normal force, p_t = e_t + D p_n; open / free rows carry p = e = 0. With z and p_S
// as unknowns this is one sparse saddle-point system
//     [ K     -G_S^T - G_slip^T D ] [z  ]   [b + G^T e]
//     [ G_S    0                  ] [p_S] = [d_S      ]
// (K [N/m per DOF unit] the stiffness, G [-] the contact rows, d [m] the offsets, p [N] the
// contact forces, z the displacements). ModeSolver solves it three ways (the defaults are
// the measured choices, docs/decisions/002-sparse-contact-path.md):
//  - at most `schur_max_rows` held rows: the dense Schur complement of the held rows on a
//    Cholesky factor of K made once per (K, G), the columns K^-1 g_i^T cached per row;
//  - more: a sparse LU of the saddle-point system (Eigen::SparseLU, COLAMD);
//  - a held set without slip coupling within `max_border_rows` rows of the last LU's: that
//    LU bordered by the changed rows (a low-rank update) instead of a new factorisation.
// The Schur way is incremental (schur_updates): the Schur complement of a new held set is
// copied from the base's (the last one factorised densely) where rows and columns stay and
// computed only where they changed, and it is solved by a low-rank update of the base's
// dense LU (Woodbury: the changed rows and columns, slip couplings included) while few
// change; accept() makes the current set the base (the caller's accepted step).
// A factorisation is named by a key (the caller's modes, or a box QP's working set) and
// reused while the key stays; within one key the solution is affine in the load b, and
// the back-solves of that map are cached.
#include <Eigen/Dense>
#include <Eigen/SparseLU>
#include <functional>
#include <memory>
#include <vector>

#include "contact/active_set.hpp"
#include "contact/sparse/driver/common.hpp"
#include "contact/sparse/linear/fixed_pattern_lu.hpp"
#include "contact/sparse/linear/primal_cholmod.hpp"
#include "contact/sparse/driver/trace.hpp"

namespace stackbeam::detail::sparse {

/// The data of one (K, G), made once per structure: K's factor, W's diagonal, the scalings.
struct SparseStiffness {
    SpMat K, G;              ///< stiffness (n x n) and contact rows (m x n), compressed
    SpMat Gt;                ///< G^T (columns: contact rows)
    RowMat Grow;             ///< G, row-major
    KCholesky k_llt;         ///< Cholesky factor of K
    Eigen::VectorXd diag;    ///< diagonal of W = G K^-1 G^T [m/N] (selected_inverse.hpp)
    double g_norm_inf = 0.0; ///< max row sum of |G|
    Eigen::VectorXd dz;      ///< column scaling of z: diag(K)^-1/2
    SpMat Gt_scaled;         ///< Dz G^T: column r is contact row r, scaled
    Eigen::VectorXd row_h;   ///< ||G_i Dz|| per contact row (1 for an empty row): the row scaling

    /// Factorises K (throws InputError("problem.K") if it is not positive definite) and
    /// makes the rest. K and G must have matching sizes.
    void build(const SpMat& K_, const SpMat& G_);
    int dofs() const { return static_cast<int>(K.rows()); }
    int rows() const { return static_cast<int>(G.rows()); }
    /// s = G z - d [m] for z = K^-1 (b + G^T p).
    Eigen::VectorXd positions(const Eigen::VectorXd& b, const Eigen::VectorXd& d, const Eigen::VectorXd& p,
                              Eigen::VectorXd& z) const;
    /// 1e-13 x (||d||_inf + ||G||_inf ||z||_inf) [m]: the round-off of s = G z - d.
    double roundoff(const Eigen::VectorXd& d, const Eigen::VectorXd& z) const;
    /// Appends Dz K Dz (the stiffness block of the scaled saddle-point systems) to t.
    void append_scaled_K(std::vector<Eigen::Triplet<double>>& t) const;
    /// g_r . v for a contact row r and a vector v of n entries (inline: the homotopy calls it per
    /// row of every column, decision 049).
    double row_dot(int r, const Eigen::Ref<const Eigen::VectorXd>& v) const {
        double sum = 0.0;
        for (RowMat::InnerIterator it(Grow, r); it; ++it) sum += it.value() * v[it.col()];
        return sum;
    }
};

/// Per contact row: its elastic-interface layer DOF (decision 013: a column of K with its
/// positive diagonal only and one nonzero of G, in this row, the first such column), or -1.
std::vector<int> layer_dofs(const SpMat& K, const SpMat& G);

/// The ways of ModeSolver (SparsePathTuning's fields of the same names).
struct ModeSolverTuning {
    int schur_max_rows = 400;   ///< >= 0 (0: always the sparse LU)
    int max_border_rows = 150;  ///< >= 0 (0: never update, always refactorise)
    /// the Schur way's incremental build and low-rank update of the dense LU (false: every
    /// new held set's Schur complement computed and factorised from scratch, as before)
    bool schur_updates = true;
    /// > 0: held sets of at least this many rows, some of them layer rows, take the primal
    /// route (primal_cholmod.hpp: CHOLMOD, rank-k updates) when this build has CHOLMOD;
    /// 0: never (SparsePathTuning::primal_min_rows; docs/decisions/027)
    int primal_min_rows = 0;
    PrimalOrdering primal_ordering = PrimalOrdering::amd;  ///< its fill-reducing ordering
    /// the sparse LU of held sets above schur_max_rows: on one pattern for every set, ordered
    /// once per (K, G) (fixed_pattern_lu.hpp; docs/decisions/031), or `off`: the variable system
    /// of each set ordered and factorised from scratch (the way before)
    FixedPatternLu fixed_pattern = FixedPatternLu::off;
    /// the fixed pattern only for held sets with at most this many rigid (not layer) rows:
    /// each forces an off-diagonal pivot that the pattern's ordering (made for diagonal
    /// pivots) does not foresee (measured: bonded 10 x 400, every row rigid and held, 20x slower)
    int fixed_max_rigid_rows = 200;
    /// KLU keeps a refactorisation on the old pivot sequence by its solves' backward error,
    /// not by klu_rgrowth (Switches::residual_refactor_check; docs/decisions/035)
    bool residual_refactor_check = true;
    /// the bordered update's new columns A0^-1 U solved together, one multi-column solve
    /// (Switches::block_border_solves; false: one refined solve per changed row, as before)
    bool block_border_solves = true;
    /// the bordered update's limit when the base LU is KLU's on the fixed pattern (the
    /// smaller of this and max_border_rows; -1: max_border_rows alone, as before;
    /// Switches::fixed_border_rows)
    int fixed_max_border_rows = 8;
    /// the Schur way's fresh dense LU (no update of the base possible) only for held sets of
    /// at most this many rows; larger ones take the sparse LU instead (docs/decisions/038;
    /// the solver takes Switches::schur_fresh_max_rows, 200; -1: no limit, as before)
    int schur_fresh_max_rows = -1;
};

class ModeSolver {
public:
    explicit ModeSolver(const ModeSolverTuning& tuning = {}) : tuning_(tuning) {}

    /// A new (K, G): factorises K, computes W's diagonal and drops every cache. `couplings`:
    /// the (tangential row, normal row) of the pairs whose slip may couple them (the fixed
    /// pattern's; a coupling not listed extends the pattern when it first occurs).
    void reset(const SpMat& K, const SpMat& G, const std::vector<std::pair<int, int>>& couplings = {});
    const SparseStiffness& stiffness() const { return st_; }

    /// Solves the linear problem of `lin` (held rows S with s = 0, fixed forces e, slip
    /// coupling p_t = e_t + coef p_n) for load b and offsets d into p [N] (every row: the
    /// held ones solved, the others e plus their coupling) and z. Reuses the factorisation
    /// while `key` names it; returns 1 if it factorised (a sparse LU or the Schur
    /// complement's dense LU), 0 otherwise (cached, or a bordered update: updates()).
    /// Throws SingularModes if the held rows are dependent.
    int solve(const modes::ModeLinearization& lin, const std::vector<signed char>& key, const Eigen::VectorXd& b,
              const Eigen::VectorXd& d, Eigen::VectorXd& p, Eigen::VectorXd& z);
    /// solve() for the columns of B (loads, n x k) and D (offsets, m x k), all with lin's fixed
    /// forces e: the forces P (m x k) and displacements Z (n x k). On the sparse LU one
    /// multi-column solve, refined (one pass over the factor for every column); the affine
    /// caches of solve() are neither used nor changed. Returns 1 if it factorised.
    int solve_block(const modes::ModeLinearization& lin, const std::vector<signed char>& key, const Eigen::MatrixXd& B,
                    const Eigen::MatrixXd& D, Eigen::MatrixXd& P, Eigen::MatrixXd& Z);
    /// For the current factorisation (lin's, made current by a solve() with its key): lin's
    /// problem for one unit right-hand side per row of `rows`, all in one multi-column solve,
    /// with b = 0 and e = 0 but a unit offset d_r (a held row of lin) or a unit fixed force e_r
    /// (a row not held): the forces P (m x k) and displacements Z (the first n of its rows; it
    /// may have more, scratch, so the sparse LU's solution needs no copy). refine false: no
    /// iterative refinement (the homotopy's columns, docs/decisions/040: its end modes are
    /// solved again with refinement by the passes). False (nothing solved) where the current
    /// factorisation is a bordered update or the primal route's: then solve() per column.
    bool unit_solves(const modes::ModeLinearization& lin, const std::vector<int>& rows, bool refine, Eigen::MatrixXd& P,
                     Eigen::MatrixXd& Z);
    /// The current set of modes is the caller's accepted answer: on the Schur way, its
    /// Schur complement is factorised densely (if it was solved by an update) and becomes
    /// the base of the next updates, so updates never chain (no drift).
    void accept();
    /// Whether `key` names the current factorisation.
    bool is_current(const std::vector<signed char>& key) const { return key == lu_key_; }
    /// The reciprocal condition estimate (1-norm) of the dense LU of the Schur way (the
    /// current held set's, when it was factorised; tests).
    double schur_rcond() const { return dlu.rcond(); }
    /// Forgets the current factorisation's key (after a singular solve).
    void forget() { lu_key_.clear(); }
    /// Solves by a bordered update since the last reset_updates().
    int updates() const { return updates_; }
    void reset_updates() { updates_ = 0; }
    /// Counts a solve by a low-rank update made outside (the homotopy's kept base, docs/decisions/045).
    void count_update() { ++updates_; }
    /// The primal route's solver (null when it is off or not built; tests, benchmark).
    PrimalSolver* primal() { return primal_.get(); }
    /// Whether the current factorisation is the primal route's.
    bool on_primal_route() const { return lu_primal; }
    /// The fixed-pattern LU (null when ModeSolverTuning::fixed_pattern is off; tests, benchmark).
    const FixedSaddle* fixed() const { return fixed_.get(); }
    /// A study aid (docs/decisions/038): where not null, every solve() adds its route, CPU
    /// time and held rows there (trace.hpp). nullptr (default): nothing recorded.
    void set_route_stats(RouteStats* stats) { routes_ = stats; }

private:
    int solve_key(const modes::ModeLinearization& lin, const std::vector<signed char>& key, const Eigen::VectorXd& b,
                  const Eigen::VectorXd& d, Eigen::VectorXd& p, Eigen::VectorXd& z);
    int solve_block_key(const modes::ModeLinearization& lin, const std::vector<signed char>& key,
                        const Eigen::MatrixXd& B, const Eigen::MatrixXd& D, Eigen::MatrixXd& P, Eigen::MatrixXd& Z);
    int make_current(const modes::ModeLinearization& lin, const std::vector<signed char>& key);
    int counted(std::size_t held_rows, const std::function<int()>& call);
    bool try_border(const modes::ModeLinearization& lin);
    void border_solve(const modes::ModeLinearization& lin, const Eigen::VectorXd& b, const Eigen::VectorXd& d,
                      Eigen::VectorXd& p, Eigen::VectorXd& z);
    void load_solve(const modes::ModeLinearization& lin, const Eigen::VectorXd& f, Eigen::VectorXd& pS,
                    Eigen::VectorXd& zf);
    void ensure_columns(const std::vector<int>& rows);
    void factor_schur(const modes::ModeLinearization& lin);
    int factor_schur_update(const modes::ModeLinearization& lin, bool may_factorise = true);
    void make_schur_base();
    Eigen::VectorXd schur_inverse(const Eigen::VectorXd& r) const;
    void schur_solve(const modes::ModeLinearization& lin, const Eigen::VectorXd& z0, const Eigen::VectorXd& target,
                     Eigen::VectorXd& pS, Eigen::VectorXd& zout);
    Eigen::VectorXd refined_solve(const Eigen::VectorXd& r);
    Eigen::MatrixXd refined_solve(const Eigen::MatrixXd& R);
    Eigen::VectorXd apply_A(const Eigen::VectorXd& x) const;
    void factor_lu(const modes::ModeLinearization& lin);
    void direct_solve(const modes::ModeLinearization& lin, const Eigen::VectorXd& f, const Eigen::VectorXd& dS,
                      Eigen::VectorXd& pS, Eigen::VectorXd& zf);

    ModeSolverTuning tuning_;
    SparseStiffness st_;
    int updates_ = 0;
    // factorisation of the current key
    std::vector<signed char> lu_key_;
    Eigen::SparseLU<SpMat, Eigen::COLAMDOrdering<int>> lu;
    bool lu_ok = false;
    std::vector<int> pos;                // row -> index in lin.S, or -1
    Eigen::VectorXd row_scale;           // scaling of the held rows (1/||G_i Dz||)
    SpMat A;                             // the scaled saddle-point matrix of the current key
    // cached back-solves of the current factorisation
    int unit_dof = -1;                   // (zu, pu) are for a unit load on this DOF
    Eigen::VectorXd const_e, const_dS;   // (zc, pc) are for these e, d_S
    bool const_ok = false;
    Eigen::VectorXd x, rhs;
    // the affine map of the load for the current factorisation: (z, p_S) = (zc, pc) + b_w (zu, pu)
    Eigen::VectorXd zc, pc, zu, pu;
    // Schur-complement way: the held rows' dense LU and the cached columns K^-1 g_i^T
    bool lu_schur = false;
    Eigen::MatrixXd Mschur;              // the Schur complement (for refinement)
    Eigen::PartialPivLU<Eigen::MatrixXd> dlu;
    std::vector<Eigen::VectorXd> xcol;   // per contact row; empty = not computed
    std::vector<int> schur_ct;           // per held row (column of M): its coupled slip row, or -1
    std::vector<double> schur_cc;        //   and the coupling's coefficient
    std::vector<int> schur_S;            // the held rows of Mschur
    // the base of the updates: a held set whose Schur complement has a dense LU (dlu_base)
    bool base_schur = false;
    std::vector<int> bs_S, bs_ct, bs_index;  // held rows, couplings, row -> index (or -1)
    std::vector<double> bs_cc;
    Eigen::MatrixXd bs_M;                // (dlu factorises it while an update is active)
    // the current set as a low-rank update of the base (Woodbury on the base set plus the
    // added rows, a removed row's equation replaced by p = 0): U-index of each held row,
    // the changed rows' and columns' U-indices, Z = A_base^-1 U, the capacitance's LU
    bool wb_active = false;
    int wb_nb = 0, wb_nu = 0;
    std::vector<int> wb_map, wb_rows, wb_cols;
    Eigen::MatrixXd wb_Drows, wb_Z;
    Eigen::PartialPivLU<Eigen::MatrixXd> wb_C;
    double l_nonzeros = 0.0;             // nonzeros of K's Cholesky factor (the cost of a solve)
    std::size_t xcol_count = 0;
    // low-rank updates of the sparse LU (try_border): the base's held set and the border
    bool base_valid = false;
    std::vector<int> base_S, base_pos;
    bool border_active = false;
    std::vector<int> border_rows;        // the freed base rows first (border_nr of them), then the added rows
    int border_nr = 0;
    std::vector<Eigen::VectorXd> bcol;   // per contact row: A0^-1 U_j, or empty
    std::size_t bcol_count = 0;          // non-empty entries of bcol
    int key_uses = 0;                    // solves with the current factorisation
    // the primal route (primal_cholmod.hpp), shared_ptr: PrimalSolver is defined only in
    // builds with CHOLMOD
    std::shared_ptr<PrimalSolver> primal_;
    bool lu_primal = false;
    // the sparse LU on the fixed pattern (replaces lu and A when tuning_.fixed_pattern is on)
    std::unique_ptr<FixedSaddle> fixed_;
    std::vector<char> layer_row_;        // per contact row: a layer row (layer_dofs)
    bool lu_fixed = false;               // the current sparse LU is fixed_'s
    RouteStats* routes_ = nullptr;       // the study's route statistics (set_route_stats)
    int route_ = route_cached;           // the route of the last solve_key
};

}  // namespace stackbeam::detail::sparse
