// The box QP of the Tresca fixed point by block principal pivoting and by the monotone
// primal active-set method (box_qp_methods.hpp).
#include <algorithm>
#include <cmath>
#include <limits>

#include "contact/box_qp.hpp"
#include "contact/sparse/qp/box_qp_methods.hpp"

namespace stackbeam::detail::sparse {

namespace {
constexpr int kBoxPasses = 50;  // block principal pivoting passes per box QP
// passes without fewer violations before the box QP turns to Murty's single switches:
// 8 halves the factorisations of friction steps on 10 leaves against 3 (measured:
// 18 -> 8 per step at 342 rows, 290 -> 150 at 1,782); the primal method still backs it up
constexpr int kBoxBudget = 8;
}  // namespace

double box_row_violation(int i, const std::vector<signed char>& at_bound, const Eigen::VectorXd& x,
                         const Eigen::VectorXd& s, const Eigen::VectorXd& lower, const Eigen::VectorXd& upper,
                         const Eigen::VectorXd& diag) {
    if (at_bound[i] == 0) return std::max(lower[i] - x[i], x[i] - upper[i]) * diag[i];
    if (lower[i] < upper[i]) return at_bound[i] < 0 ? -s[i] : s[i];
    return 0.0;
}

/// The box-constrained QP by block principal pivoting (Judice & Pires): every
/// violated bound or multiplier switches at once while their number falls, then
/// Murty's least-index rule (finite: the QP's matrix W is symmetric positive definite).
/// A few factorisations where the primal method needs one per working-set change
/// (hundreds per step on a 10-leaf stack). Returns false after max_passes.
bool box_qp_pivoting(SparsePath& path, const BoxQp& box, Eigen::VectorXd& x, Eigen::VectorXd& z,
                     std::vector<signed char>& at_bound, SolveResult& r) {
    const SparseStiffness& st = path.stiffness();
    const Eigen::VectorXd &b = box.step.b, &d = box.step.d, &lower = box.lower, &upper = box.upper;
    const double tolerance = box.tolerance;
    const int max_passes = kBoxPasses;
    const int m = static_cast<int>(x.size());
    at_bound.resize(m, 0);
    for (int i = 0; i < m; ++i) {
        if (lower[i] == upper[i]) at_bound[i] = +1;
        if (at_bound[i] == -1 && !std::isfinite(lower[i])) at_bound[i] = 0;
        if (at_bound[i] == +1 && !std::isfinite(upper[i])) at_bound[i] = 0;
    }
    modes::ModeLinearization qp;
    std::vector<int> viol;
    int best = std::numeric_limits<int>::max(), budget = kBoxBudget;
    for (int pass = 0; pass < max_passes; ++pass) {
        ++r.iterations;
        qp.S.clear();
        qp.e.setZero(m);
        for (int i = 0; i < m; ++i) {
            if (at_bound[i] == 0) qp.S.push_back(i);
            else qp.e[i] = at_bound[i] < 0 ? lower[i] : upper[i];
        }
        std::vector<signed char> key(at_bound);
        key.push_back(100);  // a box-QP working set, not a set of modes
        r.factorizations += path.solver.solve(qp, key, b, d, x, z);
        const Eigen::VectorXd sx = st.Grow * z - d;
        viol.clear();
        for (int i = 0; i < m; ++i)
            if (box_row_violation(i, at_bound, x, sx, lower, upper, st.diag) > tolerance) viol.push_back(i);
        const int nv = static_cast<int>(viol.size());
        if (nv == 0) return true;
        bool single = false;
        if (nv < best) {
            best = nv;
            budget = kBoxBudget;
        } else if (budget > 0) {
            --budget;
        } else {
            single = true;
        }
        if (single) viol.resize(1);
        for (int i : viol) {
            if (at_bound[i] != 0) at_bound[i] = 0;
            else at_bound[i] = x[i] < lower[i] ? -1 : +1;
        }
    }
    return false;
}

/// The box-constrained QP min 1/2 x^T W x + q^T x, lower <= x <= upper, by the monotone
/// primal active-set method of box_qp.hpp (the dense solver's), each equality-constrained
/// step one sparse solve of the held (free) rows with the bound ones fixed: the
/// objective falls at every iteration, so it cannot cycle. x = p, and z follows it.
bool box_qp_primal(SparsePath& path, const BoxQp& box, Eigen::VectorXd& x, Eigen::VectorXd& z,
                   std::vector<signed char>& at_bound, SolveResult& r) {
    const SparseStiffness& st = path.stiffness();
    const Eigen::VectorXd &b = box.step.b, &d = box.step.d, &lower = box.lower, &upper = box.upper;
    const double tolerance = box.tolerance;
    const int max_iterations = 50 * (static_cast<int>(d.size()) + 1);
    const int m = static_cast<int>(x.size());
    detail::project_onto_box(lower, upper, x, at_bound);
    z = st.k_llt.solve(b + st.G.transpose() * x);
    modes::ModeLinearization qp;
    Eigen::VectorXd y, zy;
    struct Blocking { int row; double t; signed char side; };
    std::vector<Blocking> blocking_rows;
    std::vector<int> wrong_rows;
    bool single = false;  // release one bound per iteration (after a zero step)
    int released = 0;     // bounds released by the last release
    for (int iter = 0; iter < max_iterations; ++iter) {
        ++r.iterations;
        qp.S.clear();
        qp.e = x;
        for (int i = 0; i < m; ++i)
            if (at_bound[i] == 0) {
                qp.S.push_back(i);
                qp.e[i] = 0.0;
            }
        std::vector<signed char> key(at_bound);
        key.push_back(100);  // a box-QP working set, not a set of modes
        r.factorizations += path.solver.solve(qp, key, b, d, y, zy);
        // step towards y up to the first bound; every row that reaches its bound at that
        // step length (ties: in degenerate problems many rows sit at a bound with a zero
        // step) joins the bounds at once. The iterate stays feasible and the objective
        // does not rise (y minimises it on the subspace, which holds x).
        double alpha = 1.0;
        blocking_rows.clear();
        for (int i : qp.S) {
            const double dd = y[i] - x[i];
            double t = 2.0;
            signed char side = 0;
            if (dd < 0.0 && y[i] < lower[i]) { t = (lower[i] - x[i]) / dd; side = -1; }
            else if (dd > 0.0 && y[i] > upper[i]) { t = (upper[i] - x[i]) / dd; side = +1; }
            if (side == 0) continue;
            t = std::max(t, 0.0);
            alpha = std::min(alpha, t);
            blocking_rows.push_back({i, t, side});
        }
        x += alpha * (y - x);
        z += alpha * (zy - z);
        bool blocked = false;
        for (const auto& c : blocking_rows)
            if (c.t <= alpha + 1e-14) {
                at_bound[c.row] = c.side;
                x[c.row] = c.side < 0 ? lower[c.row] : upper[c.row];
                blocked = true;
            }
        if (blocked) {
            // a zero step right after releasing several rows: release one at a time from
            // now on (the classical rule, which cannot cycle)
            if (alpha == 0.0 && released > 1) single = true;
            released = 0;
            continue;
        }
        // release the bounds whose multiplier has the wrong sign: all of them (the step to
        // the new subspace minimiser still lowers the objective), or the worst one only
        const Eigen::VectorXd sx = st.Grow * z - d;
        int worst = -1;
        double worst_size = tolerance;
        wrong_rows.clear();
        for (int i = 0; i < m; ++i) {
            if (at_bound[i] == 0 || lower[i] == upper[i]) continue;
            const double wrong = at_bound[i] < 0 ? -sx[i] : sx[i];
            if (wrong > tolerance) wrong_rows.push_back(i);
            if (wrong > worst_size) { worst_size = wrong; worst = i; }
        }
        if (worst < 0) return true;
        if (single) {
            at_bound[worst] = 0;
            released = 1;
        } else {
            for (int i : wrong_rows) at_bound[i] = 0;
            released = static_cast<int>(wrong_rows.size());
        }
    }
    return false;
}

}  // namespace stackbeam::detail::sparse
