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

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>
#include <utility>

#include "single_leaf.hpp"
#include "windup_cases.hpp"
#include "stackbeam/errors.hpp"
#include "stackbeam/fe/system.hpp"
#include "stackbeam/io/scenario.hpp"
#include "stackbeam/time/simulation.hpp"
#include "stackbeam/time/stepper.hpp"
#include "test_support.hpp"

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

using testing::constant;
using testing::ramp;

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

/// The InputError of parsing `text` as "test.toml": its field and message ("accepted" if none).
const auto file_refusal = stackbeam::testing::scenario_refusal;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// "test.toml:LINE:" of the line that starts with `key` in `text` (1-based).
std::string line_of(const std::string& text, const std::string& key) {
    const auto pos = text.find("\n" + key);
    BOOST_TEST_REQUIRE(pos != std::string::npos);
    return "test.toml:" + std::to_string(2 + std::count(text.begin(), text.begin() + static_cast<long>(pos), '\n')) + ":";
}

/// A one-leaf spring file with the seat off centre and `loading` as its [loading] tables.
std::string leaf_file(const std::string& loading, const std::string& symmetry = "full", double seat_m = 0.5) {
    return R"(
[[leaves]]
length_m = 1.2
height_m = 0.01
width_m = 0.05
youngs_modulus_pa = 206e9
left_support = ")" + std::string(symmetry == "half" ? "pinned" : "hinged") + R"("
right_support = "pinned"

[rigid_body]
mass_kg = 1.0
x_m = )" + std::to_string(seat_m) + R"(

)" + loading + R"(

[mesh]
element_length_m = 0.05
symmetry = ")" + symmetry + R"("

[integrator]
mode = "newmark"
dt_s = 0.1
t_end_s = 1.0
)";
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

/// A two-leaf stack: the main leaf (0) from 0 to kL on pinned ends, a shorter leaf (1) of `lower_m`
/// below it, centred on x = c, free ends; the seat at `seat_m` ties both; one interface of `law`, mu.
ModelSpec two_leaves(double seat_m, double lower_m, double c, InterfaceLaw law, double mu = 0.0) {
    return testing::with_lower_leaf(leaf(seat_m), lower_m, c, law, mu);
}

/// M / theta of the windup rig at theta [N m/rad] on `spec` (newmark, massless leaves), and the
/// largest departure from antisymmetry about the seat of every leaf's v [m] with the largest |v|.
struct Windup {
    double stiffness = 0.0, w = 0.0, asymmetry = 0.0, largest = 0.0;
};
Windup windup_of(const ModelSpec& spec, double theta) {
    const System sys(Model::build(spec));
    const auto stepper = make_stepper(sys, newmark(windup_rig(theta, false)));
    for (int i = 0; i < 10; ++i) stepper->advance();
    Windup out;
    out.stiffness = stepper->current().seat_moment_n_m / stepper->current().seat_rotation_rad;
    out.w = stepper->current().w_m;
    const double xr = spec.rigid_body.x_m;
    for (const LeafNodes& l : stepper->nodes())
        for (std::size_t i = 0; i < l.x_m.size(); ++i) {
            out.largest = std::max(out.largest, std::abs(l.w_m[i]));
            for (std::size_t j = 0; j < l.x_m.size(); ++j)  // the node mirrored about the seat
                if (std::abs(l.x_m[i] + l.x_m[j] - 2.0 * xr) < 1e-9)
                    out.asymmetry = std::max(out.asymmetry, std::abs(l.w_m[i] + l.w_m[j]));
        }
    return out;
}

}  // namespace

