#pragma once
// Internal: constructors of the contact solvers and the exact local solve of
// one pair, shared by the Gauss-Seidel solver and the exact solver's fallback.
#include <memory>

#include "stackbeam/contact.hpp"

namespace stackbeam::detail {

std::unique_ptr<ContactSolver> make_projected_solver(const SolverOptions& options);
std::unique_ptr<ContactSolver> make_exact_solver(const SolverOptions& options);

/// Exact solution of pair k's own problem s_k = W_kk p_k + b_k (b_k the free
/// term with every other pair's force fixed): open, stick or slip, whichever is
/// consistent. Writes the pair's components of p.
void solve_pair_locally(const ContactProblem& problem, int k, const Eigen::MatrixXd& W, double bn, double bt,
                        Eigen::VectorXd& p);

/// Gauss-Seidel sweeps with exact pair solves until ||v||_2 < tolerance_m.
SolveResult gauss_seidel_sweeps(const ContactProblem& problem, Eigen::VectorXd& p, double tolerance_m,
                                int max_sweeps);

}  // namespace stackbeam::detail
