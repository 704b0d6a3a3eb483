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

}  // namespace stackbeam
