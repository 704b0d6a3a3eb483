#pragma once
// Internal: the contact-mode bookkeeping shared by the two event-driven cvode steppers,
// the massless one (cvode_stepper.cpp: R's displacement w drives the contact problem)
// and the modal one with leaf inertia (cvode_modal.cpp: the retained modes q do). Both
// use the witnesses of cvode_stepper.hpp with these margins, read modes from a contact
// solution the same way, apply the transitions CVODE reports the same way and log them
// under the same labels.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "stackbeam/contact/modes.hpp"
#include "stackbeam/contact/contact.hpp"
#include "stackbeam/time/run_report.hpp"

namespace stackbeam::detail {

// The cvode layer (this header, the event driver and the event steppers) names the modes of
// contact/modes.hpp unqualified: their using-declarations, here once.
using modes::CLOSED;
using modes::FREE;
using modes::ModeLinearization;
using modes::ModeSet;
using modes::NONE;
using modes::OPEN;
using modes::SLIP_NEG;
using modes::SLIP_POS;
using modes::STICK;

/// Every witness is positive by a margin (relative to its scale) while its mode
/// holds, so that pairs that merely touch (p = s = 0 up to round-off) do not chatter.
/// Forces come from an LU of the mode's conditions (cond(C') ~ 1e5: round-off
/// ~1e-11 F_ref), so force witnesses get 1e-9: a friction limit or a contact
/// release is passed by 1e-9 F_ref before it counts. Gaps and slip rates are
/// products of C' with the forces (round-off ~1e-16 L_ref): 1e-12, so that a gap
/// closing into penetration by 1e-12 L_ref makes a force jump of only ~1e-12 L_ref / C'_nn.
constexpr double kForceMargin = 1e-9;
constexpr double kMotionMargin = 1e-12;
/// The look-ahead at an event moves the contact points by this fraction of L_ref:
/// large against round-off (1e-16 L_ref), small against every margin that matters.
constexpr double kLookahead = 1e-7;
/// At most this many events at one instant before the run is declared chattering.
constexpr int kMaxEventsAtOneTime = 200;
/// One instant, relative to max(1 s, t): events this close to the first of their cluster
/// count together towards kMaxEventsAtOneTime (10x the missed-event bisection's 1e-13 plus
/// margin; a genuine cascade of transitions at one contact front is ~1e-9 s or more apart).
constexpr double kEventInstant = 1e-10;
/// A pair of the massive stack (EventStart::pair_chatter_limit) that changes modes
/// kMaxPairSwitches times within kChatterPeriods of the stack's period
/// (2 pi / EventScales::omega_rad_per_s) chatters: a contact point vibrating on the undamped
/// elastic layer at ~1e5 Hz (the massive stack), opening and closing every microsecond, each
/// switch a restart that costs CVODE ~80 steps. The run stops with a named SolverError instead
/// of running to cvode.max_steps. A stack's own dynamics switches a pair a few times a period
/// (turning points, stick-slip): 100 switches within a hundredth of a period is 1e4 times that.
/// (A thousandth, decision 062, missed pairs switching every 3.5 us on 5.6 Hz stacks, soak seeds
/// 18, 28, 36, which then ran to the step limit: decision 065.)
constexpr int kMaxPairSwitches = 100;
constexpr double kChatterPeriods = 1e-2;
/// Passes of EventDriver::decide_modes that make the decided modes hold at the event's state.
constexpr int kSettlePasses = 4;
/// The event driver polls the caller's stop check (SimulationOptions::stop_requested) once
/// every this many CVODE steps (a step costs microseconds, so a stop is seen within a
/// millisecond or so while the check itself stays off the profile).
constexpr long kStopCheckSteps = 64;

/// The options of the event solver that decides the modes at an event: the exact solver
/// at `tolerance_m` (each stepper's own, from its scales), with the user's active-set
/// passes (at least 3) and Anderson depth of the Tresca fixed point.
inline SolverOptions event_solver_options(const SolverOptions& user, double tolerance_m) {
    SolverOptions ev;
    ev.kind = SolverKind::exact;
    ev.tolerance_m = tolerance_m;
    ev.max_active_set_iterations = std::max(3, user.max_active_set_iterations);
    ev.tresca_anderson_depth = user.tresca_anderson_depth;
    return ev;
}

/// The report of an event-driven cvode stepper: CVODE's steps, the contact iterations
/// and mode factorisations, its counters and the event log.
inline RunReport event_report(const CvodeStats& stats, const std::vector<ContactEvent>& events) {
    RunReport rep;
    rep.mode = Mode::cvode;
    rep.cvode = stats;
    rep.events = events;
    rep.steps = stats.steps;
    rep.contact_iterations = stats.contact_iterations;
    rep.factorizations = stats.mode_factorizations;
    return rep;
}

/// The map p = T p_S + e of a set of modes (ModeSet::linearize): the held rows S and the slip rows
/// p_t = e_t + coef p_n whose normal row is held, as (row, column, coefficient) links; row S[i] is
/// column i with coefficient 1. The steppers whose forces are affine in their state build their
/// mode's operators from it (cvode_stepper.cpp, cvode_modal.cpp).
struct ModeMap {
    struct Link { int row, col; double coef; };
    std::vector<Link> links;
    int columns = 0;  ///< |S|

