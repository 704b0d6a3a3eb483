// Fatigue of the leaves (include/stackbeam/post/fatigue.hpp, issue 43 item 4): rainflow counting
// against the worked example of ASTM E1049-85 (2017), section 5.4.4 (Fig. 6); the mean-stress
// corrections, the safety factor, Basquin's life and Miner's sum against hand computations
// written out below; invariances of the counting; the periodic (cheap) path against rainflow;
// the material keys of the scenario files (read, defaults, shared, written back, bad input).
//
// Tolerances: the counting is exact (ranges and means of the input's own values, no arithmetic
// beyond a subtraction and a halving of small integers: compared with ==); the strength formulas
// are a few floating-point operations and a pow: relative 1e-12 (about 50 ulps).
#define BOOST_TEST_MODULE fatigue
#include <boost/test/unit_test.hpp>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "stackbeam/errors.hpp"
#include "stackbeam/io/scenario.hpp"
#include "stackbeam/post/fatigue.hpp"

namespace tt = boost::test_tools;
using namespace stackbeam;

namespace {

constexpr double MPa = 1e6;

/// A spring steel (about 50CrV4 / SAE 6150, hardened and tempered), Goodman, an endurance limit and
/// a Basquin curve with round constants for hand computation: S_u 1600, S_y 1400, S_e 600,
/// sigma_f' 2000 MPa, b = -0.1 (so that 1/b = -10).
FatigueMaterial steel(MeanStressCorrection correction = MeanStressCorrection::goodman) {
    FatigueMaterial m;
    m.ultimate_strength_pa = 1600 * MPa;
    m.yield_strength_pa = 1400 * MPa;
    m.endurance_limit_pa = 600 * MPa;
    m.fatigue_strength_coefficient_pa = 2000 * MPa;
    m.fatigue_strength_exponent = -0.1;
    m.mean_stress_correction = correction;
    return m;
}

/// (range, mean, count) of every cycle, sorted: the counting's result without its order.
std::vector<std::tuple<double, double, double>> sorted_cycles(const std::vector<RainflowCycle>& cycles, bool full_only = false) {
    std::vector<std::tuple<double, double, double>> out;
    for (const RainflowCycle& c : cycles)
        if (!full_only || c.count == 1.0) out.emplace_back(c.range_pa, c.mean_pa, c.count);
    std::sort(out.begin(), out.end());
    return out;
}

double total_count(const std::vector<RainflowCycle>& cycles) {
    double n = 0.0;
    for (const RainflowCycle& c : cycles) n += c.count;
    return n;
}

}  // namespace

BOOST_AUTO_TEST_CASE(astm_e1049_rainflow_example) {
    // ASTM E1049-85 (reapproved 2017), 5.4.4 Rainflow Counting, Fig. 6: the history A..I =
    // -2, 1, -3, 5, -1, 3, -4, 4, -2 (load units). The standard's result (Fig. 6 and its table of
    // counts): range 3: 0.5, 4: 1.5, 6: 0.5, 8: 1.0, 9: 0.5 (ranges 5, 7, 10: 0), 4 cycles in all.
    // The rules by hand (X the latest range, Y the one before; S the starting point):
    //   A B C: X = |C-B| = 4 >= Y = |B-A| = 3, Y holds S = A: A-B half (3, mean -0.5), S = B
    //   B C D: X = 8 >= Y = 4, Y holds S: B-C half (4, -1), S = C
    //   C D E: X = 6 < Y = 8;  D E F: X = 4 < 6;  E F G: X = 7 >= Y = |F-E| = 4, S not in Y:
    //          E-F one cycle (4, mean 1), E and F discarded
    //   C D G: X = |G-D| = 9 >= Y = 8, Y holds S: C-D half (8, 1), S = D
    //   D G H: X = 8 < 9;  G H I: X = 6 < 8;  end: D-G half (9, 0.5), G-H half (8, 0), H-I half (6, 1)
    const std::vector<double> s = {-2, 1, -3, 5, -1, 3, -4, 4, -2};
    const std::vector<RainflowCycle> c = rainflow_cycles(s);
    struct Expected {
        double range, mean, count;
        std::size_t start, end;
    };
    const std::vector<Expected> expected = {{3, -0.5, 0.5, 0, 1}, {4, -1, 0.5, 1, 2}, {4, 1, 1.0, 4, 5}, {8, 1, 0.5, 2, 3},
                                            {9, 0.5, 0.5, 3, 6},  {8, 0, 0.5, 6, 7},  {6, 1, 0.5, 7, 8}};
    BOOST_TEST_REQUIRE(c.size() == expected.size());
    for (std::size_t k = 0; k < c.size(); ++k) {
        BOOST_TEST_CONTEXT("cycle " << k) {
            BOOST_TEST(c[k].range_pa == expected[k].range);
            BOOST_TEST(c[k].mean_pa == expected[k].mean);
            BOOST_TEST(c[k].count == expected[k].count);
            BOOST_TEST(c[k].start_index == expected[k].start);
            BOOST_TEST(c[k].end_index == expected[k].end);
        }
    }
    // the standard's table: counts per range
    for (const auto& [range, count] : std::vector<std::pair<double, double>>{
             {3, 0.5}, {4, 1.5}, {5, 0.0}, {6, 0.5}, {7, 0.0}, {8, 1.0}, {9, 0.5}, {10, 0.0}}) {
        double n = 0.0;
        for (const RainflowCycle& x : c)
            if (x.range_pa == range) n += x.count;
        BOOST_TEST(n == count, "range " << range);
    }
    BOOST_TEST(total_count(c) == 4.0);
}

