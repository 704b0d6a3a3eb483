// The loop figures of a run's last cycle (run/loop_figures.hpp): the one place they are computed.
#include "stackbeam/run/loop_figures.hpp"

#include "stackbeam/errors.hpp"

namespace stackbeam {

LoopFigures loop_figures(const std::vector<StepRecord>& records, double period_s) {
    LoopFigures loop;
    if (!(period_s > 0.0)) {
        loop.note = "no periodic loading: no steady cycle";
        return loop;
    }
    try {
        const auto cycle = last_cycle(records, period_s);
        loop.metrics = hysteresis_metrics(records, cycle.first, cycle.second);
    } catch (const InputError& e) {
        loop.note = e.what();
        return loop;
    }
    try {
        const FancherLoopFit fit = fit_fancher_loop(records, loop.metrics->t_start_s, loop.metrics->t_end_s);
        loop.fancher = fit.fit;
        for (std::size_t i = 0; i < fit.w_m.size(); ++i) loop.fancher_loop.emplace_back(fit.w_m[i], fit.model_force_n[i]);
    } catch (const InputError& e) {
        loop.fancher_note = e.what();
    }
    return loop;
}

bool loads_the_seat(const Loading& loading) { return loading.windup_rig() || loading.has_seat_load(); }

namespace {

/// The loop figures of `columns` over the last period `period_s` of `records`, or the note why none.
std::optional<HysteresisMetrics> last_loop(const std::vector<StepRecord>& records, double period_s,
                                           const LoopColumns& columns, const std::string& what, std::string& note) {
    if (!(period_s > 0.0)) {
        note = "no periodic " + what + ": no steady cycle";
        return std::nullopt;
    }
    try {
        const auto cycle = last_cycle(records, period_s);
        return hysteresis_metrics(records, cycle.first, cycle.second, columns);
    } catch (const InputError& e) {
        note = e.what();
        return std::nullopt;
    }
}

}  // namespace

WindupFigures windup_figures(const std::vector<StepRecord>& records, const Loading& loading, const LoopFigures& vertical) {
    WindupFigures f;
    // the windup loop: the rig's period, else the seat moment's, else the longitudinal force's (its -H h)
    double period_s = 0.0;
    if (loading.seat_rotation_rad) period_s = loading.seat_rotation_rad->period_s();
    else if (loading.seat_moment_n_m && loading.seat_moment_n_m->period_s() > 0.0) period_s = loading.seat_moment_n_m->period_s();
    else if (loading.longitudinal_force_n && loading.longitudinal_force_height_m != 0.0)
        period_s = loading.longitudinal_force_n->period_s();
    LoopColumns windup;
    windup.displacement_name = "seat_rotation";
    windup.displacement = [](const StepRecord& r) { return r.seat_rotation_rad; };
    windup.force = [](const StepRecord& r) { return r.seat_moment_n_m; };
    f.windup = last_loop(records, period_s, windup, "windup rig or seat moment", f.windup_note);
    // the longitudinal loop: H(t) against u_R
    if (loading.longitudinal_force_n) {
        LoopColumns axial;
        axial.displacement_name = "seat_axial";
        axial.displacement = [](const StepRecord& r) { return r.seat_axial_m; };
        axial.force = [&loading](const StepRecord& r) { return loading.longitudinal_force_n_at(r.t_s); };
        f.longitudinal = last_loop(records, loading.longitudinal_force_n->period_s(), axial, "longitudinal force",
                                   f.longitudinal_note);
        if (f.longitudinal && f.longitudinal->secant_stiffness_n_per_m > 0.0)
            f.longitudinal_compliance_m_per_n = 1.0 / f.longitudinal->secant_stiffness_n_per_m;
    } else {
        f.longitudinal_note = "no longitudinal force";
    }
    // the vertical rate where the vertical loading has a period of its own (Loading::period_s falls back
    // to the windup rig's: then w only follows the windup, and its "loop" is no rate)
    const double vertical_period_s = loading.kind == LoadingKind::applied_force      ? loading.force_n.period_s()
                                     : loading.kind == LoadingKind::initial_conditions ? 0.0
                                                                                       : loading.displacement_m.period_s();
    if (vertical.metrics && vertical_period_s > 0.0) f.vertical_rate_n_per_m = vertical.metrics->secant_stiffness_n_per_m;
    return f;
}

}  // namespace stackbeam