// A symmetric spring with pinned ends and the seat free vertically (statics): a vertical load P at
// the seat bends each half as a cantilever from the unturned seat with P/2 at its end, so the
// vertical rate is k_v = 2 k_c (k_c the half's tip stiffness); a windup moment M turns the seat by
// theta with w = 0 and end reactions -+M/L, each half a cantilever from the turned seat whose end
// must stay at v = 0: theta L/2 = (M/L)/k_c, so M/theta = k_c L^2/2 = k_v (L/2)^2, for any profile
// symmetric about the seat. It holds on the discrete model too (the same half's stiffness both
// times), so to rounding; k_v is System::tied_stiffness_n_per_m() (bonded: every pair tied).
BOOST_AUTO_TEST_CASE(symmetric_spring_winds_up_at_the_vertical_rate_times_the_half_length_squared) {
    const double theta = 0.01, half = 0.5 * kL;
    ModelSpec stack = two_leaves(half, 0.8, half, InterfaceLaw::bonded);
    ModelSpec tapered = leaf(half);  // 12 mm at the seat to 6 mm at the eyes, linearly
    tapered.leaves[0].height_m = 0.0;
    tapered.leaves[0].profile.x_m = {0.0, half, kL};
    tapered.leaves[0].profile.thickness_m = {0.006, 0.012, 0.006};
    for (const ModelSpec& spec : {stack, tapered}) {
        const double k_v = System(Model::build(spec)).tied_stiffness_n_per_m();
        const Windup r = windup_of(spec, theta);
        BOOST_TEST_MESSAGE(spec.leaves.size() << " leaves: windup " << r.stiffness << " N m/rad, k_v (L/2)^2 "
                                              << k_v * half * half);
        BOOST_TEST(r.stiffness == k_v * half * half, tt::tolerance(1e-9));
        BOOST_TEST(std::abs(r.w) < 1e-9 * theta * half);   // w = 0 at the seat
        BOOST_TEST(r.asymmetry < 1e-9 * r.largest);        // v(x_R + s) = -v(x_R - s)
        BOOST_TEST(r.largest > 0.1 * theta * half);        // (the S shape is there)
    }
}

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
    for (const Mode mode : {Mode::newmark, Mode::closed_form}) {  // (the latter condenses theta_R)
        SimulationOptions o = newmark(moment);
        o.mode = mode;
        const auto r = simulate(sys, o);
        const double c_mf = a * b * (b - a) / (3.0 * kEI * kL), c_ff = a * a * b * b / (3.0 * kEI * kL);
        const double F = r.back().spring_force_n;
        BOOST_TEST(std::abs(F) > 1e-3 * M0 / kL);  // R does bounce: the check below is not the static one again
        BOOST_TEST(r.back().seat_rotation_rad == theta + F * c_mf, tt::tolerance(1e-9));
        BOOST_TEST(r.back().w_m == v + F * c_ff, tt::tolerance(1e-9));
        BOOST_TEST(r.back().seat_moment_n_m == M0, tt::tolerance(1e-12));
        // the moment's work is R's kinetic energy and the strain energy: Newmark books it as it steps
        // (its trapezoidal rule), so to rounding; mode closed-form moves R exactly within the step but books
        // the moment's work by the trapezoidal rule on theta_R, which R's bounce moves within the step
        // (here 2.5 periods a step): checked below at finer steps
        if (mode == Mode::newmark) BOOST_TEST(std::abs(r.back().energy_balance_error_j) < 1e-9 * r.back().strain_energy_j);
    }
    // mode closed-form's balance converges at second order in dt (the trapezoidal rule's): measured
    // 3.5e-9 J largest at 1 ms (U = 0.1 J) and a quarter of it at 0.5 ms
    double worst[2] = {0.0, 0.0};
    for (int k = 0; k < 2; ++k) {
        SimulationOptions o = newmark(moment, 1.0, k == 0 ? 1e-3 : 5e-4);
        o.mode = Mode::closed_form;
        for (const auto& x : simulate(sys, o)) worst[k] = std::max(worst[k], std::abs(x.energy_balance_error_j));
    }
    BOOST_TEST(worst[0] < 1e-7);
    BOOST_TEST(worst[0] / worst[1] > 3.5);
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
    // The fibre stresses beside the seat are the statics' M c / I: the moment M0 x / L left of the
    // seat, -M0 (L - x) / L right of it, sigma = -/+ 6 M / (b t^2) at the top/bottom fibre (sagging M
    // positive compresses the top). Pinned ends carry no axial force: N = 0 (to round-off).
    const LeafStresses& leaf0 = s.leaves[0];
    for (const int j : {i - 1, i + 1}) {
        const double m = j < i ? M0 * x[j] / kL : -M0 * (kL - x[j]) / kL, z = 6.0 / (kB * kT * kT);
        BOOST_TEST(std::abs(leaf0.axial_force_n[j]) < 1e-9 * M0 / kT);
        BOOST_TEST(leaf0.top_stress_pa[j] == -m * z, tt::tolerance(1e-9));
        BOOST_TEST(leaf0.bottom_stress_pa[j] == m * z, tt::tolerance(1e-9));
    }
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

    // the steppers that do not take a part name it
    SimulationOptions closed = newmark(moment);
    closed.mode = Mode::closed_form;
    BOOST_TEST(refusal(spec, closed) == "accepted");
    ModelSpec with_j = spec;
    with_j.rigid_body.pitch_inertia_kg_m2 = 1.0;
    BOOST_TEST(refusal(with_j, closed) == "rigid_body.pitch_inertia_kg_m2");  // theta_R condensed, no inertia
    Loading held = moment;
    held.kind = LoadingKind::prescribed_displacement;
    held.displacement_m = constant(0.0);
    closed.loading = held;  // seat loads with the vertical rig, and the windup rig: theta_R held (decision 069)
    BOOST_TEST(refusal(spec, closed) == "accepted");
    closed.loading = windup_rig(0.01, true);
    BOOST_TEST(refusal(spec, closed) == "accepted");
    SimulationOptions cvode = newmark(moment);
    cvode.mode = Mode::cvode;  // massless leaves: cvode-massless takes seat loads (decision 069), not the windup rig
    BOOST_TEST(refusal(spec, cvode) == "accepted");
    cvode.loading = windup_rig(0.01, false);
    BOOST_TEST(refusal(spec, cvode) == "loading.seat_rotation_rad");
}

