// The exact (active-set) contact solver.
//
// Every pair component is in one mode: a normal component is closed (s_n = 0)
// or open (p_n = 0); a tangential one sticks (s_t = 0), slips with its force at
// the limit (p_t = sigma mu tau, sigma = +-1, tau affine in the pair's own p_n)
// or is free (p_t = 0: open pair, mu = 0, clamp pulled apart past its preload).
// For a set of modes the problem is linear: the unknowns are the forces of the
// components held by "s = 0" (set S); the others follow from them. So
//     (W_SS + W_S,slip * dp_slip/dp_S) p_S = -(q_S + W_S,: e)
// is solved with a dense LU. W is constant between steps and the modes rarely
// change, so the LU is kept and reused while the modes stay: most steps cost
// one triangular solve and one product with W (stage 1).
//
// When the previous step's modes are wrong (a stick-slip or open-close
// transition), switching the violated modes (primal-dual active set) is not
// safe: W is not an M-matrix and the modes can cycle. Stage 2 therefore freezes
// the friction limits (Tresca), which makes the problem a box-constrained convex
// QP, solved by a monotone primal active-set method that cannot cycle; the
// limits are updated from its normal forces until they settle (fixed point on
// tau), and its final working set gives the modes from which stage 1 solves the
// coupled Coulomb problem exactly. If that polish fails, the settled fixed point
// (Coulomb to within 1e-3 of the tolerance) is returned, flagged fell_back;
// if even that fails, Gauss-Seidel sweeps finish the job and say so.
#include <Eigen/LU>
#include <cmath>
#include <algorithm>
#include <limits>

#include "box_qp.hpp"
#include "contact_solvers.hpp"
#include "stackbeam/errors.hpp"

namespace stackbeam::detail {
namespace {

enum : signed char { NONE = 0, CLOSED = 1, OPEN = 2 };
enum : signed char { STICK = 1, SLIP_POS = 2, SLIP_NEG = 3, FREE = 4 };

class ExactSolver final : public WCachingSolver {
public:
    explicit ExactSolver(const SolverOptions& o) : options_(o) {}
    SolverKind kind() const override { return SolverKind::exact; }

    SolveResult solve(const ContactProblem& problem, Eigen::VectorXd& p) override {
        const int n = problem.size();
        const int np = static_cast<int>(problem.pairs.size());
        if (refresh(problem) || static_cast<int>(nmode_.size()) != np) {
            lu_modes_.clear();
            if (p.size() != n) p = Eigen::VectorXd::Zero(n);
            init_modes(problem, p);
        }
        SolveResult r;
        // 1. From the previous step's modes (warm start): most steps end here in one pass.
        r.converged = active_set_passes(problem, p, options_.max_active_set_iterations, r);
        if (!r.converged) {
            // 2. A transition: solve the problem with the friction limits frozen (Tresca), a
            //    box-constrained QP, by a monotone active-set method that cannot cycle; update
            //    the limits from its normal forces until they settle (fixed point on tau); then
            //    take its modes and solve the coupled Coulomb problem exactly from them.
            const bool settled = tresca_fixed_point(problem, p, r);
            if (!settled) init_modes(problem, p);
            const Eigen::VectorXd p_tresca = p;
            r.converged = active_set_passes(problem, p, options_.max_active_set_iterations, r);
            if (!r.converged && settled) {  // the fixed point itself is within kAccept x tolerance
                p = p_tresca;
                r.converged = true;
                r.fell_back = true;
            }
        }
        Eigen::VectorXd s = problem.W * p + problem.q;
        r.residual_m = error_vector(problem, p, s).norm();
        if (!r.converged) {
            SolveResult gs = gauss_seidel_sweeps(problem, p, options_.tolerance_m, options_.max_iterations);
            r.fell_back = true;
            r.converged = gs.converged;
            r.iterations += gs.iterations;
            r.residual_m = gs.residual_m;
            if (!gs.converged)
                r.message = "exact solver: neither the active set nor the Tresca fixed point converged, and the "
                            "Gauss-Seidel fallback failed: " + gs.message;
            init_modes(problem, p);
            return r;
        }
        if (!(r.residual_m < options_.tolerance_m)) {
            r.converged = false;
            r.message = std::string("exact solver (") + (r.fell_back ? "Tresca fixed point" : "active set") +
                        ") ended with ||v|| = " + format_value(r.residual_m) + " m above the tolerance " +
                        format_value(options_.tolerance_m) + " m (natural-map residual " +
                        format_value(natural_map(problem, p, s).norm()) + " m)";
        }
        return r;
    }

private:
    SolverOptions options_;
    std::vector<signed char> nmode_, tmode_;
    std::vector<signed char> lu_modes_;
    Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
    std::vector<int> S_;          // rows with s = 0, in order
    std::vector<int> pos_;        // row -> index in S_ or -1
    Eigen::VectorXd rhs_, x_, e_;

