// Axle windup and longitudinal loads (loading.hpp, "Seat loads and the windup rig"): the seat's
// moment, longitudinal force and prescribed rotation against statics and closed forms, the windup
// rig's friction loop against the energy it dissipates, the axle's pitch inertia against the
// oscillator it makes, and the named errors of bad input.
//
// Tolerances. Prismatic leaves loaded at nodes (the seat is a node): the cubic Hermite element is
// exact there, so the static checks are to rounding (relative 1e-9, well above the 1e-12 of the
// factorisations and the solves of a few hundred DOFs).
#define BOOST_TEST_MODULE windup
#include <boost/test/unit_test.hpp>

#include <cmath>
#include <string>

#include "single_leaf.hpp"
#include "stackbeam/errors.hpp"
#include "stackbeam/fe/system.hpp"
#include "stackbeam/io/scenario.hpp"
#include "stackbeam/time/simulation.hpp"
#include "stackbeam/time/stepper.hpp"

using namespace stackbeam;
namespace tt = boost::test_tools;

namespace {

constexpr double kL = 1.2, kT = 0.01, kB = 0.05, kE = 206e9, kPi = 3.14159265358979323846;
const double kEI = kE * kB * kT * kT * kT / 12.0, kEA = kE * kB * kT;

/// One prismatic leaf from 0 to kL on `left` / `right` supports, the seat at x = a (a node: the
/// element is kL / 24 = 0.05 m).
ModelSpec leaf(double a, SupportKind left = SupportKind::pinned, SupportKind right = SupportKind::pinned) {
    return testing::single_leaf(kL, kT, kB, kE, left, right, a, kL / 24);
}

/// A table from 0 at t = 0 to `end` at t = 1 s.
TimeFunction ramp(double end) {
    TimeFunction f;
    f.shape = TimeFunction::Shape::table;
    f.times_s = {0.0, 1.0};
    f.values = {0.0, end};
    return f;
}

TimeFunction constant(double value) {
    TimeFunction f;
    f.mean = value;
    return f;
}

/// Mode newmark, 10 steps to t = 1 s (massless leaves: each step a static solve).
SimulationOptions newmark(const Loading& loading, double t_end_s = 1.0, double dt_s = 0.1) {
    SimulationOptions o;
    o.mode = Mode::newmark;
    o.dt_s = dt_s;
    o.t_end_s = t_end_s;
    o.loading = loading;
    return o;
}

/// The windup rig to theta_end at t = 1 s; the seat held vertically at w = 0 or free.
Loading windup_rig(double theta_end, bool held_vertically) {
    Loading L;
    L.seat_rotation_rad = ramp(theta_end);
    if (held_vertically) {
        L.kind = LoadingKind::prescribed_displacement;
        L.displacement_m = constant(0.0);
    }
    return L;
}

/// The InputError's field of make_stepper, or "accepted".
std::string refusal(const ModelSpec& spec, const SimulationOptions& o) {
    try {
        const System sys(Model::build(spec));
        make_stepper(sys, o);
    } catch (const InputError& e) {
        return e.field();
    }
    return "accepted";
}

}  // namespace

// A single flat leaf, pinned at both ends, the seat held vertically and turned by theta: each half
// is a propped cantilever (built in at the seat, pinned at its end), rotational stiffness 3 EI / l,
// so the windup stiffness is 3 E I (1/a + 1/b) for halves a and b.
BOOST_AUTO_TEST_CASE(flat_leaf_with_the_seat_held_winds_up_at_3EI_over_a_plus_over_b) {
    const double a = 0.5, b = kL - a, theta = 0.02;
    const System sys(Model::build(leaf(a)));
    BOOST_TEST_REQUIRE(sys.seat_rotation_dof() >= 0);
    BOOST_TEST(sys.seat_axial_dof() == -1);  // pinned ends: the seat locates the stack ('auto')
    const auto r = simulate(sys, newmark(windup_rig(theta, true)));
    const double expected = 3.0 * kEI * (1.0 / a + 1.0 / b);
    BOOST_TEST(r.back().seat_rotation_rad == theta, tt::tolerance(1e-12));
    BOOST_TEST(r.back().seat_moment_n_m / theta == expected, tt::tolerance(1e-9));
    BOOST_TEST(std::abs(r.back().w_m) == 0.0);
    // the energy balance closes: the rig's work is the strain energy (static, no friction)
    BOOST_TEST(std::abs(r.back().energy_balance_error_j) < 1e-9 * r.back().strain_energy_j);
    BOOST_TEST(r.back().strain_energy_j == 0.5 * expected * theta * theta, tt::tolerance(1e-9));
}

