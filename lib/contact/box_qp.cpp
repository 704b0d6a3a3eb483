#include "contact/box_qp.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>

namespace stackbeam::detail {

void project_onto_box(const Eigen::VectorXd& lower, const Eigen::VectorXd& upper, Eigen::VectorXd& x,
                      std::vector<signed char>& at_bound) {
    const int n = static_cast<int>(x.size());
    at_bound.resize(n, 0);
    for (int i = 0; i < n; ++i) {  // feasible start; components with an empty interior are held
        if (x[i] <= lower[i]) { x[i] = lower[i]; if (std::isfinite(lower[i])) at_bound[i] = -1; }
        if (x[i] >= upper[i]) { x[i] = upper[i]; if (std::isfinite(upper[i])) at_bound[i] = +1; }
        if (at_bound[i] == -1 && !std::isfinite(lower[i])) at_bound[i] = 0;
        if (at_bound[i] == +1 && !std::isfinite(upper[i])) at_bound[i] = 0;
        if (at_bound[i] != 0) x[i] = at_bound[i] < 0 ? lower[i] : upper[i];
        if (lower[i] == upper[i]) at_bound[i] = +1;
    }
}

BoxQpResult solve_box_qp(const Eigen::MatrixXd& W, const Eigen::VectorXd& q, const Eigen::VectorXd& lower,
                         const Eigen::VectorXd& upper, Eigen::VectorXd& x, std::vector<signed char>& at_bound,
                         double tolerance, int max_iterations) {
    const int n = static_cast<int>(q.size());
    BoxQpResult r;
    project_onto_box(lower, upper, x, at_bound);
    std::vector<int> freev;
    Eigen::VectorXd y(n), rhs;
    Eigen::MatrixXd M;
    Eigen::LLT<Eigen::MatrixXd> llt;
    while (r.iterations < max_iterations) {
        ++r.iterations;
        // equality-constrained step: free components solve s_F = 0 with the bound ones held
        freev.clear();
        for (int i = 0; i < n; ++i)
            if (at_bound[i] == 0) freev.push_back(i);
        const int m = static_cast<int>(freev.size());
        y = x;
        if (m > 0) {
            M.resize(m, m);
            rhs.resize(m);
            for (int a = 0; a < m; ++a) {
                double acc = q[freev[a]];
                for (int j = 0; j < n; ++j)
                    if (at_bound[j] != 0) acc += W(freev[a], j) * x[j];
                rhs[a] = -acc;
                for (int b = 0; b < m; ++b) M(a, b) = W(freev[a], freev[b]);
            }
            llt.compute(M);
            ++r.factorizations;
            const Eigen::VectorXd sol = llt.solve(rhs);
            for (int a = 0; a < m; ++a) y[freev[a]] = sol[a];
        }
        // longest feasible step toward y
        double alpha = 1.0;
        int blocking = -1;
        signed char side = 0;
        for (int a = 0; a < m; ++a) {
            const int i = freev[a];
            const double d = y[i] - x[i];
            if (d < 0.0 && y[i] < lower[i]) {
                const double t = (lower[i] - x[i]) / d;
                if (t < alpha) { alpha = t; blocking = i; side = -1; }
            } else if (d > 0.0 && y[i] > upper[i]) {
                const double t = (upper[i] - x[i]) / d;
                if (t < alpha) { alpha = t; blocking = i; side = +1; }
            }
        }
        x += std::max(alpha, 0.0) * (y - x);
        if (blocking >= 0) {
            at_bound[blocking] = side;
            x[blocking] = side < 0 ? lower[blocking] : upper[blocking];
            continue;
        }
        // at the minimum on the working set: release the worst wrong-signed multiplier
        const Eigen::VectorXd s = W * x + q;
        int worst = -1;
        double worst_size = tolerance;
        for (int i = 0; i < n; ++i) {
            if (at_bound[i] == 0 || lower[i] == upper[i]) continue;
            const double wrong = at_bound[i] < 0 ? -s[i] : s[i];  // lower bound needs s >= 0, upper s <= 0
            if (wrong > worst_size) { worst_size = wrong; worst = i; }
        }
        if (worst < 0) {
            r.converged = true;
            return r;
        }
        at_bound[worst] = 0;
    }
    return r;
}

}  // namespace stackbeam::detail
