// The paper's projected iteration (eq. 17) with E = I, and its Gauss-Seidel
// accelerated form (E = per-pair block inverse of W, applied pair by pair).
#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

#include "contact/solvers.hpp"
#include "stackbeam/errors.hpp"

namespace stackbeam::detail {
namespace {

double sign(double x) { return (x > 0.0) - (x < 0.0); }

/// The common loop of the iterative solvers: `update(p, s, v)` makes the next iterate
/// from the current one (s = W p + q and v its error vector, eq. 9); the loop stops at
/// ||v||_2 < tolerance (the paper's step 8), or at the iteration limit with a message
/// that starts with `what`. `at_least_once`: iterate even if the start already passes.
template <class Update>
SolveResult iterate(const ContactProblem& problem, Eigen::VectorXd& p, const SolverOptions& o,
                    const std::string& what, bool at_least_once, Update update) {
    SolveResult r;
    Eigen::VectorXd s = problem.W * p + problem.q;
    Eigen::VectorXd v = error_vector(problem, p, s);
    r.residual_m = v.norm();
    bool first = at_least_once;
    while (first || r.residual_m >= o.tolerance_m) {
        first = false;
        if (r.iterations >= o.max_iterations || !std::isfinite(r.residual_m)) {
            r.message = what + " did not reach ||v|| < " + format_value(o.tolerance_m) + " m in " +
                        std::to_string(r.iterations) + " iterations; residual " + format_value(r.residual_m) + " m";
            return r;
        }
        update(p, s, v);
        s.noalias() = problem.W * p;
        s += problem.q;
        v = error_vector(problem, p, s);
        r.residual_m = v.norm();
        ++r.iterations;
    }
    r.converged = true;
    return r;
}

/// eq. 17:
///   p_bar = p - alpha E s;  p_n = min(0, p_bar_n);
///   p_t = sign(p_bar_t) min(|p_bar_t|, mu tau)  if v_t = s_t at the previous iterate,
///       = sign(p_bar_t) mu tau                  if v_t = 0 != s_t (slipping with the right sign),
/// iterated until ||v||_2 < tolerance (step 8 of the paper's algorithm).
/// with E = I (the paper). alpha defaults to a fraction of the bound 2 / lambda_max(W).
class PaperSolver final : public WCachingSolver {
public:
    explicit PaperSolver(const SolverOptions& o) : options_(o) {}
    SolverKind kind() const override { return options_.kind; }