// A windup rig's loop with friction (the vertical rig holding a two-leaf spring at w0, so the leaves
// press on each other; mu = 0.3, kappa = mu t / h = 0.06): rate independent, so from the second cycle
// on each cycle repeats the one before (the pairs' states and forces to the solver's tolerance); over a
// closed cycle the strain energy returns, so the loop's area, the rig's work, is the friction work of
// the cycle. The moment at the loop's tip lies between the frictionless spring's (no shear between
// the leaves) and the bonded one's (every pair tied).
BOOST_AUTO_TEST_CASE(friction_windup_loop_closes_and_its_area_is_the_friction_work) {
    const double w0 = 0.05, theta_a = 0.01;
    const int per_cycle = 100, cycles = 3;
    auto run = [&](InterfaceLaw law, double mu) {
        Loading L;
        L.kind = LoadingKind::prescribed_displacement;
        L.displacement_m = constant(w0);
        TimeFunction tri;
        tri.shape = TimeFunction::Shape::triangle;
        tri.amplitude = theta_a;
        tri.frequency_hz = 1.0;
        L.seat_rotation_rad = tri;
        const System sys(Model::build(two_leaves(0.6, 0.8, 0.6, law, mu)));
        return simulate(sys, newmark(L, cycles, 1.0 / per_cycle));
    };
    const auto r = run(InterfaceLaw::coulomb, 0.3);
    BOOST_TEST_REQUIRE(r.size() == static_cast<std::size_t>(cycles * per_cycle + 1));
    // the third cycle repeats the second; its area by the trapezoidal rule (the rig's work as the stepper books it)
    const auto [amplitude, repeat, area, friction] = testing::windup_loop(r, per_cycle);
    BOOST_TEST_MESSAGE("moment amplitude " << amplitude << " N m, cycle 3 - cycle 2 " << repeat << " N m, area " << area
                                           << " J, friction work " << friction << " J, slipping pairs at the tip "
                                           << r[2 * per_cycle + per_cycle / 4].n_slip);
    BOOST_TEST(repeat < 1e-6 * amplitude);
    BOOST_TEST(area > 1e-3 * amplitude * theta_a);  // a loop, not a line
    BOOST_TEST(area == friction, tt::tolerance(1e-6));
    // the loop's tip between the frictionless and the bonded spring's moment there
    const int tip = 2 * per_cycle + per_cycle / 4;
    const double frictionless = run(InterfaceLaw::coulomb, 0.0)[tip].seat_moment_n_m;
    const double bonded = run(InterfaceLaw::bonded, 0.0)[tip].seat_moment_n_m;
    BOOST_TEST_MESSAGE("tip moment: frictionless " << frictionless << ", friction " << r[tip].seat_moment_n_m << ", bonded "
                                                   << bonded << " N m");
    BOOST_TEST(frictionless < r[tip].seat_moment_n_m);
    BOOST_TEST(r[tip].seat_moment_n_m < bonded);
}

