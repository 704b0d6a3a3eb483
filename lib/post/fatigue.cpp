// Fatigue from stress histories (include/stackbeam/post/fatigue.hpp): turning points, rainflow
// counting after ASTM E1049-85 (2017) 5.4.4, mean-stress corrections, Basquin, Miner.
#include "stackbeam/post/fatigue.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "stackbeam/errors.hpp"

namespace stackbeam {

const char* to_string(Fibre fibre) { return fibre == Fibre::top ? "top" : "bottom"; }

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

void require_finite_history(const std::vector<double>& stress_pa, const std::string& name) {
    for (std::size_t k = 0; k < stress_pa.size(); ++k)
        if (!std::isfinite(stress_pa[k]))
            throw InputError(name + "[" + std::to_string(k) + "]",
                             "value " + format_value(stress_pa[k]) + " is not allowed: a stress must be finite [Pa]");
}

void require_cycle(double amplitude_pa, double mean_pa) {
    if (!std::isfinite(amplitude_pa) || amplitude_pa < 0.0)
        throw InputError("amplitude_pa", "value " + format_value(amplitude_pa) + " is not allowed: must be finite and >= 0 [Pa]");
    if (!std::isfinite(mean_pa))
        throw InputError("mean_pa", "value " + format_value(mean_pa) + " is not allowed: must be finite [Pa]");
}

/// The strength the material's straight line reaches at zero amplitude (Goodman S_u,
/// Soderberg S_y, Morrow sigma_f'); Gerber's parabola also ends at S_u.
double line_strength_pa(const FatigueMaterial& m) {
    switch (m.mean_stress_correction) {
        case MeanStressCorrection::goodman:
        case MeanStressCorrection::gerber: return m.ultimate_strength_pa;
        case MeanStressCorrection::soderberg: return m.yield_strength_pa;
        case MeanStressCorrection::morrow: return m.fatigue_strength_coefficient_pa;
    }
    return m.ultimate_strength_pa;
}

/// rainflow_cycles on the turning points' values `v` (indices `at` into the history).
std::vector<RainflowCycle> count_rainflow(const std::vector<double>& v, const std::vector<std::size_t>& at) {
    std::vector<RainflowCycle> cycles;
    auto cycle = [&](std::size_t a, std::size_t b, double count) {  // a, b: positions in v, a < b
        cycles.push_back({std::abs(v[b] - v[a]), 0.5 * (v[a] + v[b]), count, at[a], at[b]});
    };
    // ASTM E1049 5.4.4: `stack` holds the points not yet discarded, in time order; its first is
    // the starting point S (S only ever moves to the next point kept), so the range Y holds S
    // exactly when the stack has three points.
    std::vector<std::size_t> stack;
    for (std::size_t p = 0; p < v.size(); ++p) {
        stack.push_back(p);  // step 1: read the next peak or valley
        while (stack.size() >= 3) {  // step 2: X the latest range, Y the one before it
            const std::size_t n = stack.size();
            const double X = std::abs(v[stack[n - 1]] - v[stack[n - 2]]);
            const double Y = std::abs(v[stack[n - 2]] - v[stack[n - 3]]);
            if (X < Y) break;  // step 3a
            if (n == 3) {  // step 5: Y holds S: a half cycle, its first point discarded, S its second
                cycle(stack[0], stack[1], 0.5);
                stack.erase(stack.begin());
            } else {  // step 4: a full cycle, its peak and valley discarded
                cycle(stack[n - 3], stack[n - 2], 1.0);
                stack.erase(stack.begin() + static_cast<std::ptrdiff_t>(n - 3), stack.begin() + static_cast<std::ptrdiff_t>(n - 1));
            }
        }
    }
    for (std::size_t k = 1; k < stack.size(); ++k) cycle(stack[k - 1], stack[k], 0.5);  // step 6: the residue
    return cycles;
}

}  // namespace


