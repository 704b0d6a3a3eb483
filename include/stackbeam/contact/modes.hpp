#pragma once
/// @file modes.hpp
/// The modes of a contact problem's pair components and the linear problem of a set of them:
/// the mode logic the active-set solvers (dense `exact`, the sparse path) and the event driver
/// of mode cvode share, so that all take the same decisions from the same numbers.
///
/// Every pair component is in one mode: a normal component is closed (s_n = 0) or
/// open (p_n = 0); a tangential one sticks (s_t = 0), slips with its force at the
/// limit (p_t = sigma mu tau, sigma = +-1, tau affine in the pair's own p_n) or is
/// free (p_t = 0: open pair, mu = 0, clamp pulled apart past its preload). For a set
/// of modes the contact problem is linear. The mode logic needs s = W p + q and the
/// diagonal of W, never W itself (ContactProblem gives the pairs, the tau rule and the size).
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "stackbeam/contact/contact.hpp"

namespace stackbeam::modes {

/// Normal modes (ModeSet::nmode; NONE: the pair has no normal row).
enum : signed char { NONE = 0, CLOSED = 1, OPEN = 2 };
/// Tangential modes (ModeSet::tmode; NONE: no tangential row).
enum : signed char { STICK = 1, SLIP_POS = 2, SLIP_NEG = 3, FREE = 4 };

/// The linear problem of a set of modes: the rows held by "s = 0" (S, in pair order),
/// the forces the modes fix (e, zero on S), and the slip rows whose force is affine in
/// their pair's normal unknown: p_t = e_t + coef * p_n.
struct ModeLinearization {
    std::vector<int> S;
    Eigen::VectorXd e;
    std::vector<std::pair<int, int>> coupled;  // (tangential row, normal row)
    std::vector<double> coef;                  // dp_t / dp_n
};

class ModeSet {
public:
    std::vector<signed char> nmode, tmode;

    static bool unilateral(const ContactPair& c) { return c.kind == PairKind::coulomb; }

    std::vector<signed char> key() const {
        std::vector<signed char> k(nmode);
        k.insert(k.end(), tmode.begin(), tmode.end());
        return k;
    }

    void make_consistent(const ContactProblem& pr, int k) {
        const auto& c = pr.pairs[k];
        if (c.row_t < 0 || c.kind == PairKind::bonded) return;
        const bool closed = c.row_n >= 0 ? nmode[k] == CLOSED : !unilateral(c);
        if (c.friction_coefficient == 0.0) {
            tmode[k] = FREE;
        } else if (unilateral(c)) {
            if (!closed) tmode[k] = FREE;
            else if (tmode[k] == FREE) tmode[k] = STICK;
        }
    }

    /// Modes read from forces p and relative positions s0 = W p + q.
    void init(const ContactProblem& pr, const Eigen::VectorXd& p, const Eigen::VectorXd& s0) {
        const int np = static_cast<int>(pr.pairs.size());
        nmode.assign(np, NONE);
        tmode.assign(np, NONE);
        for (int k = 0; k < np; ++k) {
            const auto& c = pr.pairs[k];
            if (c.row_n >= 0)
                nmode[k] = (!unilateral(c) || p[c.row_n] < 0.0 || s0[c.row_n] >= 0.0) ? CLOSED : OPEN;
            if (c.row_t >= 0) {
                if (c.kind == PairKind::bonded) {
                    tmode[k] = STICK;
                } else {
                    const double limit = c.friction_coefficient * friction_normal_force(pr, k, p);
                    const double pt = p[c.row_t];
                    tmode[k] = (limit > 0.0 && std::abs(pt) >= limit * (1.0 - 1e-9)) ? (pt > 0 ? SLIP_POS : SLIP_NEG) : STICK;
                }
                make_consistent(pr, k);
            }
        }
    }

    /// The linear problem of the current modes.
    void linearize(const ContactProblem& pr, ModeLinearization& lin) const { linearize(pr, pr.size(), lin); }
    /// The same for the laws of a problem of n rows.
    void linearize(const ContactLaws& pr, int n, ModeLinearization& lin) const {
        const int np = static_cast<int>(pr.pairs.size());
        const bool prev = pr.tau_rule == TauRule::previous_step;
        lin.e.setZero(n);
        lin.coupled.clear();
        lin.coef.clear();
        lin.S.clear();
        for (int k = 0; k < np; ++k) {
            const auto& c = pr.pairs[k];
            if (c.row_n >= 0 && nmode[k] == CLOSED) lin.S.push_back(c.row_n);
            if (c.row_t >= 0 && tmode[k] == STICK) lin.S.push_back(c.row_t);
        }
        for (int k = 0; k < np; ++k) {
            const auto& c = pr.pairs[k];
            if (c.row_t < 0 || (tmode[k] != SLIP_POS && tmode[k] != SLIP_NEG)) continue;
            const double sigma = tmode[k] == SLIP_POS ? 1.0 : -1.0;
            const double mu = c.friction_coefficient;
            if (prev) {
                lin.e[c.row_t] = sigma * mu * pr.tau_previous_n[k];
            } else if (c.kind == PairKind::clamp) {  // p_t = sigma mu (F_c - p_n)
                lin.e[c.row_t] = sigma * mu * c.preload_n;
                if (c.row_n >= 0) {
                    lin.coupled.emplace_back(c.row_t, c.row_n);
                    lin.coef.push_back(-sigma * mu);
                }
            } else {  // coulomb: p_t = sigma mu (-p_n)
                lin.coupled.emplace_back(c.row_t, c.row_n);
                lin.coef.push_back(-sigma * mu);
            }
        }
    }