// Every stepper that takes the windup rig gives the same response on a problem they share: the
// flat leaf with the seat held vertically, turned from rest by theta = A (1 - cos 2 pi f t) (smooth,
// as leaf mass needs), read at its peak t = 1 / (2 f). Massless leaves: 3 E I (1/a + 1/b) theta at
// every step (static). Steel leaves: the leaves' inertia adds a quasi-static error of order
// (f / f_1)^2, f_1 ~ 74 Hz the lowest mode with the seat held (the 0.7 m half as a propped cantilever,
// 15.42 / (2 pi l^2) sqrt(E I / rho A)), so ~5e-5 at f = 0.5 Hz, plus Newmark's (omega dt)^2 on the
// rig's slow motion (1e-5 at dt = 1 ms): 1e-3 with a margin of 20.
BOOST_AUTO_TEST_CASE(every_stepper_of_the_windup_rig_gives_the_same_moment) {
    const double a = 0.5, b = kL - a, A = 0.005, f = 0.5;
    Loading L;
    L.kind = LoadingKind::prescribed_displacement;
    L.displacement_m = constant(0.0);
    TimeFunction from_rest;
    from_rest.shape = TimeFunction::Shape::harmonic;
    from_rest.mean = from_rest.amplitude = A;
    from_rest.frequency_hz = f;
    from_rest.phase_rad = -0.5 * kPi;
    L.seat_rotation_rad = from_rest;
    const double expected = 3.0 * kEI * (1.0 / a + 1.0 / b) * 2.0 * A;
    // newmark massless and massive, and closed-form (massless: theta_R held in its condensation)
    for (const auto& [density, mode] : {std::pair{0.0, Mode::newmark}, std::pair{7850.0, Mode::newmark},
                                        std::pair{0.0, Mode::closed_form}}) {
        ModelSpec spec = leaf(a);
        spec.leaves[0].density_kg_per_m3 = density;
        const System sys(Model::build(spec));
        SimulationOptions o = newmark(L, 0.5 / f, 1e-3);
        o.mode = mode;
        const auto r = simulate(sys, o);
        BOOST_TEST_MESSAGE(to_string(mode) << ", density " << density << ": moment " << r.back().seat_moment_n_m << " N m at "
                                      << r.back().seat_rotation_rad << " rad, balance " << r.back().energy_balance_error_j << " J");
        BOOST_TEST(r.back().seat_rotation_rad == 2.0 * A, tt::tolerance(1e-12));
        BOOST_TEST(r.back().seat_moment_n_m == expected, tt::tolerance(density > 0.0 ? 1e-3 : 1e-9));
        BOOST_TEST(std::abs(r.back().energy_balance_error_j) < 1e-6 * r.back().strain_energy_j);
    }
}

