// One per-step contact problem over the dense or the sparse form (step.hpp).
#include "stackbeam/contact/step.hpp"

#include <Eigen/SparseCholesky>
#include <stdexcept>

#include "stackbeam/errors.hpp"

namespace stackbeam {

STACKBEAM_ENUM_WORDS(ContactPath, {ContactPath::automatic, "auto"}, {ContactPath::dense, "dense"},
    {ContactPath::sparse, "sparse"})

const char* to_string(ContactPath path) { return word_of(path); }

ContactPath parse_contact_path(const std::string& text, const std::string& field) {
    return parse_word<ContactPath>(text, field, "contact path");
}

ContactPath resolve_contact_path(ContactPath requested, int rows, SolverKind kind) {
    const bool exact = kind == SolverKind::exact;
    switch (requested) {
        case ContactPath::dense: return ContactPath::dense;
        case ContactPath::sparse:
            if (!exact)
                throw InputError("contact_path", std::string("value 'sparse' needs the exact solver (solver is '") +
                                                     to_string(kind) + "')");
            return ContactPath::sparse;
        case ContactPath::automatic: break;
    }
    return exact && rows >= kSparsePathMinComponents ? ContactPath::sparse : ContactPath::dense;
}

// The dense form: W, and either Q (given in closed form) or K's factor with Y = K^-1 G^T.
struct ContactOperator::Dense {
    Eigen::MatrixXd W, Q;
    Eigen::SparseMatrix<double> G, B, E;  // from the sparse form when built from it
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
    Eigen::MatrixXd Y;                    // K^-1 G^T (from the sparse form)
    bool factored = false;
    // the closed form's displacements and strain energy (DenseStepForm), or the stiffness form's energy
    std::function<Eigen::VectorXd(const Eigen::VectorXd&, const Eigen::VectorXd&)> displacements;
    std::function<double(const Eigen::VectorXd&, const Eigen::VectorXd&)> strain_energy_j;
    decltype(SparseStepForm::strain_energy_j) stiffness_energy_j;
};

struct ContactOperator::Sparse {
    SparseStepForm form;
};

ContactOperator::ContactOperator(const StepSystem& system, ContactPath requested, SolverKind solver)
    : path_(system.sparse ? resolve_contact_path(requested, system.rows, solver) : ContactPath::dense),
      rows_(system.rows) {
    if (!system.sparse && !system.dense)
        throw InputError("system", "gives neither the sparse nor the dense form of the step's contact problem");
    if (path_ == ContactPath::sparse) {
        sparse_ = std::make_unique<Sparse>();
        sparse_->form = system.sparse();
        return;
    }
    dense_ = std::make_unique<Dense>();
    if (system.dense) {
        DenseStepForm f = system.dense();
        dense_->W = std::move(f.W);
        dense_->Q = std::move(f.Q);
        dense_->displacements = std::move(f.displacements);
        dense_->strain_energy_j = std::move(f.strain_energy_j);
        return;
    }
    // From the stiffness form: W = G K^-1 G^T (symmetrised) + diag(c_L); q and z by K's factor.
    const SparseStepForm f = system.sparse();
    dense_->ldlt.compute(f.K);
    if (dense_->ldlt.info() != Eigen::Success)
        throw SolverError("contact operator: the step's stiffness K is not positive definite", 0, 0.0, 0.0);
    // no contact rows (a single leaf): Y is n x 0 (a solve with an empty right-hand side is UB in Eigen)
    dense_->Y = f.G.rows() > 0 ? Eigen::MatrixXd(dense_->ldlt.solve(Eigen::MatrixXd(f.G.transpose())))
                               : Eigen::MatrixXd(f.K.rows(), 0);
    const Eigen::MatrixXd W = f.G * dense_->Y;
    dense_->W = 0.5 * (W + W.transpose());
    if (f.layer_compliance.size() > 0) dense_->W.diagonal() += f.layer_compliance;
    dense_->G = f.G;
    dense_->B = f.B;
    dense_->E = f.E;
    dense_->stiffness_energy_j = f.strain_energy_j;
    dense_->factored = true;
}

ContactOperator::~ContactOperator() = default;

struct StepContactSolver::Impl {
    SolverOptions options;
    SparsePathTuning tuning;
    std::unique_ptr<ContactSolver> dense_solver;
    std::unique_ptr<SparseContactSolver> sparse_solver;
    const ContactOperator* last_op = nullptr;  // the operator of the last solve (its structure kept)
    std::shared_ptr<const ContactOperator> op;
    ContactProblem dense;          // W set once per operator; q, pairs, tau per step
    SparseContactProblem sparse;   // K, G, c_L once per operator; b, d, pairs, tau per step
    Eigen::VectorXd d;             // the last problem's offsets
    Eigen::VectorXd u;             // the last problem's load parameters
    Eigen::VectorXd eu;            // E u of the last sparse step (empty: none)
    Eigen::VectorXd z;             // the last solve's displacements (a closed dense form: when first read)
    Eigen::VectorXd p;             // the closed dense form: the forces z is to be made from
    bool z_pending = false;        // z not yet made from the closed dense form
};

StepContactSolver::StepContactSolver(const SolverOptions& options, const SparsePathTuning& tuning)
    : impl_(std::make_unique<Impl>()) {
    options.validate();
    impl_->options = options;
    impl_->tuning = tuning;
}

StepContactSolver::~StepContactSolver() = default;

SolveResult StepContactSolver::solve(const StepProblem& problem, Eigen::VectorXd& p, Eigen::VectorXd& z) {
    const SolveResult r = solve(problem, p);
    z = displacements();
    return r;
}

SolveResult StepContactSolver::solve(const StepProblem& problem, Eigen::VectorXd& p) {
    Impl& im = *impl_;
    if (!problem.op) throw InputError("problem.op", "is empty: a StepProblem needs its ContactOperator");
    const ContactOperator& op = *problem.op;
    const bool same = im.last_op == &op;
    if (!same) im.op = problem.op;  // keep the operator alive while its factors are cached
    im.d = problem.d;
    im.u = problem.u;
    im.z_pending = false;
    // the laws of the last problem (last_dense_problem() has them on either form)
    static_cast<ContactLaws&>(im.dense) = problem;
    if (const ContactOperator::Dense* D = op.dense()) {
        if (!im.dense_solver) im.dense_solver = make_solver(im.options);
        ContactProblem& pr = im.dense;
        if (!same) pr.W = D->W;
        Eigen::VectorXd v;  // K^-1 B u (built from K)
        if (D->factored) {
            v = D->ldlt.solve(D->B.size() > 0 ? Eigen::VectorXd(D->B * problem.u) : problem.u);
            pr.q = D->G * v - problem.d;
            if (D->E.size() > 0) pr.q += D->E * problem.u;
        } else if (D->Q.cols() > 0) {  // (a form with no contact rows has a 0 x r Q, not the identity)
            pr.q = D->Q * problem.u - problem.d;
        } else {
            pr.q = problem.u - problem.d;
        }
        im.last_op = &op;
        const SolveResult r = im.dense_solver->solve(pr, p);
        if (D->factored) {
            im.z = v + D->Y * p;
        } else {  // the closed form's z, when read (the paper's step never needs it)
            im.p = p;
            im.z_pending = static_cast<bool>(D->displacements);
            im.z.resize(0);
        }
        return r;
    }
    const ContactOperator::Sparse& S = *op.sparse();
    // a new operator: a new sparse solver (its factors and warm starts are of the operator's K, G)
    if (!im.sparse_solver || !same) im.sparse_solver = std::make_unique<SparseContactSolver>(im.options, im.tuning);
    SparseContactProblem& pr = im.sparse;
    if (!same) {
        pr.K = S.form.K;
        pr.G = S.form.G;
        pr.layer_compliance = S.form.layer_compliance;
    }
    pr.b = S.form.B.size() > 0 ? Eigen::VectorXd(S.form.B * problem.u) : problem.u;
    if (S.form.E.size() > 0) {
        im.eu = S.form.E * problem.u;
        pr.d = problem.d - im.eu;
    } else {
        im.eu.resize(0);
        pr.d = problem.d;
    }
    static_cast<ContactLaws&>(pr) = problem;
    // K, G and the pairs are those of the previous call on the same operator (fixed over a run)
    const SolveResult r = im.sparse_solver->solve(pr, p, im.z, same);
    im.last_op = &op;
    return r;
}

const Eigen::VectorXd& StepContactSolver::displacements() const {
    Impl& im = *impl_;
    if (im.z_pending) {
        im.z = im.last_op->dense()->displacements(im.u, im.p);
        im.z_pending = false;
    }
    return im.z;
}

Eigen::VectorXd StepContactSolver::relative_positions(const Eigen::VectorXd& p) const {
    const Impl& im = *impl_;
    if (im.last_op && im.last_op->dense()) return im.dense.W * p + im.dense.q + im.d;
    Eigen::VectorXd rel = im.sparse_solver->relative_positions() + im.sparse.d;
    if (im.eu.size() > 0) rel += im.eu;
    return rel;
}

double StepContactSolver::strain_energy_j(const Eigen::VectorXd& p, const Eigen::VectorXd& rel) const {
    const Impl& im = *impl_;
    if (!im.last_op) throw std::logic_error("StepContactSolver::strain_energy_j before a solve");
    if (const ContactOperator::Dense* D = im.last_op->dense()) {
        if (D->strain_energy_j) return D->strain_energy_j(im.u, p);
        if (D->stiffness_energy_j) return D->stiffness_energy_j(im.u, p, displacements(), rel);
    } else if (im.last_op->sparse()->form.strain_energy_j) {
        return im.last_op->sparse()->form.strain_energy_j(im.u, p, im.z, rel);
    }
    throw std::logic_error("StepContactSolver::strain_energy_j: the step's form gives no strain energy");
}

ContactPath StepContactSolver::path() const noexcept {
    return impl_->last_op ? impl_->last_op->path() : ContactPath::automatic;
}

const ContactProblem& StepContactSolver::last_dense_problem() const noexcept { return impl_->dense; }
const SparseContactProblem& StepContactSolver::last_sparse_problem() const noexcept { return impl_->sparse; }

std::unique_ptr<StepContactSolver> start_step_contact(const StepSystem& system, ContactPath requested,
                                                      const SolverOptions& options, const SparsePathTuning& tuning,
                                                      const std::vector<ContactPair>& pairs, TauRule tau_rule,
                                                      StepProblem& problem) {
    problem.op = std::make_shared<const ContactOperator>(system, requested, options.kind);
    problem.pairs = pairs;
    problem.tau_rule = tau_rule;
    return std::make_unique<StepContactSolver>(options, tuning);
}

}  // namespace stackbeam