// The seat free vertically: the simply supported beam of span L with a couple M0 (counter-clockwise)
// at x = a: theta(a) = M0 (a^3 + b^3) / (3 E I L^2) and v(a) = M0 a b (b - a) / (3 E I L) (the
// bending moment M0 x / L left of a, -M0 (L - x) / L right of it, integrated twice). Once by the
// windup rig (quasi-static: the moment read) and once by the seat moment. Under the moment R's mass
// bounces on the asymmetric leaf (the couple moves w), so the leaf there carries M0 and R's force F on
// it (StepRecord::spring_force_n, +y): by superposition and Maxwell's reciprocity theta = M0 c_MM +
// F c_MF, w = M0 c_MF + F c_FF, c_MF = a b (b - a) / (3 E I L), c_FF = a^2 b^2 / (3 E I L), whatever
// the motion.
BOOST_AUTO_TEST_CASE(flat_leaf_with_the_seat_free_is_the_simply_supported_beam_under_a_couple) {
    const double a = 0.5, b = kL - a, M0 = 40.0;
    const double theta = M0 * (a * a * a + b * b * b) / (3.0 * kEI * kL * kL);
    const double v = M0 * a * b * (b - a) / (3.0 * kEI * kL);
    const System sys(Model::build(leaf(a)));
    const auto rig = simulate(sys, newmark(windup_rig(theta, false)));
    BOOST_TEST(rig.back().seat_moment_n_m == M0, tt::tolerance(1e-9));
    BOOST_TEST(rig.back().w_m == v, tt::tolerance(1e-9));
    BOOST_TEST(std::abs(rig.back().spring_force_n) < 1e-9 * M0 / kL);  // nothing pushes the seat vertically

    Loading moment;
    moment.seat_moment_n_m = ramp(M0);
    const auto r = simulate(sys, newmark(moment));
    const double c_mf = a * b * (b - a) / (3.0 * kEI * kL), c_ff = a * a * b * b / (3.0 * kEI * kL);
    const double F = r.back().spring_force_n;
    BOOST_TEST(std::abs(F) > 1e-3 * M0 / kL);  // R does bounce: the check below is not the static one again
    BOOST_TEST(r.back().seat_rotation_rad == theta + F * c_mf, tt::tolerance(1e-9));
    BOOST_TEST(r.back().w_m == v + F * c_ff, tt::tolerance(1e-9));
    BOOST_TEST(r.back().seat_moment_n_m == M0, tt::tolerance(1e-12));
    // the moment's work is R's kinetic energy and the strain energy
    BOOST_TEST(std::abs(r.back().energy_balance_error_j) < 1e-9 * r.back().strain_energy_j);
}

// The leaf's bending moment jumps by the applied couple at the seat: -M0 from left to right (the
// moment M0 x / L left of a, -M0 (L - x) / L right of it). The recovered nodal M is linear on each
// side (no load between the seat and the ends), so each side's value at the seat is its linear
// extrapolation from the two nodes next to it; the seat's own node holds their mean. The seat at the
// centre: the couple does not move w, so R's mass puts no force on the leaf.
BOOST_AUTO_TEST_CASE(bending_moment_jumps_by_the_seat_moment) {
    const double a = 0.5 * kL, M0 = 40.0;
    const System sys(Model::build(leaf(a)));
    Loading moment;
    moment.seat_moment_n_m = constant(M0);
    const auto stepper = make_stepper(sys, newmark(moment));
    stepper->advance();
    const Stresses s = stepper->stresses();
    const auto& x = s.leaves[0].x_m;
    const auto& M = s.leaves[0].bending_moment_n_m;
    int i = 0;
    while (std::abs(x[i] - a) > 1e-9) ++i;
    const double left = 2.0 * M[i - 1] - M[i - 2], right = 2.0 * M[i + 1] - M[i + 2];
    BOOST_TEST(right - left == -M0, tt::tolerance(1e-9));
    BOOST_TEST(left == M0 * a / kL, tt::tolerance(1e-9));
    BOOST_TEST(std::abs(M[i] - 0.5 * (left + right)) < 1e-9 * M0);  // 0 here: the couple is antisymmetric
}

// A longitudinal force H at height h above the seat on a seat that slides (the left end's hinged eye
// locates the stack, so 'auto' lets the seat slide; the right end is a roller). The left half carries
// H axially, u_R = H a / (E A) ('auto' leaves R's axial inertia out, so it is static); H at h adds the
// couple -H h, so theta is the simply supported beam's under M0 = -H h and R's force F (above).
BOOST_AUTO_TEST_CASE(longitudinal_force_at_a_height_pushes_and_turns_the_seat) {
    const double a = 0.5, b = kL - a, H = 2000.0, h = 0.3;
    const ModelSpec spec = leaf(a, SupportKind::hinged, SupportKind::pinned);
    const System sys(Model::build(spec));
    BOOST_TEST_REQUIRE(sys.seat_axial_dof() >= 0);
    Loading L;
    L.longitudinal_force_n = ramp(H);
    L.longitudinal_force_height_m = h;
    const auto r = simulate(sys, newmark(L));
    const double M0 = -H * h;
    BOOST_TEST(r.back().seat_axial_m == H * a / kEA, tt::tolerance(1e-9));
    const double c_mm = (a * a * a + b * b * b) / (3.0 * kEI * kL * kL), c_mf = a * b * (b - a) / (3.0 * kEI * kL);
    BOOST_TEST(r.back().seat_rotation_rad == M0 * c_mm + r.back().spring_force_n * c_mf, tt::tolerance(1e-9));
    BOOST_TEST(r.back().seat_moment_n_m == M0, tt::tolerance(1e-12));
    BOOST_TEST(std::abs(r.back().energy_balance_error_j) < 1e-9 * r.back().strain_energy_j);
}