// The scenario file of an asymmetric braking case (scenarios/asymmetric_braking.toml): its keys as
// written, the writer's round trip, and the run: the energy balance closes (massless leaves, static
// contact with friction at each step: to the solver's tolerance, here 1e-9 of the external work).
BOOST_AUTO_TEST_CASE(asymmetric_braking_file_reads_writes_and_runs) {
    const Scenario s = load_scenario(std::string(STACKBEAM_SOURCE_DIR) + "/scenarios/asymmetric_braking.toml");
    const Loading& L = s.simulation.loading;
    BOOST_TEST(s.model.rigid_body.pitch_inertia_kg_m2 == 6.0);
    BOOST_TEST((s.model.rigid_body.axial == SeatAxial::free));
    BOOST_TEST(L.longitudinal_force_height_m == -0.45);
    BOOST_TEST_REQUIRE(L.longitudinal_force_n.has_value());
    BOOST_TEST(L.longitudinal_force_n->values.back() == 8000.0);
    BOOST_TEST(!L.seat_moment_n_m.has_value());
    const Scenario again = parse_scenario(to_toml(s), "again.toml");
    BOOST_TEST(again.model.rigid_body.pitch_inertia_kg_m2 == 6.0);
    BOOST_TEST((again.model.rigid_body.axial == SeatAxial::free));
    BOOST_TEST(again.simulation.loading.longitudinal_force_height_m == -0.45);
    BOOST_TEST_REQUIRE(again.simulation.loading.longitudinal_force_n.has_value());
    BOOST_TEST(again.simulation.loading.longitudinal_force_n->times_s == L.longitudinal_force_n->times_s);

    const System sys(Model::build(s.model));
    const auto r = simulate(sys, s.simulation);
    double balance = 0.0;
    for (const auto& x : r) balance = std::max(balance, std::abs(x.energy_balance_error_j));
    BOOST_TEST_MESSAGE("braked: w " << r.back().w_m << " m, theta_R " << r.back().seat_rotation_rad << " rad, u_R "
                                    << r.back().seat_axial_m << " m, moment " << r.back().seat_moment_n_m << " N m");
    BOOST_TEST(r.back().seat_moment_n_m == 8000.0 * 0.45, tt::tolerance(1e-12));  // -H h
    BOOST_TEST(balance < 1e-9 * r.back().external_work_j);
    // braking winds the seat counter-clockwise beyond where the axle load alone left it (t = 0.5 s)
    BOOST_TEST(r.back().seat_rotation_rad > r[500].seat_rotation_rad);
}

// The windup keys refused in a file with their key path and line.
BOOST_AUTO_TEST_CASE(windup_keys_refused_at_their_line) {
    // the refusal of `text`: by `field`, at the line that starts with `key`, saying `phrase`
    auto refused = [](const std::string& text, const std::string& field, const std::string& key, const std::string& phrase) {
        const auto r = file_refusal(text);
        BOOST_TEST(r.first == field);
        BOOST_TEST(contains(r.second, line_of(text, key)));
        BOOST_TEST(contains(r.second, phrase));
    };
    const std::string rig = "[loading]\nkind = \"prescribed-displacement\"\n[loading.displacement_m]\nshape = \"constant\"\n"
                            "mean = 0.0\n[loading.seat_rotation_rad]\nshape = \"triangle\"\namplitude = 0.01\nfrequency_hz = 1.0\n";
    BOOST_TEST(file_refusal(leaf_file(rig)).first == "accepted");
    refused(leaf_file(rig + "[loading.seat_moment_n_m]\nshape = \"constant\"\nmean = 10.0\n"), "loading.seat_moment_n_m",
            "[loading.seat_moment_n_m]", "prescribed seat rotation");
    const std::string free_seat = "[loading]\nkind = \"initial-conditions\"\n";
    refused(leaf_file(free_seat + "longitudinal_force_height_m = nan\n[loading.longitudinal_force_n]\nshape = \"constant\"\n"
                                  "mean = 1.0\n"),
            "loading.longitudinal_force_height_m", "longitudinal_force_height_m", "finite");
    refused(leaf_file(free_seat + "[loading.seat_moment_n_m]\nshape = \"constant\"\nmean = 10.0\n", "half", 0.6),
            "loading.seat_moment_n_m", "[loading.seat_moment_n_m]", "half model");
    for (const auto& [key, line, phrase] : {std::tuple<std::string, std::string, std::string>{"axial", "axial = \"sideways\"\n", "auto"},
                                            {"pitch_inertia_kg_m2", "pitch_inertia_kg_m2 = -2.0\n", "-2"}}) {
        std::string text = leaf_file(free_seat);
        text.insert(text.find("x_m = "), line);
        refused(text, "rigid_body." + key, key, phrase);
    }
}

