#pragma once
/// @file step.hpp
/// One per-step contact problem and one solver entry point over both ways of posing it
/// (docs/contact-solvers.md, "Dense and sparse contact path"; docs/decisions/030).
///
/// A stepper's step is, in stiffness form (z the step's degrees of freedom, p the forces):
///     K z = B u + G^T p,    s = G z + c_L p - (d - E u)
/// with u the step's load parameters (r entries), B (n x r) their load on z and E (m x r)
/// their shift of the offsets d. Eliminating z gives the dense form of ContactProblem,
///     s = W p + q,   W = G K^-1 G^T + diag(c_L),   q = Q u - d,   Q = G K^-1 B + E.
/// The operator (ContactOperator, as Pinocchio's Delassus operators) holds one of the two:
/// the dense W (and Q, or K's factor to form q and z), or the sparse K, G with the sparse
/// solver's factors. Which one is decided once, when the operator is built, from the number
/// of rows, the solver and the requested ContactPath; a stepper builds a StepProblem per step
/// and calls StepContactSolver::solve, and never knows which form runs.
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "stackbeam/contact/contact.hpp"

namespace stackbeam {

/// How the per-step contact problem is posed.
enum class ContactPath {
    automatic,  ///< dense for small problems, sparse for large ones (resolve_contact_path)
    dense,      ///< ContactProblem: the dense W (O(m^2) memory, O(m^3) set-up); every solver
    sparse,     ///< SparseContactProblem on the banded stiffness, near-linear in the elements; exact solver only
};
template <>
const std::vector<EnumWord<ContactPath>>& enum_words<ContactPath>();
const char* to_string(ContactPath path);
/// Parses "auto" | "dense" | "sparse"; throws InputError naming `field`.
ContactPath parse_contact_path(const std::string& text, const std::string& field);

/// ContactPath::automatic takes the sparse path from this many contact components
/// (rows of the contact problem) on, with the exact solver. Measured (docs/decisions/
/// 050-automatic-path-threshold.md; CPU s per simulated second, 100 ms friction runs): on the
/// graduated 10-leaf spring the dense path is 1.12x faster at 144 rows, the sparse one 2.2x at
/// 234 and 10x at 540; on the paper example's 3 leaves the two are equal at 116 rows and the
/// sparse one 1.2x faster at 156. Bonded runs are faster on the sparse path at every size (1.7x
/// on the paper example); below this the dense path keeps the paper example and the small
/// stacks on the paper's form, at most 20 % slower for friction. (Decision 002's 1,000 was
/// measured on the sparse path before decisions 003-047.)
constexpr int kSparsePathMinComponents = 150;

/// The path `requested` resolves to for a problem of `rows` contact rows solved by `kind`:
/// automatic gives sparse when the solver is exact and rows >= kSparsePathMinComponents, dense
/// otherwise. Throws InputError (field "contact_path") for sparse with a solver other than exact.
ContactPath resolve_contact_path(ContactPath requested, int rows, SolverKind kind);

/// The sparse (stiffness) form of a step's operator: K z = B u + G^T p, s = G z + c_L p - (d - E u).
struct SparseStepForm {
    Eigen::SparseMatrix<double> K;     ///< n x n, symmetric positive definite (both triangles stored)
    Eigen::SparseMatrix<double> G;     ///< m x n contact rows [-]
    Eigen::VectorXd layer_compliance;  ///< c_L [m/N] per row, or empty (rigid contact)
    Eigen::SparseMatrix<double> B;     ///< n x r load shape; empty: the identity (u is the load on z, r = n)
    Eigen::SparseMatrix<double> E;     ///< m x r offset shift [m per unit u]; empty: none
    /// The strain energy U [J] of a solved step from its load parameters u, forces p, displacements z
    /// and relative positions rel = s + d, by the builder's own formula (optional; e.g. without a
    /// product with K). StepContactSolver::strain_energy_j() evaluates it.
    std::function<double(const Eigen::VectorXd& u, const Eigen::VectorXd& p, const Eigen::VectorXd& z,
                         const Eigen::VectorXd& rel)>
        strain_energy_j;
};

/// The dense form of a step's operator, where its builder knows it in closed form.
struct DenseStepForm {
    Eigen::MatrixXd W;  ///< m x m compliance [m/N] = G K^-1 G^T + diag(c_L)
    Eigen::MatrixXd Q;  ///< m x r: q = Q u - d (= G K^-1 B + E); empty: the identity (u is the free term plus d, r = m)
    /// The displacements z [m, rad] of the sparse form's degrees of freedom for the step's u and the
    /// forces p (e.g. from System::reduced_displacements), where W is given without K: evaluated only
    /// when a caller reads them (StepContactSolver::displacements). Empty: the operator has no
    /// degrees of freedom beyond the contact rows (displacements() is empty).
    std::function<Eigen::VectorXd(const Eigen::VectorXd& u, const Eigen::VectorXd& p)> displacements;
    /// The strain energy U [J] of a solved step from u and p, in closed form (optional).
    std::function<double(const Eigen::VectorXd& u, const Eigen::VectorXd& p)> strain_energy_j;
};

/// What a stepper's step is, given both ways; the operator builds only the form it takes.
struct StepSystem {
    int rows = 0;                            ///< m, the contact rows
    /// The stiffness form. Empty: only the dense form is given (e.g. the event driver's W on a
    /// state without stiffness form); the dense path is then taken whatever the request.
    std::function<SparseStepForm()> sparse;
    /// The dense form in closed form (optional; e.g. C' + (gamma/k) c c^T and c of the
    /// closed-form step). Empty: the dense operator is built from the sparse form (K's sparse
    /// factor; W = G K^-1 G^T + diag(c_L); q and z by one solve with it per step).
    std::function<DenseStepForm()> dense;
};

/// The operator of a run's per-step problems, dense or sparse behind it (immutable once built).
class ContactOperator {
public:
    /// Chooses the form (resolve_contact_path(requested, system.rows, solver); dense where the
    /// system gives no sparse form) and builds it. Throws InputError where neither form is given.
    ContactOperator(const StepSystem& system, ContactPath requested, SolverKind solver);
    ~ContactOperator();
    ContactOperator(const ContactOperator&) = delete;
    ContactOperator& operator=(const ContactOperator&) = delete;