BOOST_AUTO_TEST_CASE(turning_points_and_the_gate) {
    // rising 0..2 (a plateau at 2), falling to -1 (a plateau), up to 3 with a dip of 0.07 near the
    // top, down to 0
    const std::vector<double> s = {0, 1, 2, 2, 1, -1, -1, 3, 3.05, 2.98, 3.1, 0};
    BOOST_TEST(turning_points(s) == (std::vector<std::size_t>{0, 2, 5, 8, 9, 10, 11}));  // every strict reversal
    BOOST_TEST(turning_points(s, 0.2) == (std::vector<std::size_t>{0, 2, 5, 10, 11}));  // the 0.07 dip dropped
    BOOST_TEST(turning_points(s, 10.0) == (std::vector<std::size_t>{0}));                // nothing beyond the gate
    // a sine of amplitude 100 with +-1 noise on every sample: with a gate of 5 the counting is the
    // clean sine's, 5 periods from the maximum to the maximum: 5 cycles of range 200 (+-2 noise)
    std::vector<double> noisy;
    for (int k = 0; k <= 500; ++k) noisy.push_back(100.0 * std::cos(2.0 * M_PI * k / 100.0) + (k % 2 ? 1.0 : -1.0));
    const auto c = rainflow_cycles(noisy, 5.0);
    BOOST_TEST(total_count(c) == 5.0);
    for (const auto& x : c) BOOST_TEST(std::abs(x.range_pa - 200.0) <= 2.0);
    BOOST_TEST(total_count(rainflow_cycles(noisy)) > 20.0);  // without the gate the wiggles near the peaks count

    BOOST_CHECK_THROW(turning_points(s, -1.0), InputError);
    try {
        turning_points({0.0, std::nan(""), 1.0});
        BOOST_FAIL("a NaN sample was accepted");
    } catch (const InputError& e) {
        BOOST_TEST(e.field() == "stress_pa[1]");
    }
}