// The seat moment under every stepper that takes it, on a problem they share: a steel leaf with the
// axle's pitch inertia (J = 0.5 kg m^2, so a windup mode near 20 Hz) under M = M0 (1 - cos 2 pi f t) at
// f = 1 Hz, read at its peak t = 0.5 s. Newmark at dt = 0.2 ms (a phase error (omega dt)^2 / 12 of
// 5e-5 per radian on the windup mode, far less on the slow load) and CVODE at its default
// tolerances integrate the same equations; the response is the quasi-static one plus the modes'
// transients, ~(f / f_J)^2 = 2.5e-3 of it, which each integrator follows to well under a tenth: 1e-4
// of the rotation between them; so does cvode's modal stepper (the modes above its cut quasi-static,
// ~(f / f_cut)^2 off; J is in the retained modes' mass). Newmark with massless leaves has R's and J's
// inertia only (the leaves' own inertia, ~(f / f_1)^2 ~ 1e-4, and the mode's transient differ): 5e-3.
BOOST_AUTO_TEST_CASE(every_stepper_of_the_seat_moment_gives_the_same_rotation) {
    const double a = 0.5, M0 = 20.0;
    Loading L;
    TimeFunction from_rest;
    from_rest.shape = TimeFunction::Shape::harmonic;
    from_rest.mean = from_rest.amplitude = M0;
    from_rest.frequency_hz = 1.0;
    from_rest.phase_rad = -0.5 * kPi;
    L.seat_moment_n_m = from_rest;
    std::vector<double> theta;
    // newmark, cvode's massive stack and its modal stepper (J among the retained modes' masses), newmark massless
    for (const Mode mode : {Mode::newmark, Mode::cvode, Mode::cvode, Mode::newmark}) {
        const std::size_t run = theta.size();
        ModelSpec spec = leaf(a);
        spec.rigid_body.pitch_inertia_kg_m2 = 0.5;
        spec.leaves[0].density_kg_per_m3 = run < 3 ? 7850.0 : 0.0;
        const System sys(Model::build(spec));
        SimulationOptions o = newmark(L, 0.5, mode == Mode::newmark ? 2e-4 : 0.05);
        o.mode = mode;
        if (run == 2) o.cvode.leaf_inertia = LeafInertia::modal;
        const auto r = simulate(sys, o);
        BOOST_TEST(r.back().seat_moment_n_m == 2.0 * M0, tt::tolerance(1e-12));
        BOOST_TEST(std::abs(r.back().energy_balance_error_j) < 1e-6 * r.back().strain_energy_j);
        theta.push_back(r.back().seat_rotation_rad);
        BOOST_TEST_MESSAGE(to_string(mode) << ": theta_R " << theta.back() << " rad, balance " << r.back().energy_balance_error_j);
    }
    BOOST_TEST(theta[1] == theta[0], tt::tolerance(1e-4));
    BOOST_TEST(theta[2] == theta[0], tt::tolerance(1e-4));  // the modal stepper: its cut's inertia ~(f / f_cut)^2
    BOOST_TEST(theta[3] == theta[0], tt::tolerance(5e-3));
}

// Mode closed-form condenses theta_R (System::SeatCondensation) on either contact path: the dense
// one shifts the contact offsets by B S and R's force by -g^T S, the sparse one carries S on the
// stiffness form's right-hand side; both solve the same step, so they agree to the solver's
// tolerance (1e-9 relative here). Newmark (massless leaves) keeps theta_R as a DOF and gives the
// same static part; R's bounce, which the ramps' start excites at ~(1 / omega) / 1 s ~ 3e-3 of
// the deflection (omega = sqrt(k/m) ~ 300 rad/s), it integrates with its period error, so 1e-2
// between the two. The spring: two leaves with friction (mu = 0.3), the seat off centre, a
// vertical force and a seat moment ramped in together.
BOOST_AUTO_TEST_CASE(closed_form_takes_the_seat_moment_on_both_contact_paths) {
    const ModelSpec spec = two_leaves(0.5, 0.8, 0.55, InterfaceLaw::coulomb, 0.3);
    const System sys(Model::build(spec));
    Loading L;
    L.kind = LoadingKind::applied_force;
    L.force_n = ramp(2000.0);
    L.seat_moment_n_m = ramp(100.0);
    std::vector<StepRecord> last;
    for (int k = 0; k < 3; ++k) {
        SimulationOptions o = newmark(L, 1.0, 1e-3);
        o.mode = k < 2 ? Mode::closed_form : Mode::newmark;
        o.contact_path = k == 1 ? ContactPath::sparse : ContactPath::dense;
        const auto r = simulate(sys, o);
        last.push_back(r.back());
        BOOST_TEST_MESSAGE("run " << k << ": w " << r.back().w_m << " m, theta_R " << r.back().seat_rotation_rad << " rad, slipping "
                                  << r.back().n_slip << ", balance " << r.back().energy_balance_error_j << " J of "
                                  << r.back().external_work_j);
        BOOST_TEST(std::abs(r.back().energy_balance_error_j) < 1e-4 * r.back().external_work_j);
    }
    BOOST_TEST(last[1].seat_rotation_rad == last[0].seat_rotation_rad, tt::tolerance(1e-9));
    BOOST_TEST(last[1].w_m == last[0].w_m, tt::tolerance(1e-9));
    BOOST_TEST(last[1].spring_force_n == last[0].spring_force_n, tt::tolerance(1e-9));
    BOOST_TEST(last[2].seat_rotation_rad == last[0].seat_rotation_rad, tt::tolerance(1e-2));
    BOOST_TEST(last[2].w_m == last[0].w_m, tt::tolerance(1e-2));
}