    static constexpr int kTrescaIterations = 100;
    static constexpr int kBudget = 3;
    static constexpr double kAccept = 1e-3;

    /// Active-set passes from the current modes; true when no mode is violated.
    /// Block principal pivoting (Judice & Pires): switch every violated mode while the
    /// number of violations falls; when it has not fallen for kBudget passes, switch
    /// only the first violated one (Murty's least-index rule, finite for P-matrices).
    bool active_set_passes(const ContactProblem& problem, Eigen::VectorXd& p, int max_passes, SolveResult& r) {
        int best = std::numeric_limits<int>::max(), budget = kBudget;
        bool single = false;
        for (int pass = 1; pass <= max_passes; ++pass) {
            ++r.iterations;
            r.factorizations += solve_modes(problem, p);
            const int violations = count_violations(problem, p);
            if (violations == 0) return true;
            if (violations < best) {
                best = violations;
                budget = kBudget;
                single = false;
            } else if (budget > 0) {
                --budget;
            } else {
                single = true;
            }
            apply_switches(problem, single);
        }
        return false;
    }


    /// Fixed point on the friction limits: each pass a box-constrained QP (limits frozen).
    /// Returns true when the limits settle to kAccept x tolerance (measured in metres).
    bool tresca_fixed_point(const ContactProblem& pr, Eigen::VectorXd& p, SolveResult& r) {
        const int n = pr.size();
        const int np = static_cast<int>(pr.pairs.size());
        const double inf = std::numeric_limits<double>::infinity();
        Eigen::VectorXd lower = Eigen::VectorXd::Constant(n, -inf), upper = Eigen::VectorXd::Constant(n, inf);
        std::vector<signed char> at_bound(n, 0);
        for (int k = 0; k < np; ++k) {
            const auto& c = pr.pairs[k];
            if (c.row_n >= 0 && unilateral(c)) {
                upper[c.row_n] = 0.0;
                if (nmode_[k] == OPEN) at_bound[c.row_n] = +1;
            }
            if (c.row_t >= 0 && (tmode_[k] == SLIP_POS || tmode_[k] == SLIP_NEG))
                at_bound[c.row_t] = tmode_[k] == SLIP_POS ? +1 : -1;
        }
        Eigen::VectorXd tau(np);
        for (int k = 0; k < np; ++k) tau[k] = friction_normal_force(pr, k, p);
        const double accept = kAccept * options_.tolerance_m;
        for (int it = 0; it < kTrescaIterations; ++it) {
            for (int k = 0; k < np; ++k) {
                const auto& c = pr.pairs[k];
                if (c.row_t < 0 || c.kind == PairKind::bonded) continue;
                const double limit = c.friction_coefficient * tau[k];
                lower[c.row_t] = -limit;
                upper[c.row_t] = limit;
            }
            const BoxQpResult b = solve_box_qp(pr.W, pr.q, lower, upper, p, at_bound, accept, 50 * (n + 1));
            r.iterations += b.iterations;
            r.factorizations += b.factorizations;
            if (!b.converged) return false;
            double change_m = 0.0;
            for (int k = 0; k < np; ++k) {
                const auto& c = pr.pairs[k];
                if (c.row_t < 0 || c.kind == PairKind::bonded) continue;
                const double t = friction_normal_force(pr, k, p);
                change_m = std::max(change_m, c.friction_coefficient * std::abs(t - tau[k]) * pr.W(c.row_t, c.row_t));
                tau[k] = t;
            }
            if (change_m <= accept) {
                // modes from the working set; slip forces put at the limit of the final tau
                for (int k = 0; k < np; ++k) {
                    const auto& c = pr.pairs[k];
                    if (c.row_n >= 0 && unilateral(c)) nmode_[k] = at_bound[c.row_n] == +1 ? OPEN : CLOSED;
                    if (c.row_t < 0 || c.kind == PairKind::bonded) continue;
                    const double limit = c.friction_coefficient * friction_normal_force(pr, k, p);
                    if (limit <= 0.0) {
                        tmode_[k] = FREE;
                        p[c.row_t] = 0.0;
                    } else if (at_bound[c.row_t] != 0) {
                        // slip against the motion; a box that had zero width (tau was 0 in the
                        // last QP) held the force without a sign: take it from s_t.
                        const double st = (pr.W.row(c.row_t) * p)(0) + pr.q[c.row_t];
                        const signed char sigma = lower[c.row_t] < upper[c.row_t] ? at_bound[c.row_t] : (st > 0.0 ? -1 : +1);
                        tmode_[k] = sigma > 0 ? SLIP_POS : SLIP_NEG;
                        p[c.row_t] = sigma * limit;
                    } else {
                        tmode_[k] = STICK;
                    }
                    make_consistent(pr, k);
                }
                return true;
            }
        }
        return false;
    }