BOOST_AUTO_TEST_CASE(rainflow_invariances) {
    // a constant history has no cycle; one with a single move one half cycle
    BOOST_TEST(rainflow_cycles(std::vector<double>(20, 3.5)).empty());
    BOOST_TEST(rainflow_cycles({}).empty());
    const auto one = rainflow_cycles({1.0, 1.0, 4.0, 4.0});
    BOOST_TEST_REQUIRE(one.size() == 1u);
    BOOST_TEST(one[0].count == 0.5);
    BOOST_TEST(one[0].range_pa == 3.0);

    // a random history (fixed seed, real values so that no two ranges tie)
    std::mt19937 rng(43);
    std::uniform_real_distribution<double> u(-300 * MPa, 300 * MPa);
    std::vector<double> s(400);
    for (double& x : s) x = u(rng);
    const auto c = rainflow_cycles(s);
    // every range between adjacent turning points is counted once (half) or twice (in a full cycle):
    // the counts sum to (turning points - 1) / 2, a balance that must close
    BOOST_TEST(total_count(c) == 0.5 * static_cast<double>(turning_points(s).size() - 1));
    BOOST_TEST(std::count_if(c.begin(), c.end(), [](const RainflowCycle& x) { return x.count == 1.0; }) > 50);

    // reversed in time: the same closed loops (full cycles); the residue may split differently
    // (with tied ranges, X >= Y, the order matters: such histories are not used here)
    std::vector<double> r(s.rbegin(), s.rend());
    BOOST_TEST((sorted_cycles(rainflow_cycles(r), true) == sorted_cycles(c, true)));

    // shifted by a constant: the same ranges, counts and places, the means shifted
    std::vector<double> shifted = s;
    for (double& x : shifted) x += 250 * MPa;
    const auto cs = rainflow_cycles(shifted);
    BOOST_TEST_REQUIRE(cs.size() == c.size());
    for (std::size_t k = 0; k < c.size(); ++k) {
        BOOST_TEST(cs[k].range_pa == c[k].range_pa, tt::tolerance(1e-12));
        BOOST_TEST(cs[k].mean_pa == c[k].mean_pa + 250 * MPa, tt::tolerance(1e-12));
        BOOST_TEST(cs[k].count == c[k].count);
        BOOST_TEST(cs[k].start_index == c[k].start_index);
    }
    // scaled by 2.5 (a power of 2 times 1.25: exact in most samples; tolerance for the rest):
    // ranges and means scale, the counting is unchanged
    std::vector<double> scaled = s;
    for (double& x : scaled) x *= 2.5;
    const auto cx = rainflow_cycles(scaled);
    BOOST_TEST_REQUIRE(cx.size() == c.size());
    for (std::size_t k = 0; k < c.size(); ++k) {
        BOOST_TEST(cx[k].range_pa == 2.5 * c[k].range_pa, tt::tolerance(1e-12));
        BOOST_TEST(cx[k].mean_pa == 2.5 * c[k].mean_pa, tt::tolerance(1e-9));  // a mean may be near 0
        BOOST_TEST(cx[k].count == c[k].count);
        BOOST_TEST(cx[k].end_index == c[k].end_index);
    }
}