// The axle's pitch inertia J on a symmetric leaf (seat at the centre: the windup, antisymmetric, does
// not move w): a constant moment M0 from t = 0 makes the oscillator J theta'' + k theta = M0,
// theta = (M0 / k) (1 - cos omega t), k = 3 E I L^2 / (a^3 + b^3) = 12 E I / L (the couple's closed
// form above), omega = sqrt(k / J). Average-acceleration Newmark keeps the energy of a linear
// oscillator, so the largest theta is 2 M0 / k up to the sampling of the peak (1 - cos(pi / 200) ~ 1e-4
// at 200 steps per period), and its time is half the period lengthened by (omega dt)^2 / 12 (~1e-4),
// within a step of T / 2.
BOOST_AUTO_TEST_CASE(pitch_inertia_makes_the_windup_oscillator) {
    const double M0 = 40.0, J = 2.0;
    ModelSpec spec = leaf(0.5 * kL);
    spec.rigid_body.pitch_inertia_kg_m2 = J;
    const System sys(Model::build(spec));
    const double k = 12.0 * kEI / kL, omega = std::sqrt(k / J), T = 2.0 * kPi / omega;
    Loading L;
    L.seat_moment_n_m = constant(M0);
    const auto r = simulate(sys, newmark(L, T, T / 200.0));
    double peak = 0.0, t_peak = 0.0, balance = 0.0;
    for (const auto& x : r) {
        if (x.seat_rotation_rad > peak) peak = x.seat_rotation_rad, t_peak = x.t_s;
        balance = std::max(balance, std::abs(x.energy_balance_error_j));
        BOOST_TEST(std::abs(x.w_m) < 1e-12 * M0 / k * kL);
    }
    BOOST_TEST(peak == 2.0 * M0 / k, tt::tolerance(2e-4));
    BOOST_TEST(std::abs(t_peak - 0.5 * T) <= T / 200.0 + 1e-12);
    BOOST_TEST(balance < 1e-9 * M0 * 2.0 * M0 / k);  // the moment's work is the kinetic and strain energy
}

// Bad input gets a named error.
BOOST_AUTO_TEST_CASE(bad_windup_input_is_refused_by_name) {
    const ModelSpec spec = leaf(0.5);
    Loading both = windup_rig(0.01, true);
    both.seat_moment_n_m = constant(1.0);
    BOOST_TEST(refusal(spec, newmark(both)) == "loading.seat_moment_n_m");

    Loading height;
    height.longitudinal_force_n = constant(1.0);
    height.longitudinal_force_height_m = std::nan("");
    BOOST_TEST(refusal(spec, newmark(height)) == "loading.longitudinal_force_height_m");

    Loading push;  // the seat locates the stack (pinned ends, 'auto'): no axial DOF for H
    push.longitudinal_force_n = constant(1.0);
    BOOST_TEST(refusal(spec, newmark(push)) == "loading.longitudinal_force_n");

    ModelSpec half = leaf(0.5 * kL);
    half.symmetry = Symmetry::half;
    Loading moment;
    moment.seat_moment_n_m = constant(1.0);
    BOOST_TEST(refusal(half, newmark(moment)) == "loading.seat_moment_n_m");
    BOOST_TEST(refusal(half, newmark(windup_rig(0.01, false))) == "loading.seat_rotation_rad");
    ModelSpec half_j = half;
    half_j.rigid_body.pitch_inertia_kg_m2 = 1.0;
    BOOST_TEST(refusal(half_j, newmark(Loading{})) == "rigid_body.pitch_inertia_kg_m2");
    ModelSpec negative_j = spec;
    negative_j.rigid_body.pitch_inertia_kg_m2 = -1.0;
    BOOST_TEST(refusal(negative_j, newmark(Loading{})) == "rigid_body.pitch_inertia_kg_m2");

    ModelSpec unlocated = spec;  // 'free' with pinned ends: nothing holds the stack axially
    unlocated.rigid_body.axial = SeatAxial::free;
    BOOST_TEST(refusal(unlocated, newmark(Loading{})) == "rigid_body.axial");

    Loading late = windup_rig(0.01, false);  // theta_R(0) must be 0
    late.seat_rotation_rad->values[0] = 0.001;
    BOOST_TEST(refusal(spec, newmark(late)) == "loading.seat_rotation_rad");

    SimulationOptions closed = newmark(moment);  // a stepper that does not take seat loads names them
    closed.mode = Mode::closed_form;
    BOOST_TEST(refusal(spec, closed) == "loading.seat_moment_n_m");
    closed.loading = windup_rig(0.01, true);
    BOOST_TEST(refusal(spec, closed) == "loading.seat_rotation_rad");
}