    /// Slip rows: p_t = sigma mu tau(p_n), written with the same formula as the friction limit.
    void put_slip_forces(const ContactLaws& pr, Eigen::VectorXd& p) const {
        for (int k = 0; k < static_cast<int>(pr.pairs.size()); ++k) {
            const auto& c = pr.pairs[k];
            if (c.row_t >= 0 && (tmode[k] == SLIP_POS || tmode[k] == SLIP_NEG))
                p[c.row_t] = (tmode[k] == SLIP_POS ? 1.0 : -1.0) * c.friction_coefficient * friction_normal_force(pr, k, p);
        }
    }

    /// Finds the modes whose inequality fails at (p, s) (kept for apply_switches); returns
    /// their number. Every violation is measured in metres: a gap error directly, a force
    /// error by the motion it would cause, force x W_kk (`diag` is the diagonal of W). A
    /// mode is wrong when its violation exceeds `threshold_m`: near-degenerate components
    /// (p and s both ~0, common where identical leaves just touch) then cannot ping-pong.
    int count_violations(const ContactProblem& pr, const Eigen::VectorXd& p, const Eigen::VectorXd& s,
                         const Eigen::VectorXd& diag, double threshold_m) {
        const double ts = threshold_m;
        const int np = static_cast<int>(pr.pairs.size());
        sw_.clear();
        auto add = [&](int k, bool normal, signed char to, double size_m) {
            if (size_m > ts) sw_.push_back({k, normal, to, size_m});
        };
        for (int k = 0; k < np; ++k) {
            const auto& c = pr.pairs[k];
            const double Wn = c.row_n >= 0 ? diag[c.row_n] : 0.0;
            const double Wt = c.row_t >= 0 ? diag[c.row_t] : 0.0;
            if (c.row_n >= 0 && unilateral(c)) {
                const double pn = p[c.row_n], sn = s[c.row_n];
                if (nmode[k] == CLOSED) add(k, true, OPEN, pn * Wn);
                if (nmode[k] == OPEN) add(k, true, CLOSED, sn);
            }
            if (c.row_t < 0 || c.kind == PairKind::bonded || c.friction_coefficient == 0.0) continue;
            if (unilateral(c) && tmode[k] == FREE) continue;  // follows the normal mode
            const double mu = c.friction_coefficient;
            const double pt = p[c.row_t], st = s[c.row_t];
            const double pn = c.row_n >= 0 ? p[c.row_n] : 0.0;
            const double release_m = (c.kind == PairKind::clamp && pr.tau_rule == TauRule::current)
                                         ? mu * (pn - c.preload_n) * Wt  // friction lost past the preload
                                         : -1.0;
            const double limit = mu * friction_normal_force(pr, k, p);
            switch (tmode[k]) {
                case STICK:
                    if (release_m > ts) add(k, false, FREE, release_m);
                    else add(k, false, pt > 0 ? SLIP_POS : SLIP_NEG, (std::abs(pt) - limit) * Wt);
                    break;
                case SLIP_POS:
                case SLIP_NEG: {
                    const double sigma = tmode[k] == SLIP_POS ? 1.0 : -1.0;
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
        return static_cast<int>(sw_.size());
    }

    /// Switches the violated modes found by count_violations: all, or only the first.
    void apply_switches(const ContactProblem& pr, bool single) {
        // Contact status first, friction second: while a normal mode is wrong, the
        // tangential verdicts rest on wrong normal forces.
        if (std::any_of(sw_.begin(), sw_.end(), [](const Switch& x) { return x.normal; }))
            sw_.erase(std::remove_if(sw_.begin(), sw_.end(), [](const Switch& x) { return !x.normal; }), sw_.end());
        if (single) sw_.resize(1);
        for (const auto& x : sw_) {
            if (x.normal) nmode[x.k] = x.to;
            else tmode[x.k] = x.to;
            if (x.normal && x.to == CLOSED && pr.pairs[x.k].row_t >= 0) tmode[x.k] = STICK;
            make_consistent(pr, x.k);
        }
    }

private:
    struct Switch { int k; bool normal; signed char to; double size; };
    std::vector<Switch> sw_;
};

}  // namespace stackbeam::modes
