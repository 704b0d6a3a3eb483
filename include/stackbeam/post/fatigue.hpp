#pragma once
/// @file fatigue.hpp
/// Fatigue of the leaves from their stress histories: turning points, rainflow counting
/// (ASTM E1049-85 (2017), section 5.4.4), mean-stress corrections, the safety factor against
/// the endurance limit, Basquin lives and Miner's damage sum. Pure functions of plain values:
/// the stresses come from the caller (a time series of the bending stress at a node's top or
/// bottom fibre); nothing here runs a model. Formulas and sources: docs/stresses-and-fatigue.md,
/// "Fatigue".
///
/// Units and signs: stresses in Pa, tension positive (a cycle's mean > 0 is tensile). A cycle
/// of range Delta s has the amplitude s_a = Delta s / 2 and the mean s_m = (s_max + s_min) / 2.
/// Lives are in cycles (Basquin) or in repetitions of the given history (Miner, 1 / D).
#include <cstddef>
#include <vector>

#include "stackbeam/model/model.hpp"  // FatigueMaterial, MeanStressCorrection
#include "stackbeam/post/fibre.hpp"

namespace stackbeam {

/// The turning points (peaks and valleys) of a history: indices into `stress_pa`, in time
/// order, the first sample always first and the end of the last excursion last. A reversal is
/// kept only once the history has moved back from it by more than `gate_pa` (a hysteresis
/// filter: excursions of `gate_pa` or less are dropped as noise; 0 keeps every strict reversal);
/// a plateau counts once (its first sample). A history that never moves by more than the gate
/// gives the first sample alone. Throws InputError ("stress_pa[k]", "gate_pa") on a value that
/// is not finite or a negative gate.
std::vector<std::size_t> turning_points(const std::vector<double>& stress_pa, double gate_pa = 0.0);

/// One counted cycle: the range between two turning points of the history.
struct RainflowCycle {
    double range_pa = 0.0;        ///< |s(end) - s(start)| [Pa]
    double mean_pa = 0.0;         ///< (s(start) + s(end)) / 2 [Pa], + tensile
    double count = 0.0;           ///< 1 (a full cycle, a closed loop) or 0.5 (a half cycle); Miner: any n > 0
    std::size_t start_index = 0;  ///< the range's first point, an index into the history
    std::size_t end_index = 0;    ///< its second point (> start_index)
};

/// Rainflow counting of a history (ASTM E1049-85 (2017), 5.4.4, the three-point rules with the
/// starting point S): the turning points (turning_points, with `gate_pa`) are read one by one;
/// with X the most recent range and Y the one before it, X >= Y counts Y as a full cycle
/// (discarding its two points) or, when Y holds S, as a half cycle (discarding its first point,
/// S moving to its second); at the end every range left is a half cycle (the residue). Cycles in
/// the order they are counted. A constant history has none; every range between adjacent turning
/// points is counted once: the counts sum to (turning points - 1) / 2.
std::vector<RainflowCycle> rainflow_cycles(const std::vector<double>& stress_pa, double gate_pa = 0.0);

/// The equivalent fully reversed amplitude s_ar of a cycle (amplitude s_a >= 0, mean s_m) by the
/// material's mean-stress correction (Dowling, Mechanical Behavior of Materials, 4th ed., 9.7):
///     Goodman    s_ar = s_a / (1 - s_m / S_u)
///     Gerber     s_ar = s_a / (1 - (s_m / S_u)^2)
///     Soderberg  s_ar = s_a / (1 - s_m / S_y)
///     Morrow     s_ar = s_a / (1 - s_m / sigma_f')
/// for a tensile mean; a compressive mean (s_m <= 0) is given no benefit, s_ar = s_a (Shigley,
/// 10th ed., 6-12; Gerber's parabola would even penalise it). +infinity when s_m reaches the
/// line's strength (the denominator <= 0). Throws InputError on s_a < 0 or a value not finite.
double equivalent_amplitude_pa(const FatigueMaterial& material, double amplitude_pa, double mean_pa);

/// The fatigue safety factor n of a cycle against the endurance limit S_e along the material's
/// line, stresses growing in proportion (Shigley, 10th ed., table 6-7, load line through the
/// origin): Goodman 1/n = s_a/S_e + s_m/S_u, Soderberg 1/n = s_a/S_e + s_m/S_y, Morrow
/// 1/n = s_a/S_e + s_m/sigma_f', Gerber n s_a/S_e + (n s_m/S_u)^2 = 1, i.e.
///     n = (S_u/s_m)^2 s_a/(2 S_e) (-1 + sqrt(1 + (2 s_m S_e/(S_u s_a))^2));
/// for s_m <= 0, n = S_e / s_a (no benefit from compression); +infinity for s_a = s_m = 0.
/// Throws InputError ("material.endurance_limit_pa") when the material has no endurance limit.
double fatigue_safety_factor(const FatigueMaterial& material, double amplitude_pa, double mean_pa);

/// Basquin's life in cycles at the equivalent fully reversed amplitude s_ar, from
/// s_ar = sigma_f' (2N)^b: N = (s_ar / sigma_f')^(1/b) / 2; +infinity at or below the endurance
/// limit where one is given, 0 at an infinite s_ar. Throws InputError
/// ("material.fatigue_strength_coefficient_pa") above the endurance limit without an S-N curve.
double basquin_life_cycles(const FatigueMaterial& material, double equivalent_amplitude_pa);

/// Miner's damage sum D = sum n_i / N_i over the cycles (N_i the Basquin life at each cycle's
/// equivalent amplitude; cycles of infinite life add 0). The life in repetitions of the
/// history is 1 / D (+infinity for D = 0).
double miner_damage(const FatigueMaterial& material, const std::vector<RainflowCycle>& cycles);


/// Stress histories of one leaf's nodes at its two fibres [Pa]: top_pa[k] and bottom_pa[k] are
/// node k's time series (the same samples for every node and fibre).
struct LeafStressHistories {
    std::vector<int> node;                     ///< the grid node of entry k (Model::nodes_x)
    std::vector<double> x_m;                   ///< its position [m]
    std::vector<std::vector<double>> top_pa;   ///< top fibre, [k][sample] [Pa]
    std::vector<std::vector<double>> bottom_pa;///< bottom fibre, [k][sample] [Pa]
};

/// How the cycles at a node's fibre are found.
enum class CycleCounting {
    rainflow,  ///< rainflow counting of the whole history (irregular loadings: base excitation, tables)
    periodic,  ///< the history is one period of a periodic loading: one cycle, its max and min (the cheap path)
};

/// Where a leaf's fatigue figure is worst.
struct FatigueSpot {
    int node = -1;               ///< grid node (-1: none)
    double x_m = 0.0;            ///< its position [m]
    Fibre fibre = Fibre::top;
    double amplitude_pa = 0.0;   ///< the governing cycle's amplitude [Pa] (safety factor); the largest s_ar's (life)
    double mean_pa = 0.0;        ///< its mean [Pa]
};

/// A leaf's fatigue figures over its nodes and both fibres.
struct LeafFatigue {
    /// Whether least_safety_factor is known: the material has an endurance limit.
    bool has_safety_factor = false;
    double least_safety_factor = 0.0;  ///< the least n over every node, fibre and counted cycle [-] (NaN: not known)
    FatigueSpot safety_spot;           ///< where, with that cycle's s_a, s_m
    /// Whether shortest_life is known: an S-N curve, or every cycle at or below the endurance limit.
    bool has_life = false;
    /// The shortest life in repetitions of the history (periodic: in cycles of the loading), 1 / D
    /// at the spot of the largest Miner sum D (+infinity: no damage anywhere; NaN: not known).
    double shortest_life_repetitions = 0.0;
    double damage_per_repetition = 0.0;  ///< D there [-] (NaN: not known)
    FatigueSpot life_spot;               ///< where, with that spot's largest-s_ar cycle
};

/// The leaf's figures from its nodes' histories. Throws InputError ("histories.x_m",
/// "histories.top_pa[k]", ...) when the vectors' sizes disagree or a node has no samples.
LeafFatigue leaf_fatigue(const FatigueMaterial& material, const LeafStressHistories& histories,
                         CycleCounting counting = CycleCounting::rainflow, double gate_pa = 0.0);

}  // namespace stackbeam
