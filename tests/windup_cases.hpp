#pragma once
// The windup tests' shared parts (test_windup, test_windup_rig): a constant and a ramp, a second leaf.
#include "stackbeam/model/loading.hpp"
#include "stackbeam/model/model.hpp"
#include "stackbeam/time/simulation.hpp"
#include "single_leaf.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace stackbeam::testing {

inline TimeFunction constant(double value) {
    TimeFunction f;
    f.mean = value;
    return f;
}

/// A triangle wave of `amplitude` at 1 Hz (0 at t = 0, rising: the rigs' loops).
inline TimeFunction triangle(double amplitude) {
    TimeFunction f;
    f.shape = TimeFunction::Shape::triangle;
    f.amplitude = amplitude;
    f.frequency_hz = 1.0;
    return f;
}

/// A table from 0 at t = 0 to `end` at t = 1 s.
inline TimeFunction ramp(double end) {
    TimeFunction f;
    f.shape = TimeFunction::Shape::table;
    f.times_s = {0.0, 1.0};
    f.values = {0.0, end};
    return f;
}

/// `spec` (one main leaf, the seat tying it) with a shorter leaf (1) of `lower_m` below the main one,
/// centred on x = c, free ends, the main leaf's section; one interface of `law` and mu.
inline ModelSpec with_lower_leaf(ModelSpec spec, double lower_m, double c, InterfaceLaw law, double mu) {
    LeafSpec lower = spec.leaves[0];
    lower.length_m = lower_m;
    lower.x_start_m = c - 0.5 * lower_m;
    lower.left_support = lower.right_support = SupportKind::free;
    spec.leaves.push_back(lower);
    InterfaceSpec f;
    f.law = law;
    f.friction_coefficient = mu;
    spec.interfaces = {f};
    return spec;
}

/// The windup tests' asymmetric two-leaf spring: the main leaf (0) 1.2 m, 10 x 50 mm steel
/// (206 GPa), from 0 to 1.2 m, a hinged eye at x = 0 (offset 15 mm: it locates the spring, so the
/// seat slides: u_R a DOF) and a pinned end at 1.2 m; a 0.8 m leaf (1) below it centred on 0.55 m,
/// free ends; the seat at 0.5 m (asymmetric) ties both; one interface of `law` and mu; 24 elements.
inline ModelSpec two_leaves(InterfaceLaw law, double mu) {
    constexpr double L = 1.2;
    ModelSpec s = single_leaf(L, 0.01, 0.05, 206e9, SupportKind::hinged, SupportKind::pinned, 0.5, L / 24);
    s.leaves[0].left_end.eye_offset_m = 0.015;
    return with_lower_leaf(s, 0.8, 0.55, law, mu);
}

/// A windup loop's figures from a run of 3 cycles of `per_cycle` steps each: the largest |seat moment|
/// [N m], the largest departure of cycle 3's moment from cycle 2's [N m], cycle 3's area by the
/// trapezoidal rule (the rig's work as the steppers book it) [J] and its friction work [J].
struct WindupLoop {
    double amplitude = 0.0, repeat = 0.0, area = 0.0, friction = 0.0;
};
inline WindupLoop windup_loop(const std::vector<StepRecord>& r, int per_cycle) {
    WindupLoop out;
    for (const auto& x : r) out.amplitude = std::max(out.amplitude, std::abs(x.seat_moment_n_m));
    for (int k = 0; k <= per_cycle; ++k)
        out.repeat = std::max(out.repeat, std::abs(r[2 * per_cycle + k].seat_moment_n_m - r[per_cycle + k].seat_moment_n_m));
    for (int k = 2 * per_cycle; k < 3 * per_cycle; ++k)
        out.area += 0.5 * (r[k].seat_moment_n_m + r[k + 1].seat_moment_n_m) * (r[k + 1].seat_rotation_rad - r[k].seat_rotation_rad);
    out.friction = r[3 * per_cycle].dissipated_energy_j - r[2 * per_cycle].dissipated_energy_j;
    return out;
}

}  // namespace stackbeam::testing