BOOST_AUTO_TEST_CASE(mean_stress_corrections_and_safety_factors_by_hand) {
    // s_a = 300 MPa, s_m = 400 MPa on the steel (S_u 1600, S_y 1400, S_e 600, sigma_f' 2000 MPa):
    //   Goodman   1/n = 300/600 + 400/1600 = 0.5 + 0.25 = 0.75          n = 4/3
    //             s_ar = 300 / (1 - 400/1600) = 300 / 0.75 = 400 MPa
    //   Soderberg 1/n = 0.5 + 400/1400 = 0.5 + 2/7 = 11/14               n = 14/11
    //             s_ar = 300 / (1 - 2/7) = 420 MPa
    //   Morrow    1/n = 0.5 + 400/2000 = 0.7                             n = 10/7
    //             s_ar = 300 / (1 - 0.2) = 375 MPa
    //   Gerber    n = (1600/400)^2 300/(2 600) (-1 + sqrt(1 + (2 400 600/(1600 300))^2))
    //               = 16 x 0.25 x (sqrt(2) - 1) = 4 (sqrt(2) - 1) = 1.65685...
    //             (check: n s_a/S_e + (n s_m/S_u)^2 = 0.8284 + 0.1716 = 1)
    //             s_ar = 300 / (1 - 0.25^2) = 320 MPa
    const double sa = 300 * MPa, sm = 400 * MPa;
    using C = MeanStressCorrection;
    BOOST_TEST(fatigue_safety_factor(steel(C::goodman), sa, sm) == 4.0 / 3.0, tt::tolerance(1e-12));
    BOOST_TEST(fatigue_safety_factor(steel(C::soderberg), sa, sm) == 14.0 / 11.0, tt::tolerance(1e-12));
    BOOST_TEST(fatigue_safety_factor(steel(C::morrow), sa, sm) == 10.0 / 7.0, tt::tolerance(1e-12));
    BOOST_TEST(fatigue_safety_factor(steel(C::gerber), sa, sm) == 4.0 * (std::sqrt(2.0) - 1.0), tt::tolerance(1e-12));
    BOOST_TEST(equivalent_amplitude_pa(steel(C::goodman), sa, sm) == 400 * MPa, tt::tolerance(1e-12));
    BOOST_TEST(equivalent_amplitude_pa(steel(C::soderberg), sa, sm) == 420 * MPa, tt::tolerance(1e-12));
    BOOST_TEST(equivalent_amplitude_pa(steel(C::morrow), sa, sm) == 375 * MPa, tt::tolerance(1e-12));
    BOOST_TEST(equivalent_amplitude_pa(steel(C::gerber), sa, sm) == 320 * MPa, tt::tolerance(1e-12));
    // on each line n = 1 is the endurance limit: scale (s_a, s_m) by n and s_ar = S_e
    for (const C c : {C::goodman, C::gerber, C::soderberg, C::morrow}) {
        const double n = fatigue_safety_factor(steel(c), sa, sm);
        BOOST_TEST(equivalent_amplitude_pa(steel(c), n * sa, n * sm) == 600 * MPa, tt::tolerance(1e-12));
    }
    // a compressive mean gets no benefit: n = S_e / s_a = 2, s_ar = s_a; a zero amplitude no damage
    BOOST_TEST(fatigue_safety_factor(steel(), sa, -400 * MPa) == 2.0, tt::tolerance(1e-12));
    BOOST_TEST(equivalent_amplitude_pa(steel(C::gerber), sa, -400 * MPa) == sa);
    BOOST_TEST(std::isinf(fatigue_safety_factor(steel(), 0.0, 0.0)));
    BOOST_TEST(fatigue_safety_factor(steel(C::gerber), 0.0, 800 * MPa) == 2.0, tt::tolerance(1e-12));  // S_u / s_m
    // a mean at the line's strength: an infinite equivalent amplitude, no life
    BOOST_TEST(std::isinf(equivalent_amplitude_pa(steel(), sa, 1600 * MPa)));
    BOOST_TEST(basquin_life_cycles(steel(), equivalent_amplitude_pa(steel(), sa, 1600 * MPa)) == 0.0);

    // no endurance limit: no safety factor, a named error
    FatigueMaterial sn_only = steel();
    sn_only.endurance_limit_pa = 0.0;
    try {
        fatigue_safety_factor(sn_only, sa, sm);
        BOOST_FAIL("a safety factor without an endurance limit");
    } catch (const InputError& e) {
        BOOST_TEST(e.field() == "material.endurance_limit_pa");
    }
    BOOST_CHECK_THROW(equivalent_amplitude_pa(steel(), -1.0, 0.0), InputError);
}

BOOST_AUTO_TEST_CASE(basquin_life_by_hand) {
    // s_ar = sigma_f' (2N)^b, so N = (s_ar / sigma_f')^(1/b) / 2, with 1/b = -10:
    //   s_ar = 1000 MPa: N = 0.5^-10 / 2 = 1024 / 2 = 512 cycles
    //   s_ar =  800 MPa: N = 0.4^-10 / 2 = 2.5^10 / 2 = 9536.7431640625 / 2 = 4768.37158203125 cycles
    //   s_ar =  600 MPa = S_e and below: infinite (without S_e: 0.3^-10 / 2 = 84,675.3)
    // and through Goodman: s_a = 600, s_m = 400 MPa: s_ar = 600 / 0.75 = 800 MPa, N = 4768.37...
    BOOST_TEST(basquin_life_cycles(steel(), 1000 * MPa) == 512.0, tt::tolerance(1e-12));
    BOOST_TEST(basquin_life_cycles(steel(), 800 * MPa) == 4768.37158203125, tt::tolerance(1e-12));
    BOOST_TEST(std::isinf(basquin_life_cycles(steel(), 600 * MPa)));
    BOOST_TEST(std::isinf(basquin_life_cycles(steel(), 100 * MPa)));
    BOOST_TEST(basquin_life_cycles(steel(), equivalent_amplitude_pa(steel(), 600 * MPa, 400 * MPa)) == 4768.37158203125,
               tt::tolerance(1e-12));
    FatigueMaterial no_limit = steel();
    no_limit.endurance_limit_pa = 0.0;
    BOOST_TEST(basquin_life_cycles(no_limit, 600 * MPa) == 0.5 * std::pow(0.3, -10.0), tt::tolerance(1e-12));
    // an endurance limit and no curve: infinite below it, a named error above it
    FatigueMaterial limit_only = steel();
    limit_only.fatigue_strength_coefficient_pa = 0.0;
    limit_only.fatigue_strength_exponent = 0.0;
    BOOST_TEST(std::isinf(basquin_life_cycles(limit_only, 500 * MPa)));
    try {
        basquin_life_cycles(limit_only, 700 * MPa);
        BOOST_FAIL("a life above the endurance limit without an S-N curve");
    } catch (const InputError& e) {
        BOOST_TEST(e.field() == "material.fatigue_strength_coefficient_pa");
    }
}

