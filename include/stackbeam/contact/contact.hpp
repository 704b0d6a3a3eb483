#pragma once
/// @file contact.hpp
/// The per-step frictional contact problem as a value, and the solvers that
/// take it. A test can build a ContactProblem by hand; every solver has the same
/// signature and returns a SolveResult (converged, iterations, residual).
///
/// The problem (paper section 3, its sign convention: conventions.hpp):
///   s = W p + q                      relative surface positions (eq. 6 and 7)
///   p_n <= 0, s_n <= 0, p_n s_n = 0  unilateral normal (eq. 8); bilateral at clamps and bonds: s_n = 0
///   |p_t| <= mu tau;  s_t = 0 if |p_t| < mu tau;  s_t = -beta p_t, beta > 0, if |p_t| = mu tau  (eq. 8)
///   tau = |p_n| (coulomb pair) or max(0, F_c - p_n) (clamp pair); bonded pairs: s = 0.
/// The error vector v (eq. 9) is zero exactly at a solution (eq. 10); ||v||_2 [m]
/// is the solver-independent residual every solver reports.
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <memory>
#include <string>
#include <vector>

#include "stackbeam/contact/pair.hpp"
#include "stackbeam/contact/sparse_methods.hpp"

namespace stackbeam {

/// The pair laws of a contact problem, whatever form its operator takes: the pairs and their
/// rows, the tau rule and the previous step's limits. Every problem type below is one.
struct ContactLaws {
    std::vector<ContactPair> pairs;    ///< the pairs and their rows
    TauRule tau_rule = TauRule::current;
    Eigen::VectorXd tau_previous_n;    ///< per pair tau [N] of the previous step (used with TauRule::previous_step)
};

/// The per-step contact problem in dense form: s = W p + q with the pair laws.
struct ContactProblem : ContactLaws {
    Eigen::MatrixXd W;                 ///< compliance [m/N], symmetric positive definite
    Eigen::VectorXd q;                 ///< free term [m]: s when p = 0