// Asymmetric springs with every end kind, on the full model: the seat at 0.45 m of a 1.2 m main leaf,
// a 0.7 m second leaf from 0.2 m (halves 0.25 and 0.45 m), bonded. Maxwell-Betti on the linear
// spring: the seat's flexibility [theta_R; w] = C [M; F] is symmetric, so the rotation per unit
// vertical force with no moment (mode closed-form's vertical rig: w prescribed, theta_R free,
// F the load cell's force) equals the deflection per unit moment with no vertical force (newmark's
// windup rig with the seat free vertically: M read, w free). Two modes, two rigs, one identity: to
// rounding (1e-8 relative, a few solves of the same matrix). The seat turns under the vertical
// load alone (the S shape of an asymmetric spring).
BOOST_AUTO_TEST_CASE(asymmetric_springs_with_every_end_kind_are_reciprocal) {
    const std::vector<SupportKind> kinds = {SupportKind::pinned, SupportKind::fixed, SupportKind::hinged,
                                            SupportKind::shackle, SupportKind::bushing};
    for (const SupportKind kind : kinds) {
        ModelSpec spec = two_leaves(0.45, 0.7, 0.55, InterfaceLaw::bonded);
        LeafSpec& main = spec.leaves[0];
        main.left_support = main.right_support = kind;
        for (LeafEndSpec* end : {&main.left_end, &main.right_end}) {
            end->eye_offset_m = kind == SupportKind::pinned || kind == SupportKind::fixed ? 0.0 : 0.015;
            if (kind == SupportKind::bushing) {
                end->bushing_x_n_per_m = 2e6;
                end->bushing_y_n_per_m = 5e5;
                end->bushing_rotation_n_m_per_rad = 100.0;
            }
        }
        if (kind == SupportKind::shackle) main.left_support = SupportKind::hinged;  // a fixed eye and a shackle
        main.right_end.shackle_angle_rad = kind == SupportKind::shackle ? 0.2 : 0.0;
        const System sys(Model::build(spec));

        Loading vertical;  // closed-form's rig to 10 mm
        vertical.kind = LoadingKind::prescribed_displacement;
        vertical.displacement_m = ramp(0.01);
        SimulationOptions o = newmark(vertical);
        o.mode = Mode::closed_form;
        const StepRecord v = simulate(sys, o).back();
        const StepRecord r = simulate(sys, newmark(windup_rig(0.01, false))).back();
        const double c_mf = v.seat_rotation_rad / v.spring_force_n, c_fm = r.w_m / r.seat_moment_n_m;
        BOOST_TEST_MESSAGE(to_string(kind) << ": theta_R/F " << c_mf << " rad/N, w/M " << c_fm << " m/(N m), u_R "
                                           << v.seat_axial_m << " m");
        BOOST_TEST(std::abs(v.seat_rotation_rad) > 1e-3 * 0.01);  // the asymmetric spring's seat turns
        BOOST_TEST(c_mf == c_fm, tt::tolerance(1e-8));
        BOOST_TEST(std::abs(r.energy_balance_error_j) < 1e-9 * r.strain_energy_j);
    }
}

