// A user of stackbeam's contact component alone (stackbeam::contact, or
// stackbeam-contact.pc): no time integration, hence no SUNDIALS. Prints the paper
// example's bonded tied stiffness (fe) and the forces of one contact pair solved by
// the exact solver (contact); package_test.cmake checks both.
#include <cstdio>

#include "stackbeam/contact/contact.hpp"
#include "stackbeam/fe/system.hpp"
#include "stackbeam/model/paper_example.hpp"

int main() {
    const stackbeam::System system(stackbeam::Model::build(stackbeam::paper_example(stackbeam::PaperCase::bonded)));

    // One Coulomb pair (row 0 normal, row 1 tangential), mu = 0.5, compliance W [m/N]
    // symmetric positive definite. q = -W p_known makes the gap s = q + W p zero at
    // p_known = (-10, 3) N (compression negative): closed, and sticking since
    // |p_t| = 3 N < mu |p_n| = 5 N, so p_known is the solution.
    stackbeam::ContactProblem problem;
    problem.W.resize(2, 2);
    problem.W << 2.0e-6, 0.3e-6,
                 0.3e-6, 1.5e-6;
    const Eigen::Vector2d p_known(-10.0, 3.0);
    problem.q = -problem.W * p_known;
    problem.pairs = {stackbeam::ContactPair{stackbeam::PairKind::coulomb, 0.5, 0.0, 0, 1}};
    Eigen::VectorXd p = Eigen::VectorXd::Zero(2);
    const stackbeam::SolveResult result = stackbeam::make_solver(stackbeam::SolverOptions{})->solve(problem, p);

    std::printf("tied stiffness %.0f N/m, pair forces (%.3f, %.3f) N, %s\n", system.tied_stiffness_n_per_m(), p(0), p(1),
                result.converged ? "converged" : result.message.c_str());
    return result.converged ? 0 : 1;
}