    std::vector<signed char> modes_key() const {
        std::vector<signed char> k(nmode_);
        k.insert(k.end(), tmode_.begin(), tmode_.end());
        return k;
    }

    static bool unilateral(const ContactPair& c) { return c.kind == PairKind::coulomb; }

    void make_consistent(const ContactProblem& pr, int k) {
        const auto& c = pr.pairs[k];
        if (c.row_t < 0 || c.kind == PairKind::bonded) return;
        const bool closed = c.row_n >= 0 ? nmode_[k] == CLOSED : !unilateral(c);
        if (c.friction_coefficient == 0.0) {
            tmode_[k] = FREE;
        } else if (unilateral(c)) {
            if (!closed) tmode_[k] = FREE;
            else if (tmode_[k] == FREE) tmode_[k] = STICK;
        }
    }

    void init_modes(const ContactProblem& pr, const Eigen::VectorXd& p) {
        const int np = static_cast<int>(pr.pairs.size());
        const Eigen::VectorXd s0 = pr.W * p + pr.q;
        nmode_.assign(np, NONE);
        tmode_.assign(np, NONE);
        for (int k = 0; k < np; ++k) {
            const auto& c = pr.pairs[k];
            if (c.row_n >= 0)
                nmode_[k] = (!unilateral(c) || p[c.row_n] < 0.0 || s0[c.row_n] >= 0.0) ? CLOSED : OPEN;
            if (c.row_t >= 0) {
                if (c.kind == PairKind::bonded) {
                    tmode_[k] = STICK;
                } else {
                    const double limit = c.friction_coefficient * friction_normal_force(pr, k, p);
                    const double pt = p[c.row_t];
                    tmode_[k] = (limit > 0.0 && std::abs(pt) >= limit * (1.0 - 1e-9)) ? (pt > 0 ? SLIP_POS : SLIP_NEG) : STICK;
                }
                make_consistent(pr, k);
            }
        }
    }