    SolveResult solve(const ContactProblem& problem, Eigen::VectorXd& p) override {
        const int n = problem.size();
        if (p.size() != n) p = Eigen::VectorXd::Zero(n);
        if (refresh(problem)) lambda_max_ = largest_eigenvalue(W_);
        const double alpha = options_.alpha > 0.0 ? options_.alpha : options_.alpha_fraction * 2.0 / lambda_max_;
        Eigen::VectorXd pbar(n);
        const std::string what = "paper iteration (eq. 17, E = I, alpha = " + format_value(alpha) +
                                 "; stable below 2/lambda_max(W) = " + format_value(2.0 / lambda_max_) + ")";
        return iterate(problem, p, options_, what, false,
                       [&](Eigen::VectorXd& p, const Eigen::VectorXd& s, const Eigen::VectorXd& v) {
            pbar.noalias() = p - alpha * s;
            for (std::size_t k = 0; k < problem.pairs.size(); ++k) {
                const auto& c = problem.pairs[k];
                if (c.row_n >= 0)
                    p[c.row_n] = c.kind == PairKind::coulomb ? std::min(0.0, pbar[c.row_n]) : pbar[c.row_n];
                if (c.row_t < 0) continue;
                const int t = c.row_t;
                if (c.kind == PairKind::bonded) {
                    p[t] = pbar[t];
                    continue;
                }
                const double limit = c.friction_coefficient * friction_normal_force(problem, static_cast<int>(k), p);
                const bool slipping = v[t] == 0.0 && s[t] != 0.0;
                p[t] = slipping ? sign(pbar[t]) * limit : sign(pbar[t]) * std::min(std::abs(pbar[t]), limit);
            }
        });
    }

private:
    SolverOptions options_;
    double lambda_max_ = 0.0;
};

/// eq. 17 with E = the inverse of W's per-pair 2x2 diagonal blocks, the projection
/// taken in each block's own metric (so that the fixed point is the solution): every
/// pair's local problem is solved exactly with the other pairs' forces of the
/// previous iterate, and all pairs move together by the relaxation alpha_fraction.
/// (With a non-diagonal E, the paper's component-wise projection would have a fixed
/// point off the solution: a slipping pair would keep s_n = -E_nt s_t / E_nn != 0.)
class BlockJacobiSolver final : public WCachingSolver {
public:
    explicit BlockJacobiSolver(const SolverOptions& o) : options_(o) {}
    SolverKind kind() const override { return SolverKind::block_jacobi; }
    SolveResult solve(const ContactProblem& problem, Eigen::VectorXd& p) override {
        const int n = problem.size();
        if (p.size() != n) p = Eigen::VectorXd::Zero(n);
        if (refresh(problem)) {
            Eigen::MatrixXd D = Eigen::MatrixXd::Zero(n, n);  // per-pair diagonal blocks of W
            for (const auto& c : problem.pairs)
                for (int a : {c.row_n, c.row_t})
                    for (int b : {c.row_n, c.row_t})
                        if (a >= 0 && b >= 0) D(a, b) = W_(a, b);
            Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(W_, D, Eigen::EigenvaluesOnly);
            lambda_max_ = es.eigenvalues().maxCoeff();
        }
        // relaxation: a fraction of the stability bound 2 / lambda_max(E W) of the linear part
        const double relax = options_.alpha > 0.0 ? options_.alpha : options_.alpha_fraction * 2.0 / lambda_max_;
        Eigen::VectorXd local(n);
        return iterate(problem, p, options_, "block-Jacobi iteration (relaxation " + format_value(relax) + ")", true,
                       [&](Eigen::VectorXd& p, const Eigen::VectorXd& s, const Eigen::VectorXd&) {
            local = p;
            for (int k = 0; k < static_cast<int>(problem.pairs.size()); ++k) {
                double bn, bt;
                pair_free_term(problem, k, p, s, bn, bt);
                solve_pair_locally(problem, k, W_, bn, bt, local);
            }
            p += relax * (local - p);
        });
    }

private:
    SolverOptions options_;
    double lambda_max_ = 1.0;
};

class GaussSeidelSolver final : public WCachingSolver {
public:
    explicit GaussSeidelSolver(const SolverOptions& o) : options_(o) {}
    SolverKind kind() const override { return SolverKind::accelerated; }
    SolveResult solve(const ContactProblem& problem, Eigen::VectorXd& p) override {
        refresh(problem);
        if (p.size() != problem.size()) p = Eigen::VectorXd::Zero(problem.size());
        return gauss_seidel_sweeps(problem, p, options_.tolerance_m, options_.max_iterations);
    }

private:
    SolverOptions options_;
};

}  // namespace

std::unique_ptr<ContactSolver> make_projected_solver(const SolverOptions& o) {
    if (o.kind == SolverKind::accelerated) return std::make_unique<GaussSeidelSolver>(o);
    if (o.kind == SolverKind::block_jacobi) return std::make_unique<BlockJacobiSolver>(o);
    return std::make_unique<PaperSolver>(o);
}

void pair_free_term(const ContactProblem& problem, int k, const Eigen::VectorXd& p, const Eigen::VectorXd& s,
                    double& bn, double& bt) {
    const auto& c = problem.pairs[k];
    const auto& W = problem.W;
    const double pn = c.row_n >= 0 ? p[c.row_n] : 0.0, pt = c.row_t >= 0 ? p[c.row_t] : 0.0;
    bn = c.row_n >= 0 ? s[c.row_n] - W(c.row_n, c.row_n) * pn - (c.row_t >= 0 ? W(c.row_n, c.row_t) * pt : 0.0) : 0.0;
    bt = c.row_t >= 0 ? s[c.row_t] - W(c.row_t, c.row_t) * pt - (c.row_n >= 0 ? W(c.row_t, c.row_n) * pn : 0.0) : 0.0;
}

void solve_pair_locally(const ContactProblem& problem, int k, const Eigen::MatrixXd& W, double bn, double bt,
                        Eigen::VectorXd& p) {
    const auto& c = problem.pairs[k];
    const int rn = c.row_n, rt = c.row_t;
    const double mu = c.friction_coefficient;
    const bool prev = problem.tau_rule == TauRule::previous_step;
    const double tau_prev = prev ? problem.tau_previous_n[k] : 0.0;
    const double Ann = rn >= 0 ? W(rn, rn) : 1.0, Att = rt >= 0 ? W(rt, rt) : 1.0;
    const double Ant = (rn >= 0 && rt >= 0) ? W(rn, rt) : 0.0;

    if (rt < 0) {  // normal only
        const double pn = -bn / Ann;
        p[rn] = c.kind == PairKind::coulomb ? std::min(0.0, pn) : pn;
        return;
    }
    if (c.kind == PairKind::bonded) {
        if (rn < 0) {
            p[rt] = -bt / Att;
        } else {
            const double det = Ann * Att - Ant * Ant;
            p[rn] = (-Att * bn + Ant * bt) / det;
            p[rt] = (Ant * bn - Ann * bt) / det;
        }
        return;
    }
    if (rn < 0) {  // tangential only: the limit does not depend on this pair's force
        const double limit = mu * (c.kind == PairKind::clamp ? (prev ? tau_prev : c.preload_n) : 0.0);
        p[rt] = std::clamp(-bt / Att, -limit, limit);
        return;
    }
    const double c0 = c.kind == PairKind::clamp ? c.preload_n : 0.0;
    const bool unilateral = c.kind == PairKind::coulomb;
    auto tau_of = [&](double pn) {
        if (unilateral) return pn < 0.0 ? (prev ? tau_prev : -pn) : 0.0;
        return prev ? tau_prev : std::max(0.0, c0 - pn);
    };
    const double tiny = 1e-14;
    // open (unilateral only): p = 0 is consistent when the free gap is open.
    if (unilateral && bn <= 0.0) {
        p[rn] = 0.0;
        p[rt] = 0.0;
        return;
    }
    // stick
    {
        const double det = Ann * Att - Ant * Ant;
        const double pn = (-Att * bn + Ant * bt) / det;
        const double pt = (Ant * bn - Ann * bt) / det;
        const double limit = mu * tau_of(pn);
        if ((!unilateral || pn <= 0.0) && std::abs(pt) <= limit * (1.0 + tiny)) {
            p[rn] = pn;
            p[rt] = pt;
            return;
        }
    }
    // slip in the direction sigma of the force: p_t = sigma mu tau
    for (double sigma : {1.0, -1.0}) {
        double pn, pt;
        if (prev) {
            pt = sigma * mu * tau_prev;
            pn = -(bn + Ant * pt) / Ann;
        } else {  // p_t = sigma mu (c0 - p_n)
            pn = (-bn - sigma * mu * Ant * c0) / (Ann - sigma * mu * Ant);
            pt = sigma * mu * (c0 - pn);
        }
        const double st = Ant * pn + Att * pt + bt;
        const bool normal_ok = unilateral ? pn <= 0.0 : (prev || c0 - pn >= 0.0);
        if (normal_ok && sigma * st <= tiny * std::abs(bt)) {
            p[rn] = pn;
            p[rt] = pt;
            return;
        }
    }
    // clamp pulled apart beyond its preload: the interface carries no friction
    const double pn = -bn / Ann;
    p[rn] = unilateral ? std::min(0.0, pn) : pn;
    p[rt] = 0.0;
}

SolveResult gauss_seidel_sweeps(const ContactProblem& problem, Eigen::VectorXd& p, double tolerance_m,
                                int max_sweeps) {
    // eq. 9's v is blind to forces outside the admissible set (p_n > 0 with an open
    // gap, |p_t| above the limit): a start that may hold such forces gets one sweep first.
    bool admissible = true;
    for (std::size_t k = 0; k < problem.pairs.size(); ++k) {
        const auto& c = problem.pairs[k];
        if (c.row_n >= 0 && c.kind == PairKind::coulomb && p[c.row_n] > 0.0) admissible = false;
        if (c.row_t >= 0 && c.kind != PairKind::bonded &&
            std::abs(p[c.row_t]) > c.friction_coefficient * friction_normal_force(problem, static_cast<int>(k), p) * (1.0 + 1e-12))
            admissible = false;
    }
    SolverOptions o;
    o.tolerance_m = tolerance_m;
    o.max_iterations = max_sweeps;
    const auto& W = problem.W;
    Eigen::VectorXd ls;
    return iterate(problem, p, o, "Gauss-Seidel sweeps", !admissible,
                   [&](Eigen::VectorXd& p, const Eigen::VectorXd& s, const Eigen::VectorXd&) {
        ls = s;  // kept current pair by pair; iterate() recomputes s after the sweep (no drift)
        for (int k = 0; k < static_cast<int>(problem.pairs.size()); ++k) {
            const auto& c = problem.pairs[k];
            const double pn0 = c.row_n >= 0 ? p[c.row_n] : 0.0, pt0 = c.row_t >= 0 ? p[c.row_t] : 0.0;
            double bn, bt;
            pair_free_term(problem, k, p, ls, bn, bt);
            solve_pair_locally(problem, k, W, bn, bt, p);
            if (c.row_n >= 0 && p[c.row_n] != pn0) ls += W.col(c.row_n) * (p[c.row_n] - pn0);
            if (c.row_t >= 0 && p[c.row_t] != pt0) ls += W.col(c.row_t) * (p[c.row_t] - pt0);
        }
    });
}

}  // namespace stackbeam::detail