    /// The form taken (dense or sparse; never automatic): outside the contact layer for reports, not for branching on.
    ContactPath path() const noexcept { return path_; }
    int rows() const noexcept { return rows_; }

private:
    friend class StepContactSolver;  // solves on the form built (lib/contact/step.cpp)
    struct Dense;
    struct Sparse;
    const Dense* dense() const noexcept { return dense_.get(); }
    const Sparse* sparse() const noexcept { return sparse_.get(); }
    ContactPath path_ = ContactPath::dense;
    int rows_ = 0;
    std::unique_ptr<Dense> dense_;
    std::unique_ptr<Sparse> sparse_;
};

/// The per-step contact problem as a plain value: the operator (shared over a run), the pair
/// laws, the step's load parameters u and the offsets d.
struct StepProblem : ContactLaws {
    std::shared_ptr<const ContactOperator> op;
    Eigen::VectorXd u;                ///< the step's load parameters (SparseStepForm::B's columns)
    Eigen::VectorXd d;                ///< offsets [m], one per row (normal gaps, tangential anchors)
};

/// The one contact solve of the library: a step's problem over either form, the dense form by the
/// solver of options.kind (make_solver), the sparse one by SparseContactSolver (exact only). What a
/// caller reads of the solution (the forces, the displacements, the relative positions, the strain
/// energy, the SolveResult) means the same on both forms; the form taken is for reports only.
class StepContactSolver {
public:
    /// Throws InputError for bad options or tuning (SolverOptions::validate, SparseContactSolver).
    explicit StepContactSolver(const SolverOptions& options, const SparsePathTuning& tuning = {});
    ~StepContactSolver();
    StepContactSolver(const StepContactSolver&) = delete;
    StepContactSolver& operator=(const StepContactSolver&) = delete;

