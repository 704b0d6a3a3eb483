// Loop figures of a force-displacement cycle (hysteresis.hpp).
#include "stackbeam/post/hysteresis.hpp"

#include <algorithm>
#include <cmath>
#include <complex>

#include "stackbeam/errors.hpp"

namespace stackbeam {

namespace {
constexpr double kPi = 3.14159265358979323846264338327950288;
}

std::pair<double, double> last_cycle(const std::vector<StepRecord>& records, double period_s) {
    if (records.size() < 3) throw InputError("cycle", "the run has " + std::to_string(records.size()) + " records: too short for a cycle");
    const double t_last = records.back().t_s;
    if (period_s > 0.0) {
        const double t0 = t_last - period_s;
        if (t0 < records.front().t_s - 1e-12 * std::max(1.0, t_last))
            throw InputError("cycle", "the run (to t = " + format_value(t_last) + " s) is shorter than one period of the loading (" +
                                          format_value(period_s) + " s)");
        // the record nearest to t_last - period
        std::size_t i = 0;
        for (std::size_t j = 0; j < records.size(); ++j)
            if (std::abs(records[j].t_s - t0) < std::abs(records[i].t_s - t0)) i = j;
        return {records[i].t_s, t_last};
    }
    std::vector<std::size_t> maxima;
    for (std::size_t j = 1; j + 1 < records.size(); ++j)
        if (records[j].w_m > records[j - 1].w_m && records[j].w_m >= records[j + 1].w_m) maxima.push_back(j);
    if (maxima.size() < 2)
        throw InputError("cycle", "w has " + std::to_string(maxima.size()) +
                                      " maxima in the run: a cycle needs two (run longer, or give a periodic loading)");
    return {records[maxima[maxima.size() - 2]].t_s, records[maxima.back()].t_s};
}

HysteresisMetrics hysteresis_metrics(const std::vector<StepRecord>& records, double t_start_s, double t_end_s,
                                     const LoopColumns& columns) {
    const double eps = 1e-9 * std::max(1.0, std::abs(t_end_s));
    std::vector<const StepRecord*> c;
    for (const auto& r : records)
        if (r.t_s >= t_start_s - eps && r.t_s <= t_end_s + eps) c.push_back(&r);
    if (c.size() < 8)
        throw InputError("cycle", "[" + format_value(t_start_s) + ", " + format_value(t_end_s) + "] s holds " +
                                      std::to_string(c.size()) + " records: a loop needs at least 8");
    // the pair's values along the cycle: x the displacement, f the force doing work on it
    std::vector<double> x(c.size()), f(c.size());
    for (std::size_t j = 0; j < c.size(); ++j) {
        x[j] = columns.displacement(*c[j]);
        f[j] = columns.force(*c[j]);
    }
    HysteresisMetrics h;
    h.t_start_s = c.front()->t_s;
    h.t_end_s = c.back()->t_s;
    h.samples = static_cast<int>(c.size());
    h.w_min_m = *std::min_element(x.begin(), x.end());
    h.w_max_m = *std::max_element(x.begin(), x.end());
    h.force_min_n = *std::min_element(f.begin(), f.end());
    h.force_max_n = *std::max_element(f.begin(), f.end());
    const double dw = h.w_max_m - h.w_min_m;
    if (!(dw > 0.0)) throw InputError("cycle", columns.displacement_name + " does not move over the cycle: no loop");
    // Loop area, trapezoidal over the recorded path (closed by the last segment back to
    // the start when the cycle is not exactly closed, e.g. a decaying free vibration).
    double area = 0.0;
    const std::size_t n = c.size();
    for (std::size_t j = 0; j + 1 < n; ++j) area += 0.5 * (f[j] + f[j + 1]) * (x[j + 1] - x[j]);
    area += 0.5 * (f[n - 1] + f[0]) * (x[0] - x[n - 1]);
    h.loop_area_j = area;
    h.secant_stiffness_n_per_m = (h.force_max_n - h.force_min_n) / dw;
    // First harmonics over the cycle (trapezoidal rule on a periodic integrand).
    const double T = h.t_end_s - h.t_start_s;
    const double om = 2.0 * kPi / T;
    std::complex<double> F1 = 0.0, W1 = 0.0;
    for (std::size_t j = 0; j + 1 < c.size(); ++j) {
        const double h_t = c[j + 1]->t_s - c[j]->t_s;
        const auto e0 = std::exp(std::complex<double>(0.0, -om * (c[j]->t_s - h.t_start_s)));
        const auto e1 = std::exp(std::complex<double>(0.0, -om * (c[j + 1]->t_s - h.t_start_s)));
        F1 += 0.5 * h_t * (f[j] * e0 + f[j + 1] * e1);
        W1 += 0.5 * h_t * (x[j] * e0 + x[j + 1] * e1);
    }
    if (std::abs(W1) > 0.0) {
        const std::complex<double> K = F1 / W1;
        h.dynamic_rate_n_per_m = std::abs(K);
        h.loss_factor = K.imag() / K.real();
    }
    const double wa = 0.5 * dw;
    const double Es = 0.5 * h.secant_stiffness_n_per_m * wa * wa;
    if (Es > 0.0) {
        h.energy_loss_factor = area / (2.0 * kPi * Es);
        h.equivalent_damping_ratio = area / (4.0 * kPi * Es);
    }
    h.dissipated_j = c.back()->dissipated_energy_j - c.front()->dissipated_energy_j;
    h.external_work_j = c.back()->external_work_j - c.front()->external_work_j;
    h.strain_energy_change_j = c.back()->strain_energy_j - c.front()->strain_energy_j;
    return h;
}

}  // namespace stackbeam