std::vector<std::size_t> turning_points(const std::vector<double>& stress_pa, double gate_pa) {
    require_finite_history(stress_pa, "stress_pa");
    if (!std::isfinite(gate_pa) || gate_pa < 0.0)
        throw InputError("gate_pa", "value " + format_value(gate_pa) + " is not allowed: must be finite and >= 0 [Pa] (0: no gate)");
    std::vector<std::size_t> out;
    if (stress_pa.empty()) return out;
    out.push_back(0);
    int direction = 0;      // +1 rising, -1 falling, 0 not yet moved by more than the gate
    std::size_t extreme = 0;  // the running extreme of the current excursion
    for (std::size_t k = 1; k < stress_pa.size(); ++k) {
        const double s = stress_pa[k];
        if (direction == 0) {
            if (std::abs(s - stress_pa[0]) > gate_pa) {
                direction = s > stress_pa[0] ? 1 : -1;
                extreme = k;
            }
        } else if (direction * (s - stress_pa[extreme]) > 0.0) {
            extreme = k;  // the excursion goes on (a plateau keeps its first sample)
        } else if (direction * (stress_pa[extreme] - s) > gate_pa) {
            out.push_back(extreme);  // moved back by more than the gate: the extreme is a reversal
            direction = -direction;
            extreme = k;
        }
    }
    if (direction != 0) out.push_back(extreme);
    return out;
}

std::vector<RainflowCycle> rainflow_cycles(const std::vector<double>& stress_pa, double gate_pa) {
    const std::vector<std::size_t> at = turning_points(stress_pa, gate_pa);
    std::vector<double> v;
    v.reserve(at.size());
    for (std::size_t i : at) v.push_back(stress_pa[i]);
    return count_rainflow(v, at);
}

double equivalent_amplitude_pa(const FatigueMaterial& m, double amplitude_pa, double mean_pa) {
    require_cycle(amplitude_pa, mean_pa);
    if (mean_pa <= 0.0) return amplitude_pa;  // no benefit from a compressive mean
    const double r = mean_pa / line_strength_pa(m);
    const double denominator = m.mean_stress_correction == MeanStressCorrection::gerber ? 1.0 - r * r : 1.0 - r;
    if (denominator <= 0.0) return amplitude_pa > 0.0 ? kInf : 0.0;  // the mean alone reaches the strength
    return amplitude_pa / denominator;
}

double fatigue_safety_factor(const FatigueMaterial& m, double amplitude_pa, double mean_pa) {
    require_cycle(amplitude_pa, mean_pa);
    const double Se = m.endurance_limit_pa;
    if (Se <= 0.0)
        throw InputError("material.endurance_limit_pa",
                         "required key is missing: the fatigue safety factor is taken against the endurance limit");
    if (mean_pa <= 0.0) return amplitude_pa > 0.0 ? Se / amplitude_pa : kInf;
    const double S = line_strength_pa(m);
    if (m.mean_stress_correction != MeanStressCorrection::gerber) return 1.0 / (amplitude_pa / Se + mean_pa / S);
    if (amplitude_pa == 0.0) return S / mean_pa;  // the parabola's end on the mean axis
    const double q = 2.0 * mean_pa * Se / (S * amplitude_pa);
    // -1 + sqrt(1 + q^2) without cancellation for small q: q^2 / (1 + sqrt(1 + q^2))
    return (S / mean_pa) * (S / mean_pa) * amplitude_pa / (2.0 * Se) * (q * q / (1.0 + std::sqrt(1.0 + q * q)));
}

double basquin_life_cycles(const FatigueMaterial& m, double sar_pa) {
    if (std::isnan(sar_pa) || sar_pa < 0.0)
        throw InputError("equivalent_amplitude_pa", "value " + format_value(sar_pa) + " is not allowed: must be >= 0 [Pa]");
    if (m.endurance_limit_pa > 0.0 && sar_pa <= m.endurance_limit_pa) return kInf;
    if (!has_sn_curve(m)) {
        if (sar_pa == 0.0) return kInf;
        throw InputError("material.fatigue_strength_coefficient_pa",
                         "required key is missing: a life at the amplitude " + format_value(sar_pa) +
                             " Pa (above the endurance limit) needs the S-N curve (fatigue_strength_coefficient_pa and "
                             "fatigue_strength_exponent)");
    }
    if (std::isinf(sar_pa)) return 0.0;
    if (sar_pa == 0.0) return kInf;
    return 0.5 * std::pow(sar_pa / m.fatigue_strength_coefficient_pa, 1.0 / m.fatigue_strength_exponent);
}