    /// Solves `problem`; p is the warm start on entry and the forces [N] on exit. Keeps its
    /// factorisations while the operator stays the same object (a new operator on the sparse form:
    /// a new sparse solver, its factors being of the operator's K and G).
    SolveResult solve(const StepProblem& problem, Eigen::VectorXd& p);
    /// The same, and z receives displacements() (an n-vector where the operator has degrees of freedom).
    SolveResult solve(const StepProblem& problem, Eigen::VectorXd& p, Eigen::VectorXd& z);
    /// The displacements z [m, rad] of the operator's degrees of freedom at the last solve: the
    /// sparse solve's, K^-1 (B u + G^T p) on a dense form built from the stiffness form, or the dense
    /// form's DenseStepForm::displacements (computed here, once per solve, when first read).
    const Eigen::VectorXd& displacements() const;
    /// The relative positions s + d [m] at the last solve (forces p: those it returned).
    Eigen::VectorXd relative_positions(const Eigen::VectorXd& p) const;
    /// The strain energy U [J] at the last solve (forces p: those it returned, rel: relative_positions),
    /// by the form's own formula (SparseStepForm / DenseStepForm::strain_energy_j). Throws
    /// std::logic_error where the form taken gives none.
    double strain_energy_j(const Eigen::VectorXd& p, const Eigen::VectorXd& rel) const;
    /// The form of the last solve's operator (dense or sparse): for reports, never for branching on.
    ContactPath path() const noexcept;
    /// The last step's problem in the form solved: the dense ContactProblem (W, q; empty W on
    /// the sparse form) and the SparseContactProblem (K, G, b, d; empty on the dense form). For
    /// tests and studies that replay a step.
    const ContactProblem& last_dense_problem() const noexcept;
    const SparseContactProblem& last_sparse_problem() const noexcept;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// The impulse projection of an impact (restitution law): the velocities v of the degrees of
/// freedom of mass M [kg, kg m^2] projected so that the held contact rows C move as asked,
///     M v+ + G_C^T l = M v,   G_C v+ = -b,
/// the M-orthogonal projection (the impulse G_C^T l that changes the kinetic energy least). On
/// the form the step's operator took: dense, A = G M^-1 G^T and Z = M^-1 G^T once per run and
/// A_CC factorised per held set (m^2 doubles, affordable where W is dense); sparse, the saddle
/// matrix [M G_C^T; G_C 0] factorised by a sparse LU per held set.
class ImpactProjection {
public:
    /// M's factor (an LDL^T of M, kept by the caller) and G (m x n); `op` the step's operator.
    ImpactProjection(const Eigen::SparseMatrix<double>& M, const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>& mass,
                     const Eigen::SparseMatrix<double>& G, const ContactOperator& op);
    ~ImpactProjection();
    ImpactProjection(const ImpactProjection&) = delete;
    ImpactProjection& operator=(const ImpactProjection&) = delete;
    /// Projects v (on entry v-, on exit v+) for the held rows `held` (ascending, not empty) and
    /// their target -b [m/s]; returns the kinetic energy removed times `factor` [J] (factor: the
    /// whole spring's factor): 1/2 (v- - v+)^T M (v- - v+) where b = 0 (`elastic` false), the
    /// difference of the kinetic energies otherwise. Throws SolverError naming `step` where the
    /// saddle matrix is singular.
    double project(const std::vector<int>& held, const Eigen::VectorXd& b, bool elastic, double factor, long step,
                   double t_s, Eigen::VectorXd& v);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// A stepper's contact solve set up once per run: a new operator of `system` (its path chosen
/// here, once: ContactOperator), `problem` over it with these pairs and tau rule (its u and d
/// left to each step), and the solver it returns. Throws InputError as the two constructors.
std::unique_ptr<StepContactSolver> start_step_contact(const StepSystem& system, ContactPath requested,
                                                      const SolverOptions& options, const SparsePathTuning& tuning,
                                                      const std::vector<ContactPair>& pairs, TauRule tau_rule,
                                                      StepProblem& problem);

}  // namespace stackbeam