    int size() const { return static_cast<int>(q.size()); }
    /// Throws InputError if the sizes, rows or laws are inconsistent.
    void validate() const;
};

/// State of a pair at a solution.
enum class PairState { stick, slip, open };
const char* to_string(PairState state);
template <>
const std::vector<EnumWord<PairState>>& enum_words<PairState>();

/// tau [N] of pair `k` for the force vector p, by the problem's tau rule.
double friction_normal_force(const ContactLaws& problem, int k, const Eigen::VectorXd& p);

/// The paper's error vector v (eq. 9) for forces p and relative positions s = W p + q.
Eigen::VectorXd error_vector(const ContactLaws& problem, const Eigen::VectorXd& p, const Eigen::VectorXd& s);

/// Solver-independent residual [m]: the natural map of the contact laws, scaled to
/// metres by the diagonal of W. Per component, with w = W_kk:
///   unilateral normal  w (p_n - min(0, p_n - s_n / w))
///   tangential         w (p_t - clamp(p_t - s_t / w, -mu tau, mu tau))
///   bilateral / bonded s
/// It is zero exactly at a solution and, unlike eq. 9's v, also sees forces outside
/// the admissible set (tension in an open pair, friction above the limit).
Eigen::VectorXd natural_map(const ContactProblem& problem, const Eigen::VectorXd& p, const Eigen::VectorXd& s);

/// State of pair k at (p, s). A pair whose normal force is zero and may open is
/// open; a tangential force at the friction limit (relative 1e-9) is slip; bonded pairs stick.
PairState pair_state(const ContactLaws& problem, int k, const Eigen::VectorXd& p);

/// The available solvers.
enum class SolverKind {
    paper,        ///< eq. 17 with E = I and constant alpha (the faithful reference; slow)
    accelerated,  ///< eq. 17 with E = per-pair 2x2 block inverse of W, Gauss-Seidel sweeps (Lee 1989 style)
    exact,        ///< active-set direct solver, factorisation reused while the modes stay (default)
    block_jacobi, ///< eq. 17 with E = per-pair 2x2 block inverse of W, applied to all pairs at once
};
template <>
const std::vector<EnumWord<SolverKind>>& enum_words<SolverKind>();
const char* to_string(SolverKind kind);
/// Parses "paper" | "accelerated" | "block-jacobi" | "exact"; throws InputError naming `field`.
SolverKind parse_solver_kind(const std::string& text, const std::string& field);

struct SolverOptions {
    SolverKind kind = SolverKind::exact;  ///< the default in every mode (SimulationOptions::solver)
    double tolerance_m = 2e-6;        ///< stop when ||v||_2 < tolerance_m [m] (paper: 2e-6)
    int max_iterations = 200000;      ///< iteration limit of the iterative solvers
    double alpha = 0.0;               ///< paper / block_jacobi: alpha; 0 = alpha_fraction * 2 / lambda_max(E W)
    double alpha_fraction = 0.9;      ///< paper / block_jacobi: alpha as a fraction of the stability bound 2/lambda_max(E W)
    int max_active_set_iterations = 3;    ///< exact solver: active-set passes from the given modes before it
                                          ///< turns to the Tresca fixed point (and again after it); on the
                                          ///< sparse path's Newton route one pass precedes the Newton method
                                          ///< and these passes confirm its answer (docs/contact-solvers.md)
    int tresca_anderson_depth = 8;        ///< exact solver (dense and sparse path): Anderson acceleration depth of
                                          ///< the Tresca fixed point on the friction limits, 0..50; 0 = the plain
                                          ///< fixed point (decision 007: of 3, 5 and 8 only 8 settles the graduated
                                          ///< 10 x 400 first step; 3 needs 6-23 % fewer factorisations at 10 x 100)
    /// Throws InputError naming `solver.<field>`, the value and what is allowed, for a field out of range.
    void validate() const;
};

/// What a solve reports, the same fields in the same meaning whichever form (dense W or sparse
/// K, G: step.hpp) and solver ran; a count of a route the solver did not take is 0. A solve that
/// does not converge says so; it never passes silently.
struct SolveResult {
    bool converged = false;
    int iterations = 0;        ///< the solver's iterations of every kind, its measure of work: sweeps (paper,
                               ///< accelerated, block-Jacobi, the Gauss-Seidel fallback), active-set passes,
                               ///< Newton iterations (also counted in newton_iterations) and box-QP iterations
    double residual_m = 0.0;   ///< ||v||_2 (eq. 9) at the returned forces [m]
    double natural_residual_m = 0.0;  ///< ||natural_map||_2 at the returned forces [m]
    int factorizations = 0;    ///< matrix factorisations this solve did (LU or LDL^T of a set of modes' linear
                               ///< system, dense or sparse, and of the box QPs' systems); 0 for the iterative solvers
    int updates = 0;           ///< sets of modes solved by a low-rank update of an earlier factorisation instead of
                               ///< a new one (the sparse form's bordered LU, SparsePathTuning::max_border_rows)
    int newton_iterations = 0; ///< iterations of the semismooth Newton method (each one linear solve of a set of
                               ///< modes: a factorisation, an update or a cached one; SparsePathTuning::newton_min_rows)
    int smoothing_iterations = 0;  ///< iterations of the smoothing Newton method (each one LU of its Jacobian's
                                   ///< system), for transitions the semismooth one does not settle
    int tresca_iterations = 0;   ///< passes of the Tresca fixed point on the friction limits (box QPs solved;
                                 ///< SolverOptions::tresca_anderson_depth), where it ran
    bool fell_back = false;    ///< the answer is not one the active-set passes confirmed: the settled Tresca fixed
                               ///< point, the Gauss-Seidel sweeps or (sparse form) the dense exact solver finished it
    std::string message;       ///< why it did not converge, when it did not
};

/// A contact solver. It may keep data derived from W between calls (factorisations,
/// eigenvalues): it notices when W changes.
class ContactSolver {
public:
    virtual ~ContactSolver() = default;
    /// Solves `problem`; p is the warm start on entry and the forces [N] on exit.
    virtual SolveResult solve(const ContactProblem& problem, Eigen::VectorXd& p) = 0;
    virtual SolverKind kind() const = 0;
};

/// Creates the solver named in `options`. Throws InputError for bad options.
std::unique_ptr<ContactSolver> make_solver(const SolverOptions& options);

/// The per-step contact problem on the sparse stiffness (the "sparse path"):
///     K z = b + G^T p,    s = G z - d,
/// with the pair laws of ContactProblem (the same pairs, rows and tau rule). z are
/// displacements, K a sparse symmetric positive definite stiffness, G the contact
/// rows. Eliminating z gives the dense problem s = W p + q of ContactProblem with
///     W = G K^-1 G^T,  q = G K^-1 b - d     (to_dense()),
/// so both have the same solution; this form never builds the dense W (its cost
/// grows with the number of elements, not with its square or cube).
struct SparseContactProblem : ContactLaws {
    Eigen::SparseMatrix<double> K;     ///< stiffness, n x n, symmetric positive definite (both triangles stored)
    Eigen::SparseMatrix<double> G;     ///< contact rows [-], m x n
    Eigen::VectorXd b;                 ///< load with p = 0, n entries
    Eigen::VectorXd d;                 ///< offsets [m], m entries (normal gaps, tangential anchors)
    /// The elastic interface layer's compliance per row, c_L [m/N] (System::layer_compliance_m_per_n()):
    /// s = G z + c_L p - d. Empty or all zero: rigid contact. The solver takes the layer as one extra
    /// degree of freedom per layer row, of stiffness 1/c_L, between the surface and the contact force
    /// (K' = diag(K, 1/c_L), G' = [G  E]): G' K'^-1 G'^T = G K^-1 G^T + diag(c_L), the same problem with
    /// a positive definite K' (docs/decisions/013-elastic-interface.md).
    Eigen::VectorXd layer_compliance;