double miner_damage(const FatigueMaterial& m, const std::vector<RainflowCycle>& cycles) {
    double damage = 0.0;
    for (const RainflowCycle& c : cycles) {
        if (!std::isfinite(c.count) || c.count < 0.0)
            throw InputError("cycles.count", "value " + format_value(c.count) + " is not allowed: must be finite and >= 0");
        if (c.count == 0.0) continue;
        const double N = basquin_life_cycles(m, equivalent_amplitude_pa(m, 0.5 * c.range_pa, c.mean_pa));
        damage += N == 0.0 ? kInf : c.count / N;
    }
    return damage;
}

LeafFatigue leaf_fatigue(const FatigueMaterial& m, const LeafStressHistories& h, CycleCounting counting, double gate_pa) {
    const std::size_t n = h.node.size();
    for (const auto& [name, size] : {std::pair<const char*, std::size_t>{"histories.x_m", h.x_m.size()},
                                     {"histories.top_pa", h.top_pa.size()},
                                     {"histories.bottom_pa", h.bottom_pa.size()}})
        if (size != n)
            throw InputError(name, "has " + std::to_string(size) + " entries: must have one per node of histories.node (" +
                                       std::to_string(n) + ")");
    LeafFatigue out;
    out.has_safety_factor = m.endurance_limit_pa > 0.0;
    out.least_safety_factor = kInf;
    out.has_life = true;
    out.damage_per_repetition = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
        for (const Fibre fibre : {Fibre::top, Fibre::bottom}) {
            const std::vector<double>& s = fibre == Fibre::top ? h.top_pa[k] : h.bottom_pa[k];
            const std::string name = std::string("histories.") + to_string(fibre) + "_pa[" + std::to_string(k) + "]";
            if (s.empty()) throw InputError(name, "has no samples: a node's history needs at least one");
            require_finite_history(s, name);
            std::vector<RainflowCycle> cycles;
            if (counting == CycleCounting::rainflow) {
                cycles = rainflow_cycles(s, gate_pa);
            } else {  // one period: its extremes make the one cycle
                const auto [lo, hi] = std::minmax_element(s.begin(), s.end());
                cycles.push_back({*hi - *lo, 0.5 * (*hi + *lo), 1.0, static_cast<std::size_t>(std::min(lo, hi) - s.begin()),
                                  static_cast<std::size_t>(std::max(lo, hi) - s.begin())});
            }
            FatigueSpot spot{h.node[k], h.x_m[k], fibre, 0.0, 0.0};
            double damage = 0.0, worst_sar = -1.0;
            for (const RainflowCycle& c : cycles) {
                const double sa = 0.5 * c.range_pa;
                if (out.has_safety_factor) {
                    const double f = fatigue_safety_factor(m, sa, c.mean_pa);
                    if (f < out.least_safety_factor) {
                        out.least_safety_factor = f;
                        out.safety_spot = {spot.node, spot.x_m, fibre, sa, c.mean_pa};
                    }
                }
                const double sar = equivalent_amplitude_pa(m, sa, c.mean_pa);
                if (sar > worst_sar) {
                    worst_sar = sar;
                    spot.amplitude_pa = sa;
                    spot.mean_pa = c.mean_pa;
                }
                if (!has_sn_curve(m) && !(sar <= m.endurance_limit_pa)) out.has_life = false;  // no curve above S_e
            }
            if (has_sn_curve(m)) damage = miner_damage(m, cycles);
            if ((k == 0 && fibre == Fibre::top) || damage > out.damage_per_repetition) {  // the first spot, or worse
                out.damage_per_repetition = damage;
                out.life_spot = spot;
            }
        }
    }
    const double unknown = std::numeric_limits<double>::quiet_NaN();
    if (!out.has_safety_factor) out.least_safety_factor = unknown;
    if (!out.has_life) out.damage_per_repetition = unknown;
    out.shortest_life_repetitions = !out.has_life ? unknown : out.damage_per_repetition > 0.0 ? 1.0 / out.damage_per_repetition : kInf;
    return out;
}

}  // namespace stackbeam
