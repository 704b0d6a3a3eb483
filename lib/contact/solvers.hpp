#pragma once
// Internal: constructors of the contact solvers and the exact local solve of
// one pair, shared by the Gauss-Seidel solver and the exact solver's fallback.
#include <memory>

#include "stackbeam/contact/contact.hpp"

namespace stackbeam::detail {

std::unique_ptr<ContactSolver> make_projected_solver(const SolverOptions& options);
std::unique_ptr<ContactSolver> make_exact_solver(const SolverOptions& options);

/// The checks of ContactProblem::validate on the pairs and the tau rule, for n rows.
void validate_laws(const std::vector<ContactPair>& pairs, int n, TauRule tau_rule, const Eigen::VectorXd& tau_previous_n);

/// natural_map() with the diagonal of W given (the sparse path has no dense W).
Eigen::VectorXd natural_map_diag(const ContactProblem& problem, const Eigen::VectorXd& diag,
                                 const Eigen::VectorXd& p, const Eigen::VectorXd& s);
/// ||error_vector(problem, p, s)||_2 and ||natural_map_diag(problem, diag, p, s)||_2 in
/// one pass over the pairs, without the two vectors (the sparse path's per-step report).
void residual_norms(const ContactProblem& problem, const Eigen::VectorXd& diag, const Eigen::VectorXd& p,
                    const Eigen::VectorXd& s, double& error_norm_m, double& natural_norm_m);

/// Exact solution of pair k's own problem s_k = W_kk p_k + b_k (b_k the free
/// term with every other pair's force fixed): open, stick or slip, whichever is
/// consistent. Writes the pair's components of p.
void solve_pair_locally(const ContactProblem& problem, int k, const Eigen::MatrixXd& W, double bn, double bt,
                        Eigen::VectorXd& p);

/// Pair k's own free term (bn, bt) = s_k - W_kk p_k: its relative position with its
/// own force removed and every other pair's force kept.
void pair_free_term(const ContactProblem& problem, int k, const Eigen::VectorXd& p, const Eigen::VectorXd& s,
                    double& bn, double& bt);

/// Base of the solvers that keep data derived from W: refresh() validates the
/// problem and reports true when W is new (so the derived data must be rebuilt).
class WCachingSolver : public ContactSolver {
protected:
    bool refresh(const ContactProblem& problem) {
        if (W_.rows() == problem.size() && W_ == problem.W) return false;
        problem.validate();
        W_ = problem.W;
        return true;
    }
    Eigen::MatrixXd W_;
};

/// Gauss-Seidel sweeps with exact pair solves until ||v||_2 < tolerance_m.
SolveResult gauss_seidel_sweeps(const ContactProblem& problem, Eigen::VectorXd& p, double tolerance_m,
                                int max_sweeps);

}  // namespace stackbeam::detail