    /// Solves the linear problem of the current modes; returns 1 if it factorised.
    int solve_modes(const ContactProblem& pr, Eigen::VectorXd& p) {
        const int n = pr.size();
        const int np = static_cast<int>(pr.pairs.size());
        const bool prev = pr.tau_rule == TauRule::previous_step;
        // e: forces fixed by the modes; coupling of slip rows to their normal unknown.
        e_.setZero(n);
        std::vector<std::pair<int, int>> coupled;   // (tangential row, normal row)
        std::vector<double> coef;                   // dp_t/dp_n
        S_.clear();
        pos_.assign(n, -1);
        for (int k = 0; k < np; ++k) {
            const auto& c = pr.pairs[k];
            if (c.row_n >= 0 && nmode_[k] == CLOSED) S_.push_back(c.row_n);
            if (c.row_t >= 0 && tmode_[k] == STICK) S_.push_back(c.row_t);
        }
        for (std::size_t i = 0; i < S_.size(); ++i) pos_[S_[i]] = static_cast<int>(i);
        for (int k = 0; k < np; ++k) {
            const auto& c = pr.pairs[k];
            if (c.row_t < 0 || (tmode_[k] != SLIP_POS && tmode_[k] != SLIP_NEG)) continue;
            const double sigma = tmode_[k] == SLIP_POS ? 1.0 : -1.0;
            const double mu = c.friction_coefficient;
            if (prev) {
                e_[c.row_t] = sigma * mu * pr.tau_previous_n[k];
            } else if (c.kind == PairKind::clamp) {  // p_t = sigma mu (F_c - p_n)
                e_[c.row_t] = sigma * mu * c.preload_n;
                if (c.row_n >= 0) {
                    coupled.emplace_back(c.row_t, c.row_n);
                    coef.push_back(-sigma * mu);
                }
            } else {  // coulomb: p_t = sigma mu (-p_n)
                coupled.emplace_back(c.row_t, c.row_n);
                coef.push_back(-sigma * mu);
            }
        }
        const int m = static_cast<int>(S_.size());
        int factorised = 0;
        std::vector<signed char> key = modes_key();
        if (m > 0 && key != lu_modes_) {
            Eigen::MatrixXd M(m, m);
            for (int j = 0; j < m; ++j)
                for (int i = 0; i < m; ++i) M(i, j) = pr.W(S_[i], S_[j]);
            for (std::size_t a = 0; a < coupled.size(); ++a) {
                const int col = pos_[coupled[a].second];
                for (int i = 0; i < m; ++i) M(i, col) += coef[a] * pr.W(S_[i], coupled[a].first);
            }
            lu_.compute(M);
            lu_modes_ = std::move(key);
            factorised = 1;
        }
        // rhs = -(q_S + (W e)_S)
        rhs_.resize(m);
        for (int i = 0; i < m; ++i) rhs_[i] = -pr.q[S_[i]];
        for (int r = 0; r < n; ++r)
            if (e_[r] != 0.0)
                for (int i = 0; i < m; ++i) rhs_[i] -= pr.W(S_[i], r) * e_[r];
        if (m > 0) x_ = lu_.solve(rhs_);
        p = e_;
        for (int i = 0; i < m; ++i) p[S_[i]] = x_[i];
        // slip rows: p_t = sigma mu tau(p_n), written with the same formula as the friction limit
        for (int k = 0; k < np; ++k) {
            const auto& c = pr.pairs[k];
            if (c.row_t >= 0 && (tmode_[k] == SLIP_POS || tmode_[k] == SLIP_NEG))
                p[c.row_t] = (tmode_[k] == SLIP_POS ? 1.0 : -1.0) * c.friction_coefficient * friction_normal_force(pr, k, p);
        }
        return factorised;
    }

    struct Switch { int k; bool normal; signed char to; double size; };
    std::vector<Switch> sw_;