BOOST_AUTO_TEST_CASE(miner_two_level_block_by_hand) {
    // A block of 100 cycles at +-1000 MPa and 1000 cycles at +-800 MPa (mean 0: s_ar = s_a):
    //   D = 100 / 512 + 1000 / 4768.37158203125 = 0.1953125 + 0.2097152 = 0.4050277
    //   (1000 / (2.5^10 / 2) = 2000 x 0.4^10 = 2000 x 1.048576e-4 = 0.2097152)
    // life 1 / D = 2.46897 blocks. Cycles below the endurance limit add nothing.
    const std::vector<RainflowCycle> block = {{2000 * MPa, 0.0, 100.0, 0, 0}, {1600 * MPa, 0.0, 1000.0, 0, 0},
                                              {1000 * MPa, 0.0, 1e9, 0, 0}};
    const double D = miner_damage(steel(), block);
    BOOST_TEST(D == 0.4050277, tt::tolerance(1e-12));
    BOOST_TEST(1.0 / D == 2.4689669373230525, tt::tolerance(1e-12));

    // the same block by rainflow: 100 periods at +-1000 MPa from the maximum, then 1000 periods at
    // +-800 MPa ending at +800 (2201 turning points, 2200 ranges). By the rules: each +-1000 range
    // holds S when it is counted, so the 199 of them are halves (99.5 cycles; the last one in the
    // residue); from -1000 the history rises to 800 (X = 1800 < Y = 2000) and every +-800 pair then
    // closes a full cycle (X = Y = 1600, S not in Y): 1000 full cycles; the residue keeps the
    // -1000 -> 800 range (1800 MPa, mean -100 MPa) as a half.
    std::vector<double> s;
    for (int k = 0; k < 100; ++k) s.insert(s.end(), {1000 * MPa, -1000 * MPa});
    for (int k = 0; k < 1000; ++k) s.insert(s.end(), {800 * MPa, -800 * MPa});
    s.push_back(800 * MPa);
    const auto c = rainflow_cycles(s);
    BOOST_TEST(total_count(c) == 0.5 * static_cast<double>(s.size() - 1));
    double n1000 = 0.0, n800 = 0.0, n900 = 0.0;
    for (const auto& x : c) {
        if (x.range_pa == 2000 * MPa) n1000 += x.count;
        if (x.range_pa == 1600 * MPa) n800 += x.count;
        if (x.range_pa == 1800 * MPa) n900 += x.count;
    }
    BOOST_TEST(n1000 == 99.5);
    BOOST_TEST(n800 == 1000.0);
    BOOST_TEST(n900 == 0.5);
    // Miner on the counted cycles: half a cycle less at +-1000 than the block, plus the 1800 MPa
    // half (mean -100 MPa, no benefit: s_ar = 900 MPa, N = 0.45^-10 / 2 = 1468.4 cycles)
    const double n_1800 = 0.5 * std::pow(0.45, -10.0);
    BOOST_TEST(miner_damage(steel(), c) == 99.5 / 512.0 + 1000.0 / 4768.37158203125 + 0.5 / n_1800, tt::tolerance(1e-12));
}