    ModeMap(const ModeLinearization& lin, int rows) : columns(static_cast<int>(lin.S.size())) {
        std::vector<int> pos(static_cast<std::size_t>(rows), -1);
        for (int i = 0; i < columns; ++i) pos[lin.S[i]] = i;
        for (int i = 0; i < columns; ++i) links.push_back({lin.S[i], i, 1.0});
        for (std::size_t i = 0; i < lin.coupled.size(); ++i)
            if (pos[lin.coupled[i].second] >= 0) links.push_back({lin.coupled[i].first, pos[lin.coupled[i].second], lin.coef[i]});
    }
    /// W T (rows x |S|) for a compliance W (rows x rows).
    Eigen::MatrixXd compliance_times(const Eigen::MatrixXd& W) const {
        Eigen::MatrixXd WT = Eigen::MatrixXd::Zero(W.rows(), columns);
        for (const Link& l : links) WT.col(l.col) += l.coef * W.col(l.row);
        return WT;
    }
};

/// Label of a pair's modes (nm, tm) for the event log.
inline std::string mode_label(const ContactPair& cp, signed char nm, signed char tm) {
    if (cp.kind == PairKind::bonded) return "bonded";
    if (cp.kind == PairKind::coulomb && nm == OPEN) return "open";
    switch (tm) {
        case STICK: return "stick";
        case SLIP_POS: return "slip+";
        case SLIP_NEG: return "slip-";
        case FREE: return cp.kind == PairKind::clamp ? "released" : "closed";
        default: return cp.kind == PairKind::clamp ? "clamped" : "closed";
    }
}

/// Modes of the contact solution p of `laws` (tau rule current): a unilateral pair with
/// p_n >= -eps_f [N] is open; a friction force within 1e-9 of its limit slips.
inline void modes_from_solution(const ContactLaws& laws, const Eigen::VectorXd& p, double eps_f,
                                std::vector<signed char>& nm, std::vector<signed char>& tm) {
    const int np = static_cast<int>(laws.pairs.size());
    nm.assign(np, NONE);
    tm.assign(np, NONE);
    for (int kk = 0; kk < np; ++kk) {
        const auto& cp = laws.pairs[kk];
        bool open = false;
        if (cp.row_n >= 0) {
            open = cp.kind == PairKind::coulomb && p[cp.row_n] >= -eps_f;
            nm[kk] = open ? OPEN : CLOSED;
        } else if (cp.kind == PairKind::coulomb) {
            open = true;  // no normal component: it carries no friction either
        }
        if (cp.row_t < 0) continue;
        if (cp.kind == PairKind::bonded) {
            tm[kk] = STICK;
            continue;
        }
        const double limit = cp.friction_coefficient * friction_normal_force(laws, kk, p);
        const double pt = p[cp.row_t];
        if (open || cp.friction_coefficient == 0.0 || limit <= 0.0) tm[kk] = FREE;
        else if (std::abs(pt) >= limit * (1.0 - 1e-9)) tm[kk] = pt > 0.0 ? SLIP_POS : SLIP_NEG;
        else tm[kk] = STICK;
    }
}

/// The transition a witness announces, applied to the pair's modes (nm, tm): the normal
/// slot of a unilateral pair opens or closes it (closing: sticking if it has friction),
/// that of a clamp releases or engages it; the tangential slot makes a stuck pair slip
/// in the direction of its force p_t [N] and a slipping one stick.
inline void apply_transition(const ContactPair& cp, bool normal_slot, double p_t, signed char& nm, signed char& tm) {
    const bool friction = cp.row_t >= 0 && cp.friction_coefficient > 0.0;
    if (normal_slot && cp.kind == PairKind::coulomb) {
        if (nm == CLOSED) {
            nm = OPEN;
            if (cp.row_t >= 0) tm = FREE;
        } else {
            nm = CLOSED;
            if (cp.row_t >= 0) tm = friction ? STICK : FREE;
        }
    } else if (normal_slot) {
        tm = tm == FREE ? STICK : FREE;
    } else if (tm == STICK) {
        tm = p_t > 0.0 ? SLIP_POS : SLIP_NEG;
    } else if (tm == SLIP_POS || tm == SLIP_NEG) {
        tm = STICK;
    }
}

}  // namespace stackbeam::detail