    /// Finds the modes whose inequality fails at p (kept in sw_); returns their number.
    int count_violations(const ContactProblem& pr, const Eigen::VectorXd& p) {
        // Every violation is measured in metres: a gap error directly, a force error by
        // the motion it would cause, force x W_kk. A mode is wrong when its violation
        // exceeds kAccept x tolerance (or round-off of the products): the answer is then
        // exact to far below what the caller asked, and near-degenerate components (p and
        // s both ~0, common where identical leaves just touch) cannot ping-pong forever.
        const Eigen::VectorXd s = pr.W * p + pr.q;
        const double pscale = p.lpNorm<Eigen::Infinity>();
        const double roundoff = 1e-13 * (pr.q.lpNorm<Eigen::Infinity>() + pr.W.lpNorm<Eigen::Infinity>() * pscale);
        const double ts = std::max(kAccept * options_.tolerance_m, roundoff);
        const int np = static_cast<int>(pr.pairs.size());
        auto& sw = sw_;
        sw.clear();
        auto add = [&](int k, bool normal, signed char to, double size_m) {
            if (size_m > ts) sw.push_back({k, normal, to, size_m});
        };
        for (int k = 0; k < np; ++k) {
            const auto& c = pr.pairs[k];
            const double Wn = c.row_n >= 0 ? pr.W(c.row_n, c.row_n) : 0.0;
            const double Wt = c.row_t >= 0 ? pr.W(c.row_t, c.row_t) : 0.0;
            if (c.row_n >= 0 && unilateral(c)) {
                const double pn = p[c.row_n], sn = s[c.row_n];
                if (nmode_[k] == CLOSED) add(k, true, OPEN, pn * Wn);
                if (nmode_[k] == OPEN) add(k, true, CLOSED, sn);
            }
            if (c.row_t < 0 || c.kind == PairKind::bonded || c.friction_coefficient == 0.0) continue;
            if (unilateral(c) && tmode_[k] == FREE) continue;  // follows the normal mode
            const double mu = c.friction_coefficient;
            const double pt = p[c.row_t], st = s[c.row_t];
            const double pn = c.row_n >= 0 ? p[c.row_n] : 0.0;
            const double release_m = (c.kind == PairKind::clamp && pr.tau_rule == TauRule::current)
                                         ? mu * (pn - c.preload_n) * Wt  // friction lost past the preload
                                         : -1.0;
            const double limit = mu * friction_normal_force(pr, k, p);
            switch (tmode_[k]) {
                case STICK:
                    if (release_m > ts) add(k, false, FREE, release_m);
                    else add(k, false, pt > 0 ? SLIP_POS : SLIP_NEG, (std::abs(pt) - limit) * Wt);
                    break;
                case SLIP_POS:
                case SLIP_NEG: {
                    const double sigma = tmode_[k] == SLIP_POS ? 1.0 : -1.0;
                    if (release_m > ts) add(k, false, FREE, release_m);
                    else add(k, false, STICK, sigma * st);
                    break;
                }
                case FREE:  // a clamp that carried no friction
                    if (c.kind == PairKind::clamp) add(k, false, STICK, -release_m);
                    break;
                default: break;
            }
        }
        return static_cast<int>(sw.size());
    }

    /// Switches the violated modes found by count_violations: all, or only the first.
    void apply_switches(const ContactProblem& pr, bool single) {
        auto& sw = sw_;
        // Contact status first, friction second: while a normal mode is wrong, the
        // tangential verdicts rest on wrong normal forces.
        if (std::any_of(sw.begin(), sw.end(), [](const Switch& x) { return x.normal; }))
            sw.erase(std::remove_if(sw.begin(), sw.end(), [](const Switch& x) { return !x.normal; }), sw.end());
        if (single) sw.resize(1);
        for (const auto& x : sw) {
            if (x.normal) nmode_[x.k] = x.to;
            else tmode_[x.k] = x.to;
            if (x.normal && x.to == CLOSED && pr.pairs[x.k].row_t >= 0) tmode_[x.k] = STICK;
            make_consistent(pr, x.k);
        }
    }
};

}  // namespace

std::unique_ptr<ContactSolver> make_exact_solver(const SolverOptions& o) {
    if (o.max_active_set_iterations < 1)
        throw InputError("solver.max_active_set_iterations",
                         "value " + std::to_string(o.max_active_set_iterations) + " must be >= 1");
    return std::make_unique<ExactSolver>(o);
}

}  // namespace stackbeam::detail