BOOST_AUTO_TEST_CASE(leaf_summary_periodic_and_rainflow) {
    // three nodes of a leaf, one period of s_m + s_a cos(2 pi t/T) at each fibre [MPa]:
    //   node 4 (x 0.10 m): top  400 +- 300 (Goodman n = 4/3, s_ar 400 < S_e: infinite life)
    //                      bottom -400 +- 300 (compressive mean: n = 600/300 = 2)
    //   node 5 (x 0.15 m): top  200 +- 100 (n = 1/(1/6 + 1/8) = 24/7), bottom 0 (constant: n infinite)
    //   node 6 (x 0.20 m): top  100 +- 50, bottom 400 +- 600 (n = 1/(1 + 0.25) = 0.8;
    //                      s_ar = 600/0.75 = 800 MPa: N = 4768.37158203125 cycles, the only damage)
    auto period = [](double mean, double amp, int samples, int periods) {
        std::vector<double> s;
        for (int k = 0; k <= samples * periods; ++k) s.push_back((mean + amp * std::cos(2.0 * M_PI * k / samples)) * MPa);
        return s;
    };
    auto leaf = [&](int periods) {
        LeafStressHistories h;
        h.node = {4, 5, 6};
        h.x_m = {0.10, 0.15, 0.20};
        h.top_pa = {period(400, 300, 64, periods), period(200, 100, 64, periods), period(100, 50, 64, periods)};
        h.bottom_pa = {period(-400, 300, 64, periods), period(0, 0, 64, periods), period(400, 600, 64, periods)};
        return h;
    };
    const LeafFatigue p = leaf_fatigue(steel(), leaf(1), CycleCounting::periodic);
    BOOST_TEST(p.has_safety_factor);
    BOOST_TEST(p.least_safety_factor == 0.8, tt::tolerance(1e-12));
    BOOST_TEST(p.safety_spot.node == 6);
    BOOST_TEST(p.safety_spot.x_m == 0.20);
    BOOST_TEST((p.safety_spot.fibre == Fibre::bottom));
    BOOST_TEST(p.safety_spot.amplitude_pa == 600 * MPa, tt::tolerance(1e-12));
    BOOST_TEST(p.safety_spot.mean_pa == 400 * MPa, tt::tolerance(1e-12));
    BOOST_TEST(p.has_life);
    BOOST_TEST(p.shortest_life_repetitions == 4768.37158203125, tt::tolerance(1e-12));
    BOOST_TEST(p.life_spot.node == 6);
    BOOST_TEST((p.life_spot.fibre == Fibre::bottom));

    // rainflow over 7 periods from the maximum to the maximum: 7 full-range cycles counted as
    // 14 halves with S (ASTM's starting point), so D is 7 times the periodic one and the life in
    // repetitions of the 7-period history is 1/7 of it, the same place and least factor
    const LeafFatigue r = leaf_fatigue(steel(), leaf(7), CycleCounting::rainflow);
    BOOST_TEST(r.least_safety_factor == p.least_safety_factor, tt::tolerance(1e-12));
    BOOST_TEST(r.damage_per_repetition == 7.0 * p.damage_per_repetition, tt::tolerance(1e-12));
    BOOST_TEST(r.shortest_life_repetitions == p.shortest_life_repetitions / 7.0, tt::tolerance(1e-12));
    BOOST_TEST(r.life_spot.node == 6);

    // without an S-N curve: the safety factor, and no life (a cycle above S_e)
    FatigueMaterial limit_only = steel();
    limit_only.fatigue_strength_coefficient_pa = 0.0;
    limit_only.fatigue_strength_exponent = 0.0;
    const LeafFatigue l = leaf_fatigue(limit_only, leaf(1), CycleCounting::periodic);
    BOOST_TEST(l.least_safety_factor == 0.8, tt::tolerance(1e-12));
    BOOST_TEST(!l.has_life);
    BOOST_TEST(std::isnan(l.shortest_life_repetitions));

    LeafStressHistories bad = leaf(1);
    bad.x_m.pop_back();
    try {
        leaf_fatigue(steel(), bad);
        BOOST_FAIL("mismatched histories accepted");
    } catch (const InputError& e) {
        BOOST_TEST(e.field() == "histories.x_m");
    }
}

// --- the scenario keys ---------------------------------------------------------------------

