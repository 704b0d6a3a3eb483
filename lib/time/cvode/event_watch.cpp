// The event driver's watch on its own events (event_driver.hpp): the events at one instant, a
// pair's chatter and what a step limit's steps went into, each a SolverError's message naming the
// pairs, their interfaces and x, and what to do (the chatter of decisions 062, 065 and 071).
#include "time/cvode/event_driver.hpp"

#include <algorithm>
#include <deque>
#include <string>
#include <vector>

#include "stackbeam/errors.hpp"

namespace stackbeam::detail {

void EventDriver::note_event_time(double te) {
    // Events closer than kEventInstant (relative) to the first of their cluster count as one
    // instant: a run that restarts into modes that do not hold creeps by the bisection's time
    // tolerance (~1e-12 s) per restart, which an exact comparison of times would never catch.
    if (te - last_event_t_ <= kEventInstant * std::max(1.0, std::abs(te))) {
        if (++events_at_this_time_ > kMaxEventsAtOneTime) {
            std::string last;
            if (!events_.empty()) {
                const ContactEvent& e = events_.back();
                last = "; the last transition: pair " + std::to_string(e.pair) + " (interface " +
                       std::to_string(e.interface_index) + ", x = " + format_value(e.x_m) + " m) " + e.from + " -> " +
                       e.to + " at t = " + format_value(e.t_s) + " s";
            }
            throw SolverError(who_ + ": more than " + std::to_string(kMaxEventsAtOneTime) + " events within " +
                                  format_value(kEventInstant * std::max(1.0, std::abs(te))) + " s of t = " +
                                  format_value(last_event_t_) +
                                  " s: the contact modes chatter (no consistent mode set found)" + last,
                              stats_.steps, te, 0.0);
        }
    } else {
        last_event_t_ = te;
        events_at_this_time_ = 0;
    }
    ++stats_.events;
}

void EventDriver::note_pair_switch(int kk, double te) {
    if (switch_times_.empty()) switch_times_.resize(static_cast<std::size_t>(np_));
    std::deque<double>& times = switch_times_[static_cast<std::size_t>(kk)];
    times.push_back(te);
    if (static_cast<int>(times.size()) > kMaxPairSwitches) times.pop_front();
    constexpr double kTwoPi = 6.283185307179586;
    const double window = kChatterPeriods * kTwoPi / scales_.omega_rad_per_s;
    if (static_cast<int>(times.size()) < kMaxPairSwitches || te - times.front() > window) return;
    const ContactEvent& e = events_.back();
    throw SolverError(who_ + ": pair " + std::to_string(kk) + " (interface " + std::to_string(e.interface_index) +
                          ", x = " + format_value(e.x_m) + " m) changed modes " + std::to_string(kMaxPairSwitches) +
                          " times within " + format_value(te - times.front()) + " s (a hundredth of the stack's period is " +
                          format_value(window) + " s) up to t = " + format_value(te) + " s, the last " + e.from + " -> " +
                          e.to + ": the contact chatters (a contact point vibrating on the elastic layer, each switch a "
                          "restart); damping.layer_normal_time_s > 0 damps that vibration (a dashpot on the layer, e.g. "
                          "1e-6 s), or leaf_inertia = modal (a massless contact layer) or mode newmark follow such a stack",
                      stats_.steps, te, 0.0);
}

std::string EventDriver::step_limit_diagnostics() const {
    // What the steps went into: their mean size against the stack's period, the last one, the
    // events and the pairs that changed modes most among the last kDiagnosedEvents of them.
    constexpr std::size_t kDiagnosedEvents = 200;
    constexpr double kTwoPi = 6.283185307179586;
    const long steps = std::max(1L, cvode_->counters().steps);
    std::string d = " (mean step " + format_value(t_ / static_cast<double>(steps)) + " s, the last " +
                    format_value(cvode_->last_step()) + " s, the stack's period " +
                    format_value(kTwoPi / scales_.omega_rad_per_s) + " s; " + std::to_string(stats_.events) + " events, " +
                    std::to_string(stats_.missed_events) + " missed";
    if (!events_.empty()) {
        const std::size_t first = events_.size() > kDiagnosedEvents ? events_.size() - kDiagnosedEvents : 0;
        std::vector<int> count(static_cast<std::size_t>(np_), 0);
        for (std::size_t i = first; i < events_.size(); ++i) ++count[static_cast<std::size_t>(events_[i].pair)];
        std::vector<int> order(static_cast<std::size_t>(np_));
        for (int kk = 0; kk < np_; ++kk) order[static_cast<std::size_t>(kk)] = kk;
        std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return count[a] > count[b]; });
        d += "; of the last " + std::to_string(events_.size() - first) + " transitions (since t = " +
             format_value(events_[first].t_s) + " s)";
        for (std::size_t i = 0; i < std::min<std::size_t>(3, order.size()) && count[order[i]] > 0; ++i) {
            const PairSpec& spec = sys_.pair_spec(order[i]);
            d += std::string(i == 0 ? ": " : ", ") + "pair " + std::to_string(order[i]) + " (interface " +
                 std::to_string(spec.interface_index) + ", x = " + format_value(spec.x_m) + " m) " +
                 std::to_string(count[order[i]]);
        }
    }
    d += ")";
    if (pair_chatter_limit_)  // the massive stack: its layer's vibrations are what takes the steps
        d += ": the whole massive stack follows its elastic layer's own vibrations; damping.layer_normal_time_s > 0 "
             "damps them (a dashpot on the layer, e.g. 1e-6 s), or leaf_inertia = modal (a massless contact layer) or "
             "mode newmark follow such a stack at the stack's time scale";
    return d;
}

}  // namespace stackbeam::detail