    int size() const { return static_cast<int>(d.size()); }
    /// Throws InputError if the sizes, rows or laws are inconsistent.
    void validate() const;
    /// The equivalent dense problem (W = G K^-1 G^T + diag(c_L), q = G K^-1 b - d): m solves and
    /// m^2 doubles: to replay the problem with a dense solver, and the sparse solver's last-resort fallback.
    ContactProblem to_dense() const;
};

/// The active-set method of SolverKind::exact on a SparseContactProblem. Per set of
/// modes the conditions are linear, so the solve is one sparse saddle-point system
///     [ K                       -G_S^T - G_slip^T D ] [z  ]   [b + G^T e]
///     [ G_S                      0                  ] [p_S] = [d_S      ]
/// (S: rows held by s = 0; slip rows carry p_t = e_t + D p_n), factorised by a sparse
/// LU once per set of modes and reused while the modes stay (few held rows: the dense
/// Schur complement on K's Cholesky factor instead; near the last LU's held set: a
/// low-rank update of it; see SparsePathTuning). The mode switching and the
/// handling of transitions (Tresca fixed point on a box QP, solved by block principal
/// pivoting and, where that does not settle, by an interior-point method; then the coupled Coulomb
/// problem) are those of the exact solver (the same mode code, lib/contact/active_set.hpp), so
/// both paths reach the same solution. Before the Tresca fixed point, a transition is
/// tried by a semismooth Newton method on the natural map (many
/// pairs change mode per iteration, one linear solve of a set of modes each; it starts from
/// the last answer extrapolated linearly from the two before, when the warm start p is this
/// solver's last answer, so a solve's answer may depend on the solves before it; its final
/// modes are confirmed by the active-set passes, SolveResult::newton_iterations), and if
/// that stalls, by a smoothing Newton method (the natural map with every max(0, .)
/// smoothed, the smoothing driven to zero with the residual; one sparse LU of its
/// Jacobian per iteration, SolveResult::smoothing_iterations; its modes are confirmed the
/// same way). If all that fails, a problem of at most 4000 rows is
/// finished by the dense exact solver on to_dense() (SolveResult::fell_back); a larger
/// one returns converged = false with a message. (The units: lib/contact/sparse/; tests force
/// each transition and box-QP method alone through SparsePathTuning::methods.)
///
/// How SparseContactSolver solves the linear problem of a set of modes (the defaults
/// are the measured choices, docs/decisions/002-sparse-contact-path.md; tests set them to force each way; the three
/// fields are those a user may tune):
///  - at most `schur_max_rows` held rows: the dense Schur complement of the held rows on
///    a Cholesky factor of K made once per run (columns K^-1 g_i^T cached per row);
///  - more: a sparse LU of the saddle-point system, and a set of modes without slip
///    coupling that differs from the last LU's held set in at most `max_border_rows`
///    rows is solved by bordering that LU (low-rank update: a solve per changed row and
///    a small dense LU) instead of a new factorisation.
struct SparsePathTuning {
    int schur_max_rows = 400;   ///< >= 0 (0: always the sparse LU)
    int max_border_rows = 150;  ///< >= 0 (0: never update, always refactorise)
    /// >= 0: held sets of at least this many rows, some of them elastic-interface (layer) rows
    /// and at most 200 of them rigid, take the primal route when the library was built with
    /// CHOLMOD (0: never, the default: measured no faster on the 10 x 400 friction runs, where
    /// the slip coupling needs many Krylov iterations): the leaves' stiffness plus the held
    /// layer springs, factorised by CHOLMOD once per run and updated by rank-k updates as rows
    /// enter and leave the set (docs/contact-solvers.md, "Large held sets")
    int primal_min_rows = 0;
    /// >= 0: the Newton method is tried on problems of at least this many contact rows (smaller
    /// ones, e.g. the paper example's 76, settle quickly by the passes and the Tresca fixed
    /// point, and keep exactly the answers they had: their near-degenerate pairs may settle in
    /// another of the modes within the threshold, e.g. 1.03e-9 J against 0.70e-9 J of
    /// energy-balance round-off on the paper example with steel leaves)
    int newton_min_rows = 200;
    /// The transition, box-QP and linear-route methods (sparse_methods.hpp): the defaults are
    /// the measured choices; tests and benchmarks/ set a field to check or measure one way alone.
    SparsePathMethods methods;
    /// Where not null, the solver records its transition steps there (counters per route and
    /// phase, per-step traces: a study aid, docs/decisions/036). The caller owns it; it must
    /// outlive the solver. nullptr (default): nothing recorded and nothing costs.
    SparsePathObserver* observer = nullptr;
};

class SparseContactSolver {
public:
    /// options.kind must be SolverKind::exact; throws InputError otherwise (and for a
    /// negative tuning field, naming it).
    explicit SparseContactSolver(const SolverOptions& options, const SparsePathTuning& tuning = {});
    ~SparseContactSolver();
    SparseContactSolver(const SparseContactSolver&) = delete;
    SparseContactSolver& operator=(const SparseContactSolver&) = delete;

    /// Solves `problem`; p is the warm start on entry and the forces [N] on exit; z the
    /// displacements on exit (K's degrees of freedom; the layer's deflection is c_L p). It keeps its factorisations while K and G stay the same:
    /// it compares them with the previous call's (O(nnz)), unless the caller passes
    /// `structure_unchanged` = true, a promise that K, G and the pairs are those of the
    /// previous call on this solver (the closed-form stepper's are constant over a run;
    /// at 10 leaves x 400 elements the comparison was a quarter of a step's cost).
    SolveResult solve(const SparseContactProblem& problem, Eigen::VectorXd& p, Eigen::VectorXd& z,
                      bool structure_unchanged = false);
    /// s = G z + c_L p - d at the last solution [m].
    const Eigen::VectorXd& relative_positions() const;
    /// Diagonal of W = G K^-1 G^T + diag(c_L) [m/N] (computed once per K, G: it scales the force
    /// violations to metres as in the dense solver).
    const Eigen::VectorXd& compliance_diagonal() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// Largest eigenvalue of a symmetric matrix [same units as W].
double largest_eigenvalue(const Eigen::MatrixXd& W);

}  // namespace stackbeam