namespace {

#ifndef STACKBEAM_SOURCE_DIR
#error "STACKBEAM_SOURCE_DIR must be defined"
#endif

/// The paper's bonded example (three leaves), the scenario the material keys are added to.
std::string base_text() {
    std::ifstream in(std::string(STACKBEAM_SOURCE_DIR) + "/scenarios/paper_bonded.toml");
    std::ostringstream text;
    text << in.rdbuf();
    if (text.str().find("[[leaves]]") == std::string::npos) throw std::runtime_error("cannot read scenarios/paper_bonded.toml");
    return text.str();
}
const std::string kBase = base_text();

const std::string kShared = R"(
[material]
ultimate_strength_pa = 1.6e9
yield_strength_pa = 1.4e9
endurance_limit_pa = 6e8
fatigue_strength_coefficient_pa = 2e9
fatigue_strength_exponent = -0.1
)";

/// `text` with `lines` as leaves[1]'s [leaves.material]: before the third [[leaves]].
std::string second_leaf_material(const std::string& lines, std::string text = kBase) {
    std::size_t pos = 0;
    for (int k = 0; k < 3; ++k) {
        pos = text.find("\n[[leaves]]", pos + 1);
        BOOST_TEST_REQUIRE(pos != std::string::npos);
    }
    return text.insert(pos + 1, "[leaves.material]\n" + lines + "\n");
}

bool same(const FatigueMaterial& a, const FatigueMaterial& b) {
    return a.ultimate_strength_pa == b.ultimate_strength_pa && a.yield_strength_pa == b.yield_strength_pa &&
           a.endurance_limit_pa == b.endurance_limit_pa && a.fatigue_strength_coefficient_pa == b.fatigue_strength_coefficient_pa &&
           a.fatigue_strength_exponent == b.fatigue_strength_exponent && a.mean_stress_correction == b.mean_stress_correction;
}

}  // namespace

BOOST_AUTO_TEST_CASE(material_keys_read_shared_and_written_back) {
    // absent: no material, no fatigue figures
    for (const auto& l : parse_scenario(kBase, "t.toml").model.leaves) BOOST_TEST(!l.material.has_value());

    // [material] for every leaf; leaves[1]'s own table replaces it whole
    const std::string text = second_leaf_material("ultimate_strength_pa = 1.2e9\nendurance_limit_pa = 5e8\n"
                                                  "mean_stress_correction = \"gerber\"\n",
                                                  kBase + kShared);
    const Scenario s = parse_scenario(text, "t.toml");
    BOOST_TEST_REQUIRE(s.model.leaves[0].material.has_value());
    BOOST_TEST_REQUIRE(s.model.leaves[1].material.has_value());
    BOOST_TEST(same(*s.model.leaves[0].material, steel()));
    const FatigueMaterial& own = *s.model.leaves[1].material;
    BOOST_TEST(own.ultimate_strength_pa == 1.2e9);
    BOOST_TEST(own.endurance_limit_pa == 5e8);
    BOOST_TEST(own.yield_strength_pa == 0.0);  // not merged with the shared one
    BOOST_TEST(!has_sn_curve(own));
    BOOST_TEST((own.mean_stress_correction == MeanStressCorrection::gerber));
    BOOST_TEST(s.key_locations.count("leaves[1].material.mean_stress_correction") == 1u);

    // written back per leaf, read back the same (and the text a fixed point)
    const std::string written = to_toml(s);
    BOOST_TEST(written.find("[leaves.material]") != std::string::npos);
    const Scenario back = parse_scenario(written, "written.toml");
    for (std::size_t i = 0; i < 2; ++i) {
        BOOST_TEST_REQUIRE(back.model.leaves[i].material.has_value());
        BOOST_TEST(same(*back.model.leaves[i].material, *s.model.leaves[i].material), "leaves[" << i << "]");
    }
    BOOST_TEST(to_toml(back) == written);
    // no material: none written
    BOOST_TEST(to_toml(parse_scenario(kBase, "t.toml")).find("material") == std::string::npos);
}