// The seat loads go with every vertical loading, in every mode that takes them, and the energy
// balance closes over each (a balance that must close: the seat loads' work, the vertical load's and
// the strain, kinetic and friction energies). The two-leaf spring with friction, the seat off centre,
// a smooth seat moment and a longitudinal force at a height (a hinged eye locates the spring), 0.5 s.
// Bounds: newmark books every work by its own trapezoidal rule, so to the contact solver's tolerance
// (1e-9 of the external work); closed-form moves R exactly within a step but books the seat loads'
// work by the trapezoidal rule (second order, decision 063): 1e-5 at dt = 0.5 ms; cvode's massless,
// massive and modal steppers integrate the work as a state to their tolerances: 1e-6.
BOOST_AUTO_TEST_CASE(seat_loads_go_with_every_vertical_loading) {
    TimeFunction smooth;  // from rest: mean = amplitude, phase -pi/2
    smooth.shape = TimeFunction::Shape::harmonic;
    smooth.frequency_hz = 1.0;
    smooth.phase_rad = -0.5 * kPi;
    for (const double density : {0.0, 7850.0}) {
        ModelSpec spec = two_leaves(0.5, 0.8, 0.55, InterfaceLaw::coulomb, 0.3);
        spec.leaves[0].left_support = SupportKind::hinged;  // locates the spring: the seat slides ('auto')
        for (auto& l : spec.leaves) l.density_kg_per_m3 = density;
        if (density > 0.0)  // leaf mass with the vertical rig needs an elastic layer (the impact law)
            spec.interfaces[0].contact = InterfaceContact::elastic;
        const System sys(Model::build(spec));
        for (const LoadingKind kind : {LoadingKind::applied_force, LoadingKind::initial_conditions, LoadingKind::base_excitation,
                                       LoadingKind::prescribed_displacement}) {
            Loading L;
            L.kind = kind;
            TimeFunction vertical = smooth;
            vertical.mean = vertical.amplitude = kind == LoadingKind::applied_force ? 1000.0 : 0.005;
            L.force_n = vertical;
            L.displacement_m = vertical;
            if (kind == LoadingKind::initial_conditions) L.gravity_m_per_s2 = 9.81;
            TimeFunction moment = smooth, push = smooth;
            moment.mean = moment.amplitude = 20.0;
            push.mean = push.amplitude = 200.0;
            L.seat_moment_n_m = moment;
            L.longitudinal_force_n = push;
            L.longitudinal_force_height_m = -0.3;
            std::vector<std::pair<Mode, double>> modes = {{Mode::newmark, 1e-9}};
            if (density == 0.0 && kind != LoadingKind::prescribed_displacement) {
                modes.push_back({Mode::closed_form, 1e-5});
                modes.push_back({Mode::cvode, 1e-6});  // cvode-massless
            }
            if (density > 0.0 && kind != LoadingKind::prescribed_displacement) modes.push_back({Mode::cvode, 1e-6});
            if (density == 0.0 && kind == LoadingKind::prescribed_displacement)  // newmark massless has no vertical rig
                modes = {{Mode::closed_form, 1e-5}};
            for (const auto& [mode, bound] : modes) {
                SimulationOptions o = newmark(L, 0.5, 5e-4);
                o.mode = mode;
                const auto r = simulate(sys, o);
                double balance = 0.0, work = 0.0;
                for (const auto& x : r) {
                    balance = std::max(balance, std::abs(x.energy_balance_error_j));
                    work = std::max(work, std::abs(x.external_work_j));
                }
                BOOST_TEST_MESSAGE("density " << density << ", " << to_string(kind) << ", " << to_string(mode) << ": balance "
                                              << balance << " J of " << work << " J, theta_R " << r.back().seat_rotation_rad
                                              << " rad, u_R " << r.back().seat_axial_m << " m");
                BOOST_TEST(balance < bound * work);
                BOOST_TEST(r.back().seat_moment_n_m == 40.0 + 400.0 * 0.3, tt::tolerance(1e-9));
                BOOST_TEST(std::abs(r.back().seat_axial_m) > 0.0);
            }
        }
    }
}
