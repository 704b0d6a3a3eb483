// The contact problem: validation, the paper's error vector (eq. 9), pair
// states, the friction limit, and the solver factory.
#include "stackbeam/contact/contact.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "contact/solvers.hpp"
#include "stackbeam/errors.hpp"

namespace stackbeam {

STACKBEAM_ENUM_WORDS(PairKind, {PairKind::bonded, "bonded"}, {PairKind::coulomb, "coulomb"}, {PairKind::clamp, "clamp"})
STACKBEAM_ENUM_WORDS(PairState, {PairState::stick, "stick"}, {PairState::slip, "slip"}, {PairState::open, "open"})

const char* to_string(PairKind kind) { return word_of(kind); }
const char* to_string(PairState state) { return word_of(state); }

STACKBEAM_ENUM_WORDS(SolverKind, {SolverKind::exact, "exact"}, {SolverKind::accelerated, "accelerated"},
    {SolverKind::block_jacobi, "block-jacobi"}, {SolverKind::paper, "paper"})

const char* to_string(SolverKind kind) { return word_of(kind); }

SolverKind parse_solver_kind(const std::string& text, const std::string& field) {
    return parse_word<SolverKind>(text, field, "solver");
}

void ContactProblem::validate() const {
    const int n = size();
    if (W.rows() != n || W.cols() != n)
        throw InputError("problem.W", "is " + std::to_string(W.rows()) + "x" + std::to_string(W.cols()) +
                                          ": must be square of the size of q (" + std::to_string(n) + ")");
    if (!W.allFinite()) throw InputError("problem.W", "has a non-finite entry");
    if (!q.allFinite()) throw InputError("problem.q", "has a non-finite entry");
    detail::validate_laws(pairs, n, tau_rule, tau_previous_n);
}

void detail::validate_laws(const std::vector<ContactPair>& pairs, int n, TauRule tau_rule,
                           const Eigen::VectorXd& tau_previous_n) {
    std::vector<int> used(n, 0);
    for (std::size_t k = 0; k < pairs.size(); ++k) {
        const auto& c = pairs[k];
        const std::string f = "problem.pairs[" + std::to_string(k) + "]";
        for (int r : {c.row_n, c.row_t}) {
            if (r < -1 || r >= n) throw InputError(f + ".row", "value " + std::to_string(r) + " is outside 0.." + std::to_string(n - 1));
            if (r >= 0 && used[r]++) throw InputError(f + ".row", "row " + std::to_string(r) + " belongs to two components");
        }
        if (!std::isfinite(c.friction_coefficient) || c.friction_coefficient < 0.0)
            throw InputError(f + ".friction_coefficient", "value " + format_value(c.friction_coefficient) + " must be finite and >= 0");
        if (!std::isfinite(c.preload_n) || c.preload_n < 0.0)
            throw InputError(f + ".preload_n", "value " + format_value(c.preload_n) + " must be finite and >= 0");
    }
    for (int r = 0; r < n; ++r)
        if (!used[r]) throw InputError("problem.pairs", "row " + std::to_string(r) + " belongs to no pair");
    if (tau_rule == TauRule::previous_step && tau_previous_n.size() != static_cast<Eigen::Index>(pairs.size()))
        throw InputError("problem.tau_previous_n", "needs one entry per pair with TauRule::previous_step");
}

double friction_normal_force(const ContactLaws& problem, int k, const Eigen::VectorXd& p) {
    const auto& c = problem.pairs[k];
    const double pn = c.row_n >= 0 ? p[c.row_n] : 0.0;
    if (c.kind == PairKind::clamp) {
        if (problem.tau_rule == TauRule::previous_step) return problem.tau_previous_n[k];
        return std::max(0.0, c.preload_n - pn);
    }
    if (c.kind == PairKind::coulomb) {
        if (pn >= 0.0) return 0.0;  // open: no normal force, no friction
        return problem.tau_rule == TauRule::previous_step ? problem.tau_previous_n[k] : -pn;
    }
    return std::numeric_limits<double>::infinity();  // bonded: no limit
}

Eigen::VectorXd error_vector(const ContactLaws& problem, const Eigen::VectorXd& p, const Eigen::VectorXd& s) {
    Eigen::VectorXd v = Eigen::VectorXd::Zero(s.size());
    for (std::size_t k = 0; k < problem.pairs.size(); ++k) {
        const auto& c = problem.pairs[k];
        if (c.row_n >= 0) {
            const double pn = p[c.row_n], sn = s[c.row_n];
            // eq. 9, normal: v_n = s_n if p_n < 0 or s_n > 0, else 0; bilateral pairs: v_n = s_n.
            if (c.kind != PairKind::coulomb || pn < 0.0 || sn > 0.0) v[c.row_n] = sn;
        }
        if (c.row_t >= 0) {
            const double pt = p[c.row_t], st = s[c.row_t];
            if (c.kind == PairKind::bonded) {
                v[c.row_t] = st;
                continue;
            }
            // eq. 9, tangential: v_t = s_t while sticking or while slipping with the force.
            const double limit = c.friction_coefficient * friction_normal_force(problem, static_cast<int>(k), p);
            if (limit <= 0.0) continue;
            // "below the limit" with a relative margin of 1e-12: a force put at the limit by
            // another formula (e.g. sigma mu F_c - sigma mu p_n) may differ from mu tau in the last bit.
            if (std::abs(pt) < limit * (1.0 - 1e-12) || pt * st > 0.0) v[c.row_t] = st;
        }
    }
    return v;
}

Eigen::VectorXd natural_map(const ContactProblem& problem, const Eigen::VectorXd& p, const Eigen::VectorXd& s) {
    return detail::natural_map_diag(problem, problem.W.diagonal(), p, s);
}

Eigen::VectorXd detail::natural_map_diag(const ContactProblem& problem, const Eigen::VectorXd& diag,
                                         const Eigen::VectorXd& p, const Eigen::VectorXd& s) {
    Eigen::VectorXd r = s;  // bilateral and bonded components: s itself
    for (std::size_t k = 0; k < problem.pairs.size(); ++k) {
        const auto& c = problem.pairs[k];
        if (c.row_n >= 0 && c.kind == PairKind::coulomb) {
            const double w = diag[c.row_n], pn = p[c.row_n];
            r[c.row_n] = w * (pn - std::min(0.0, pn - s[c.row_n] / w));
        }
        if (c.row_t >= 0 && c.kind != PairKind::bonded) {
            const double w = diag[c.row_t], pt = p[c.row_t];
            const double limit = c.friction_coefficient * friction_normal_force(problem, static_cast<int>(k), p);
            r[c.row_t] = w * (pt - std::clamp(pt - s[c.row_t] / w, -limit, limit));
        }
    }
    return r;
}

void detail::residual_norms(const ContactProblem& problem, const Eigen::VectorXd& diag, const Eigen::VectorXd& p,
                            const Eigen::VectorXd& s, double& error_norm_m, double& natural_norm_m) {
    // the same formulas as error_vector and natural_map_diag, component by component
    double v2 = 0.0, r2 = 0.0;
    for (std::size_t k = 0; k < problem.pairs.size(); ++k) {
        const auto& c = problem.pairs[k];
        if (c.row_n >= 0) {
            const double pn = p[c.row_n], sn = s[c.row_n];
            if (c.kind != PairKind::coulomb || pn < 0.0 || sn > 0.0) v2 += sn * sn;
            double r = sn;
            if (c.kind == PairKind::coulomb) {
                const double w = diag[c.row_n];
                r = w * (pn - std::min(0.0, pn - sn / w));
            }
            r2 += r * r;
        }
        if (c.row_t >= 0) {
            const double pt = p[c.row_t], st = s[c.row_t];
            if (c.kind == PairKind::bonded) {
                v2 += st * st;
                r2 += st * st;
                continue;
            }
            const double limit = c.friction_coefficient * friction_normal_force(problem, static_cast<int>(k), p);
            const double w = diag[c.row_t];
            const double r = w * (pt - std::clamp(pt - st / w, -limit, limit));
            r2 += r * r;
            if (limit <= 0.0) continue;
            if (std::abs(pt) < limit * (1.0 - 1e-12) || pt * st > 0.0) v2 += st * st;
        }
    }
    error_norm_m = std::sqrt(v2);
    natural_norm_m = std::sqrt(r2);
}

PairState pair_state(const ContactLaws& problem, int k, const Eigen::VectorXd& p) {
    const auto& c = problem.pairs[k];
    if (c.kind == PairKind::bonded) return PairState::stick;
    if (c.kind == PairKind::coulomb && (c.row_n < 0 || p[c.row_n] >= 0.0)) return PairState::open;
    if (c.row_t < 0) return PairState::stick;
    const double limit = c.friction_coefficient * friction_normal_force(problem, k, p);
    if (limit <= 0.0) return PairState::slip;
    return std::abs(p[c.row_t]) >= limit * (1.0 - 1e-9) ? PairState::slip : PairState::stick;
}

double largest_eigenvalue(const Eigen::MatrixXd& W) {
    if (W.rows() == 0) return 0.0;
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(W, Eigen::EigenvaluesOnly);
    return es.eigenvalues().maxCoeff();
}

namespace {
/// Adds the solver-independent natural-map residual to every solver's result.
class ResidualReporting final : public ContactSolver {
public:
    explicit ResidualReporting(std::unique_ptr<ContactSolver> inner) : inner_(std::move(inner)) {}
    SolverKind kind() const override { return inner_->kind(); }
    SolveResult solve(const ContactProblem& problem, Eigen::VectorXd& p) override {
        SolveResult r = inner_->solve(problem, p);
        r.natural_residual_m = natural_map(problem, p, problem.W * p + problem.q).norm();
        return r;
    }

private:
    std::unique_ptr<ContactSolver> inner_;
};
}  // namespace

void SolverOptions::validate() const {
    const SolverOptions& o = *this;
    if (!std::isfinite(o.tolerance_m) || o.tolerance_m <= 0.0)
        throw InputError("solver.tolerance_m", "value " + format_value(o.tolerance_m) + " must be finite and > 0 [m]");
    if (o.max_iterations < 1)
        throw InputError("solver.max_iterations", "value " + std::to_string(o.max_iterations) + " must be >= 1");
    if (!std::isfinite(o.alpha) || o.alpha < 0.0)
        throw InputError("solver.alpha", "value " + format_value(o.alpha) + " must be finite and >= 0 (0: automatic) [N/m]");
    if (!std::isfinite(o.alpha_fraction) || o.alpha_fraction <= 0.0)
        throw InputError("solver.alpha_fraction", "value " + format_value(o.alpha_fraction) + " must be finite and > 0");
    if (o.kind != SolverKind::exact) return;  // the exact solver's own fields
    if (o.tresca_anderson_depth < 0 || o.tresca_anderson_depth > 50)
        throw InputError("solver.tresca_anderson_depth",
                         "value " + std::to_string(o.tresca_anderson_depth) + " must be in 0..50 (0: no acceleration)");
    if (o.max_active_set_iterations < 1)
        throw InputError("solver.max_active_set_iterations",
                         "value " + std::to_string(o.max_active_set_iterations) + " must be >= 1");
}

std::unique_ptr<ContactSolver> make_solver(const SolverOptions& o) {
    o.validate();
    std::unique_ptr<ContactSolver> inner;
    switch (o.kind) {
        case SolverKind::paper:
        case SolverKind::block_jacobi:
        case SolverKind::accelerated: inner = detail::make_projected_solver(o); break;
        case SolverKind::exact: inner = detail::make_exact_solver(o); break;
    }
    if (inner) return std::make_unique<ResidualReporting>(std::move(inner));
    throw InputError("solver.kind", "unknown solver");
}

}  // namespace stackbeam