BOOST_AUTO_TEST_CASE(bad_material_keys_are_named) {
    struct Case {
        std::string text, field, message;
    };
    const std::string leaf = "leaves[1].material.";
    const std::vector<Case> cases = {
        {second_leaf_material("endurance_limit_pa = 5e8\n"), leaf + "ultimate_strength_pa", "required key is missing"},
        {second_leaf_material("ultimate_strength_pa = -1.6e9\nendurance_limit_pa = 5e8\n"), leaf + "ultimate_strength_pa",
         "value -1600000000 is not allowed: must be finite and > 0 [Pa]"},
        {second_leaf_material("ultimate_strength_pa = nan\nendurance_limit_pa = 5e8\n"), leaf + "ultimate_strength_pa",
         "value nan is not allowed"},
        {second_leaf_material("ultimate_strength_pa = 1.6e9\nendurance_limit_pa = 0\n"), leaf + "endurance_limit_pa",
         "value 0 is not allowed"},
        {second_leaf_material("ultimate_strength_pa = 1.6e9\n"), leaf + "endurance_limit_pa",
         "needs an endurance limit (endurance_limit_pa) or an S-N curve"},
        {second_leaf_material("ultimate_strength_pa = 1.6e9\nendurance_limit_pa = 1.7e9\n"), leaf + "endurance_limit_pa",
         "must be < ultimate_strength_pa"},
        {second_leaf_material("ultimate_strength_pa = 1.6e9\nyield_strength_pa = 1.7e9\nendurance_limit_pa = 5e8\n"),
         leaf + "yield_strength_pa", "must be <= ultimate_strength_pa"},
        {second_leaf_material("ultimate_strength_pa = 1.6e9\nfatigue_strength_coefficient_pa = 2e9\nfatigue_strength_exponent = 0.1\n"),
         leaf + "fatigue_strength_exponent", "value 0.1 is not allowed: Basquin's exponent b must be in (-1, 0)"},
        {second_leaf_material("ultimate_strength_pa = 1.6e9\nfatigue_strength_exponent = -0.1\n"),
         leaf + "fatigue_strength_coefficient_pa", "needs both fatigue_strength_coefficient_pa and fatigue_strength_exponent"},
        {second_leaf_material("ultimate_strength_pa = 1.6e9\nendurance_limit_pa = 5e8\nmean_stress_correction = \"soderberg\"\n"),
         leaf + "yield_strength_pa", "'soderberg' needs the yield strength"},
        {second_leaf_material("ultimate_strength_pa = 1.6e9\nendurance_limit_pa = 5e8\nmean_stress_correction = \"morrow\"\n"),
         leaf + "fatigue_strength_coefficient_pa", "'morrow' needs the fatigue strength coefficient"},
        {second_leaf_material("ultimate_strength_pa = 1.6e9\nendurance_limit_pa = 5e8\nmean_stress_correction = \"walker\"\n"),
         leaf + "mean_stress_correction", "value 'walker' is not allowed: must be one of 'goodman', 'gerber', 'soderberg', 'morrow'"},
        {second_leaf_material("ultimate_strength_pa = 1.6e9\nendurance_limt_pa = 5e8\n"), leaf + "endurance_limt_pa",
         "unknown key 'endurance_limt_pa'"},
        // the shared table: named as written, [material]
        {kBase + "\n[material]\nultimate_strength_pa = 1.6e9\nendurance_limit_pa = 6e8\nfatigue_strength_exponent = -1.5\n"
                 "fatigue_strength_coefficient_pa = 2e9\n",
         "material.fatigue_strength_exponent", "must be in (-1, 0)"},
        {kBase + "\n[material]\nultimate_strength_pa = \"high\"\n", "material.ultimate_strength_pa", "wrong type, a string"},
    };
    for (const Case& c : cases) {
        std::string field, what;
        try {
            parse_scenario(c.text, "test.toml");
            field = "accepted";
        } catch (const InputError& e) {
            field = e.field();
            what = e.what();
        }
        BOOST_TEST_CONTEXT(c.field << ": " << what) {
            BOOST_TEST(field == c.field);
            BOOST_TEST(what.rfind("test.toml:", 0) == 0);  // the key's (or its table's) place in the file
            BOOST_TEST(what.find(": " + c.field + ": ") != std::string::npos);
            BOOST_TEST(what.find(c.message) != std::string::npos);
        }
    }
    // Model::build names the spec's path for a material set in C++
    ModelSpec spec = parse_scenario(kBase, "t.toml").model;
    spec.leaves[0].material = steel();
    spec.leaves[0].material->fatigue_strength_exponent = -2.0;
    try {
        Model::build(spec);
        BOOST_FAIL("b = -2 accepted");
    } catch (const InputError& e) {
        BOOST_TEST(e.field() == "leaves[0].material.fatigue_strength_exponent");
    }
}
