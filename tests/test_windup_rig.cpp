// The windup rig and seat loads with the vertical rig in mode closed-form (decision 069): theta_R held
// in the seat's condensation (C_h = C' - a b b^T, c_h, k_h) on the dense path, theta_R (and w) taken out
// of the stiffness form on the sparse one. Proved against newmark with massless leaves (theta_R a DOF
// of its own, held by its rig), between the two contact paths, against a closed form, by reciprocity
// between the two ways of loading the seat, and by the friction loop's area against its friction work.
//
// Tolerances. With massless leaves both modes solve, at each step, the same static contact problem
// with the same anchors (friction: the same incremental problem), each exactly by its own
// factorisation (C' and its rank-one update here, the reduced stiffness with the rig's rows taken
// out in newmark): they agree to the rounding of those solves and of the condensation's two solves,
// ~1e-12 relative on a few hundred DOFs, asserted at 1e-8 (the brief's bound; the messages print
// the figures). Dense against sparse: the same problem in two forms (step.hpp), 1e-9 as the other
// closed-form path tests.
#define BOOST_TEST_MODULE windup_rig
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "single_leaf.hpp"
#include "windup_cases.hpp"
#include "stackbeam/errors.hpp"
#include "stackbeam/fe/system.hpp"
#include "stackbeam/time/newmark_stepper.hpp"
#include "stackbeam/time/simulation.hpp"
#include "stackbeam/time/stepper.hpp"

using namespace stackbeam;
namespace tt = boost::test_tools;

namespace {

constexpr double kL = 1.2, kT = 0.01, kB = 0.05, kE = 206e9, kPi = 3.14159265358979323846;
const double kEI = kE * kB * kT * kT * kT / 12.0;

using testing::two_leaves;  // windup_cases.hpp

using testing::constant;
using testing::ramp;
using testing::triangle;

/// The three loadings of the windup rig: (0) the seat held vertically at 20 mm and wound +-0.01 rad
/// (the FMU's: both rigs); (1) the seat free vertically under a 2 kN ramp, wound; (2) as (1) with a
/// longitudinal force at a height (its moment joins the rig's, H moves u_R).
Loading windup_loading(int which) {
    Loading L;
    L.seat_rotation_rad = triangle(0.01);
    if (which == 0) {
        L.kind = LoadingKind::prescribed_displacement;
        L.displacement_m = constant(0.02);
    } else {
        L.kind = LoadingKind::applied_force;
        L.force_n = ramp(2000.0);
    }
    if (which == 2) {
        L.longitudinal_force_n = ramp(500.0);
        L.longitudinal_force_height_m = -0.3;
    }
    return L;
}

/// theta = A (1 - cos 2 pi f t) [rad]: from rest, smooth (the windup rig with leaf mass).
TimeFunction from_rest(double A, double f) {
    TimeFunction r;
    r.shape = TimeFunction::Shape::harmonic;
    r.mean = r.amplitude = A;
    r.frequency_hz = f;
    r.phase_rad = -0.5 * kPi;
    return r;
}

/// `spec` with steel leaves and elastic contact (the windup rig with leaf mass in newmark: elastic rows).
ModelSpec steel(ModelSpec spec) {
    for (auto& l : spec.leaves) l.density_kg_per_m3 = 7850.0;
    for (auto& i : spec.interfaces) i.contact = InterfaceContact::elastic;
    return spec;
}

std::vector<StepRecord> run(const System& sys, const Loading& L, Mode mode, ContactPath path = ContactPath::dense,
                            double t_end_s = 1.0, double dt_s = 0.01) {
    SimulationOptions o;
    o.mode = mode;
    o.contact_path = path;
    o.dt_s = dt_s;
    o.t_end_s = t_end_s;
    o.loading = L;
    return simulate(sys, o);
}

/// The largest |a_i - b_i| of a record's column over two runs, and the largest |a_i|.
template <class Column>
std::pair<double, double> departure(const std::vector<StepRecord>& a, const std::vector<StepRecord>& b, Column col) {
    BOOST_TEST_REQUIRE(a.size() == b.size());
    double diff = 0.0, scale = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        diff = std::max(diff, std::abs(col(a[i]) - col(b[i])));
        scale = std::max(scale, std::abs(col(a[i])));
    }
    return {diff, scale};
}

}  // namespace

// Closed-form's windup rig against newmark's (massless leaves, every step static in both), on the
// asymmetric two-leaf spring frictionless and with friction (mu = 0.3: a hysteresis loop), for the
// three loadings: the seat moment, w and u_R at every step to 1e-8 of their largest values.
BOOST_AUTO_TEST_CASE(closed_form_windup_rig_matches_newmark_massless) {
    for (const double mu : {0.0, 0.3}) {
        const System sys(Model::build(two_leaves(InterfaceLaw::coulomb, mu)));
        for (int which = 0; which < 3; ++which) {
            const Loading L = windup_loading(which);
            const auto c = run(sys, L, Mode::closed_form);
            const auto n = run(sys, L, Mode::newmark);
            const auto m = departure(c, n, [](const StepRecord& r) { return r.seat_moment_n_m; });
            const auto w = departure(c, n, [](const StepRecord& r) { return r.w_m; });
            const auto u = departure(c, n, [](const StepRecord& r) { return r.seat_axial_m; });
            const auto th = departure(c, n, [](const StepRecord& r) { return r.seat_rotation_rad; });
            BOOST_TEST_MESSAGE("mu " << mu << ", loading " << which << ": moment " << m.first << " of " << m.second
                                     << " N m, w " << w.first << " of " << w.second << " m, u_R " << u.first << " of "
                                     << u.second << " m, slipping at the end " << c.back().n_slip << ", balance "
                                     << c.back().energy_balance_error_j << " J");
            BOOST_TEST(m.first <= 1e-8 * m.second);
            BOOST_TEST(w.first <= 1e-8 * w.second);
            BOOST_TEST(u.first <= 1e-8 * u.second);
            BOOST_TEST(th.first <= 1e-12 * th.second);  // theta_R: the rig's, in both
            BOOST_TEST(std::abs(c.back().spring_force_n - n.back().spring_force_n) <= 1e-8 * std::abs(n.back().spring_force_n));
        }
    }
}

// Both contact paths take the windup rig and the seat loads with the vertical rig and solve the same
// problem: the records agree to 1e-9 relative.
BOOST_AUTO_TEST_CASE(closed_form_windup_rig_dense_and_sparse_agree) {
    const System sys(Model::build(two_leaves(InterfaceLaw::coulomb, 0.3)));
    std::vector<Loading> loadings = {windup_loading(0), windup_loading(1), windup_loading(2)};
    Loading held;  // seat loads with the vertical rig
    held.kind = LoadingKind::prescribed_displacement;
    held.displacement_m = ramp(0.02);
    held.seat_moment_n_m = ramp(100.0);
    held.longitudinal_force_n = ramp(500.0);
    held.longitudinal_force_height_m = -0.3;
    loadings.push_back(held);
    for (std::size_t k = 0; k < loadings.size(); ++k) {
        const auto d = run(sys, loadings[k], Mode::closed_form, ContactPath::dense);
        const auto s = run(sys, loadings[k], Mode::closed_form, ContactPath::sparse);
        for (const auto& col : std::vector<double (*)(const StepRecord&)>{
                 [](const StepRecord& r) { return r.seat_moment_n_m; }, [](const StepRecord& r) { return r.seat_rotation_rad; },
                 [](const StepRecord& r) { return r.w_m; }, [](const StepRecord& r) { return r.spring_force_n; },
                 [](const StepRecord& r) { return r.seat_axial_m; }, [](const StepRecord& r) { return r.strain_energy_j; }}) {
            const auto x = departure(d, s, col);
            BOOST_TEST(x.first <= 1e-9 * x.second, "loading " << k << ": " << x.first << " of " << x.second);
        }
        BOOST_TEST_MESSAGE("loading " << k << ": moment " << d.back().seat_moment_n_m << " N m, theta_R "
                                      << d.back().seat_rotation_rad << " rad, w " << d.back().w_m << " m");
    }
}

// A windup rig's loop with friction in closed-form (the seat held at 20 mm by the vertical rig, mu =
// 0.3): rate independent, so from the second cycle each cycle repeats the one before, and over a
// closed cycle the strain energy returns: the loop's area (the rig's work, booked by the trapezoidal
// rule as the stepper books it) is the cycle's friction work. The energy balance closes at every step
// (quasi-static, the rig's work trapezoidal on a linear path between contact events): 1e-6 of the
// strain energy.
BOOST_AUTO_TEST_CASE(closed_form_friction_windup_loop_area_is_the_friction_work) {
    const int per_cycle = 100, cycles = 3;
    const System sys(Model::build(two_leaves(InterfaceLaw::coulomb, 0.3)));
    const auto r = run(sys, windup_loading(0), Mode::closed_form, ContactPath::dense, cycles, 1.0 / per_cycle);
    BOOST_TEST_REQUIRE(r.size() == static_cast<std::size_t>(cycles * per_cycle + 1));
    const auto [amplitude, repeat, area, friction] = testing::windup_loop(r, per_cycle);
    double balance = 0.0, strain = 0.0;
    for (const auto& x : r) {
        balance = std::max(balance, std::abs(x.energy_balance_error_j));
        strain = std::max(strain, x.strain_energy_j);
    }
    BOOST_TEST_MESSAGE("moment amplitude " << amplitude << " N m, cycle 3 - cycle 2 " << repeat << " N m, area " << area
                                           << " J, friction work " << friction << " J, balance " << balance << " J of "
                                           << strain << " J");
    BOOST_TEST(repeat < 1e-6 * amplitude);
    BOOST_TEST(area > 1e-3 * amplitude * 0.01);  // a loop, not a line
    BOOST_TEST(area == friction, tt::tolerance(1e-6));
    BOOST_TEST(balance < 1e-6 * strain);
}

// Seat loads with the vertical rig (closed-form, theta_R free in the condensation): a single flat
// leaf with pinned ends, the seat held at w = 0 and a moment M ramped in: each half a propped
// cantilever from the turned seat, theta = M / (3 E I (1/a + 1/b)) (exact on the cubic element,
// the seat a node: to rounding, 1e-9), and the load cell reads the halves' end shears' sum,
// 3 E I theta (1/b^2 - 1/a^2) (each half l: 3 E I theta / l^2). Then by reciprocity on the two-leaf
// bonded spring (linear): the windup rig turned to the theta the moment M gave (seat held at 20 mm)
// reads M back and the same load cell force, to the rounding of two condensations (1e-9).
BOOST_AUTO_TEST_CASE(closed_form_takes_seat_loads_with_the_vertical_rig) {
    const double a = 0.5, b = kL - a, M = 40.0;
    const System leaf(Model::build(testing::single_leaf(kL, kT, kB, kE, SupportKind::pinned, SupportKind::pinned, a, kL / 24)));
    Loading L;
    L.kind = LoadingKind::prescribed_displacement;
    L.displacement_m = constant(0.0);
    L.seat_moment_n_m = ramp(M);
    const auto r = run(leaf, L, Mode::closed_form, ContactPath::dense, 1.0, 0.1);
    const double theta = M / (3.0 * kEI * (1.0 / a + 1.0 / b));
    BOOST_TEST_MESSAGE("theta_R " << r.back().seat_rotation_rad << " rad (" << theta << "), load cell " << r.back().spring_force_n
                                  << " N (" << 3.0 * kEI * theta * (1.0 / (b * b) - 1.0 / (a * a)) << ")");
    BOOST_TEST(r.back().seat_rotation_rad == theta, tt::tolerance(1e-9));
    BOOST_TEST(std::abs(r.back().spring_force_n) == std::abs(3.0 * kEI * theta * (1.0 / (b * b) - 1.0 / (a * a))),
               tt::tolerance(1e-9));
    BOOST_TEST(r.back().seat_moment_n_m == M, tt::tolerance(1e-12));
    BOOST_TEST(std::abs(r.back().energy_balance_error_j) < 1e-9 * r.back().strain_energy_j);

    const System stack(Model::build(two_leaves(InterfaceLaw::bonded, 0.0)));
    L.displacement_m = constant(0.02);
    const StepRecord loaded = run(stack, L, Mode::closed_form).back();
    Loading wound;
    wound.kind = LoadingKind::prescribed_displacement;
    wound.displacement_m = constant(0.02);
    wound.seat_rotation_rad = ramp(loaded.seat_rotation_rad);
    const StepRecord turned = run(stack, wound, Mode::closed_form).back();
    BOOST_TEST_MESSAGE("bonded stack: M " << loaded.seat_moment_n_m << " -> theta_R " << loaded.seat_rotation_rad
                                          << " rad -> M " << turned.seat_moment_n_m << " N m; load cell " << loaded.spring_force_n
                                          << ", " << turned.spring_force_n << " N");
    BOOST_TEST(turned.seat_moment_n_m == M, tt::tolerance(1e-9));
    BOOST_TEST(turned.spring_force_n == loaded.spring_force_n, tt::tolerance(1e-9));
    BOOST_TEST(turned.seat_axial_m == loaded.seat_axial_m, tt::tolerance(1e-9));
}

// cvode's massive stack takes the windup rig as its vertical rig (theta_R's acceleration prescribed
// by a reaction) against newmark with leaf mass (theta_R held by its rig's rows): steel leaves turned
// smoothly from rest, theta = A (1 - cos 2 pi f t), f = 0.5 Hz, read at the peak. (a) The flat leaf
// with the seat held vertically (both rigs); (b) the two-leaf spring bonded on an elastic layer, the
// seat free vertically under a smooth 2 kN force. The two integrators share the
// problem, so they differ by their time errors: newmark's (omega dt)^2 on the rig's slow motion
// (1e-5 at dt = 1 ms) and on the leaves' vibration, which the free seat lets the force excite (b's
// moment, measured: 75.414, 75.393, 75.362, 75.353 N m at dt = 2, 1, 0.5, 0.25 ms, cvode 75.354: (b)
// at 0.25 ms), cvode's to its tolerances: 1e-4 as the cvode-vs-newmark seat-moment test of test_windup.
BOOST_AUTO_TEST_CASE(cvode_massive_windup_rig_matches_newmark_with_leaf_mass) {
    const double A = 0.005, f = 0.5;
    for (int which = 0; which < 2; ++which) {
        const System sys(Model::build(
            steel(which == 0 ? testing::single_leaf(kL, kT, kB, kE, SupportKind::pinned, SupportKind::pinned, 0.5, kL / 24)
                             : two_leaves(InterfaceLaw::bonded, 0.0))));
        Loading L;
        L.seat_rotation_rad = from_rest(A, f);
        if (which == 0) {
            L.kind = LoadingKind::prescribed_displacement;
            L.displacement_m = constant(0.0);
        } else {
            L.kind = LoadingKind::applied_force;
            TimeFunction force = from_rest(A, f);
            force.mean = force.amplitude = 1000.0;
            L.force_n = force;
        }
        const StepRecord n = run(sys, L, Mode::newmark, ContactPath::dense, 0.5 / f, which == 0 ? 1e-3 : 2.5e-4).back();
        // (the vertical rig moves the cvode stepper to the massive stack, as the windup rig does)
        const auto cv = run(sys, L, Mode::cvode, ContactPath::dense, 0.5 / f, 0.05);
        const StepRecord& c = cv.back();
        double balance = 0.0, work = 0.0;
        for (const auto& x : cv) {
            balance = std::max(balance, std::abs(x.energy_balance_error_j));
            work = std::max(work, std::abs(x.external_work_j));
        }
        BOOST_TEST_MESSAGE("spring " << which << ": moment cvode " << c.seat_moment_n_m << ", newmark " << n.seat_moment_n_m
                                     << " N m; w " << c.w_m << ", " << n.w_m << " m; theta_R " << c.seat_rotation_rad
                                     << " rad; balance " << balance << " J of " << work << " J");
        BOOST_TEST(c.seat_rotation_rad == 2.0 * A, tt::tolerance(1e-6));  // the rig's, to cvode's tolerance
        BOOST_TEST(c.seat_moment_n_m == n.seat_moment_n_m, tt::tolerance(1e-4));
        if (which == 1) BOOST_TEST(c.w_m == n.w_m, tt::tolerance(1e-4));
        BOOST_TEST(balance < 1e-6 * work);  // the work a state, to cvode's tolerances (as test_windup's 1e-6)
    }
}

// Seat loads with the vertical rig in cvode's massive stack: the rig's reaction on w and the seat
// loads' work q^T v both booked (the prescribed DOFs' form with H = {w}). The two-leaf spring bonded
// on an elastic layer, steel leaves, held at a smooth 5 mm stroke with a smooth seat moment and a
// longitudinal force at a height, 0.5 s: against newmark with leaf mass, theta_R, u_R and the load
// cell to 1e-4 (the time errors, as above; the load cell reads the leaves' inertia, which newmark
// converges on slowly: measured 644.252, 644.385, 644.550 N at dt = 0.5, 0.25, 0.125 ms, cvode
// 644.569: newmark at 0.125 ms), the energy balance to cvode's tolerances (1e-6 of the external work, as test_windup's). (A friction stack on its elastic layer
// is not a case for the massive stack: its contact points chatter on the layer, decision 015.)
// Slow (~35 s in Release: cvode follows the stiff layer under the rig), so Release only.
BOOST_AUTO_TEST_CASE(cvode_massive_takes_seat_loads_with_the_vertical_rig, *boost::unit_test::label("slow")) {
    const System sys(Model::build(steel(two_leaves(InterfaceLaw::bonded, 0.0))));
    TimeFunction smooth;  // from rest: mean = amplitude, phase -pi/2
    smooth.shape = TimeFunction::Shape::harmonic;
    smooth.frequency_hz = 1.0;
    smooth.phase_rad = -0.5 * kPi;
    Loading L;
    L.kind = LoadingKind::prescribed_displacement;
    L.displacement_m = smooth;
    L.displacement_m.mean = L.displacement_m.amplitude = 0.0025;
    L.seat_moment_n_m = smooth;
    L.seat_moment_n_m->mean = L.seat_moment_n_m->amplitude = 20.0;
    L.longitudinal_force_n = smooth;
    L.longitudinal_force_n->mean = L.longitudinal_force_n->amplitude = 200.0;
    L.longitudinal_force_height_m = -0.3;
    const StepRecord n = run(sys, L, Mode::newmark, ContactPath::dense, 0.5, 1.25e-4).back();
    const auto cv = run(sys, L, Mode::cvode, ContactPath::dense, 0.5, 0.05);
    const StepRecord& c = cv.back();
    double balance = 0.0, work = 0.0;
    for (const auto& x : cv) {
        balance = std::max(balance, std::abs(x.energy_balance_error_j));
        work = std::max(work, std::abs(x.external_work_j));
    }
    BOOST_TEST_MESSAGE("theta_R cvode " << c.seat_rotation_rad << ", newmark " << n.seat_rotation_rad << " rad; u_R "
                                        << c.seat_axial_m << ", " << n.seat_axial_m << " m; load cell " << c.spring_force_n
                                        << ", " << n.spring_force_n << " N; balance " << balance << " J of " << work << " J");
    BOOST_TEST(c.seat_moment_n_m == 40.0 + 400.0 * 0.3, tt::tolerance(1e-12));
    BOOST_TEST(c.seat_rotation_rad == n.seat_rotation_rad, tt::tolerance(1e-4));
    BOOST_TEST(c.seat_axial_m == n.seat_axial_m, tt::tolerance(1e-4));
    BOOST_TEST(c.spring_force_n == n.spring_force_n, tt::tolerance(1e-4));
    BOOST_TEST(balance < 1e-6 * work);
}

// The start holds the seat where the windup rig does (theta_R(0) = 0) in every stepper that takes the rig:
// a single flat leaf, pinned ends, the seat at a = 0.5 m of kL = 1.2 m (b = 0.7 m: asymmetric), held at
// w0 = 10 mm by the vertical rig. Each half is then a propped cantilever whose clamped end (the seat)
// is displaced by w0 unturned; the pinned-fixed member's condensed stiffness on (v, theta) at its fixed
// end, 3 E I / l^3 [[1, -+l], [-+l, l^2]] (- on the half left of the seat, + on the right one), gives
// the moment that holds theta_R = 0: M0 = 3 E I w0 (1/b^2 - 1/a^2), counter-clockwise (the transpose of
// the load-cell figure of closed_form_takes_seat_loads_with_the_vertical_rig: reciprocity). Exact on
// the cubic elements with the seat a node, so to rounding (1e-9). Record 0 reads theta_R = 0 to rounding
// and M0; the rig held still (theta_R = 0, w = w0 throughout), step 1 is each stepper's own solve of the
// same state: the same moment, and the balance at step 1 is rounding (it was the jump to the held seat).
BOOST_AUTO_TEST_CASE(the_start_holds_the_seat_where_the_windup_rig_does) {
    const double a = 0.5, b = kL - a, w0 = 0.01;
    const double M0 = 3.0 * kEI * w0 * (1.0 / (b * b) - 1.0 / (a * a));
    const ModelSpec flat = testing::single_leaf(kL, kT, kB, kE, SupportKind::pinned, SupportKind::pinned, a, kL / 24);
    const System massless(Model::build(flat)), massive(Model::build(steel(flat)));
    Loading L;
    L.kind = LoadingKind::prescribed_displacement;
    L.displacement_m = constant(w0);
    L.seat_rotation_rad = constant(0.0);
    struct Case {
        const char* what;
        const System* sys;
        Mode mode;
        ContactPath path;
    };
    for (const Case& c : {Case{"closed-form dense", &massless, Mode::closed_form, ContactPath::dense},
                          Case{"closed-form sparse", &massless, Mode::closed_form, ContactPath::sparse},
                          Case{"newmark massless", &massless, Mode::newmark, ContactPath::dense},
                          Case{"newmark leaf mass", &massive, Mode::newmark, ContactPath::dense},
                          Case{"cvode massive", &massive, Mode::cvode, ContactPath::dense}}) {
        const auto r = run(*c.sys, L, c.mode, c.path, 0.1, 0.05);
        BOOST_TEST_MESSAGE(c.what << ": record 0 theta_R " << r[0].seat_rotation_rad << " rad, moment " << r[0].seat_moment_n_m
                                  << " N m (" << M0 << "), record 1 " << r[1].seat_moment_n_m << " N m, balance at step 1 "
                                  << r[1].energy_balance_error_j << " J of " << r[1].strain_energy_j << " J");
        BOOST_TEST(std::abs(r[0].seat_rotation_rad) <= 1e-12 * w0 / a, c.what);
        BOOST_TEST(r[0].seat_moment_n_m == M0, tt::tolerance(1e-9));
        BOOST_TEST(r[1].seat_moment_n_m == M0, tt::tolerance(1e-9));
        BOOST_TEST(std::abs(r[1].energy_balance_error_j) <= 1e-9 * r[1].strain_energy_j, c.what);
    }
}

// The same on the asymmetric two-leaf spring with friction (mu = 0.3), the seat held at 20 mm (its
// seat turned freely by 0.01 rad there) and wound +-0.01 rad from the start, massless leaves: record 0
// holds theta_R = 0, its moment is what the steppers' own step reads with the rig held still (as
// above; friction: a rest state stays put, 1e-9), and step 1's balance error is of the order of the
// rest of the run's (all rounding, bounded as the loop test's 1e-6 of the strain energy). The start's
// pairs that slipped into the held state are re-anchored where they are (as after every step): the
// friction work never decreases (per step, to rounding: 1e-12 of the strain energy); with the anchors
// left where the pairs were before the start's solve, the friction work fell by 6.0e-4 J over a step.
BOOST_AUTO_TEST_CASE(the_start_holds_the_seat_of_a_friction_stack) {
    const System sys(Model::build(two_leaves(InterfaceLaw::coulomb, 0.3)));
    Loading still = windup_loading(0);
    still.seat_rotation_rad = constant(0.0);
    for (const Mode mode : {Mode::closed_form, Mode::newmark}) {
        for (const ContactPath path : {ContactPath::dense, ContactPath::sparse}) {
            const auto s = run(sys, still, mode, path, 0.02, 0.01);
            const auto r = run(sys, windup_loading(0), mode, path);
            double balance = 0.0, strain = 0.0, friction_drop = 0.0;
            for (std::size_t k = 0; k < r.size(); ++k) {
                balance = std::max(balance, std::abs(r[k].energy_balance_error_j));
                strain = std::max(strain, r[k].strain_energy_j);
                if (k > 0) friction_drop = std::max(friction_drop, r[k - 1].dissipated_energy_j - r[k].dissipated_energy_j);
            }
            BOOST_TEST(friction_drop <= 1e-12 * strain, "friction work decreasing by " << friction_drop << " J");
            BOOST_TEST_MESSAGE("mode " << static_cast<int>(mode) << ", path " << static_cast<int>(path) << ": theta_R(0) "
                                       << r[0].seat_rotation_rad << " rad, moment " << s[0].seat_moment_n_m << " N m, held "
                                       << s[1].seat_moment_n_m << " N m; balance at step 1 " << r[1].energy_balance_error_j
                                       << " J, largest " << balance << " J of " << strain << " J");
            BOOST_TEST(std::abs(r[0].seat_rotation_rad) <= 1e-12 * 0.01);
            BOOST_TEST(r[0].seat_moment_n_m == s[0].seat_moment_n_m, tt::tolerance(1e-12));
            BOOST_TEST(s[1].seat_moment_n_m == s[0].seat_moment_n_m, tt::tolerance(1e-9));
            BOOST_TEST(std::abs(s[0].seat_moment_n_m) > 1.0);  // the asymmetric spring needs a moment to stay unturned
            BOOST_TEST(balance < 1e-6 * strain);
        }
    }
}

// The kinetic energy under the windup rig with leaf mass is the leaves' alone (R's inertia is out of
// the rig's loop: mass_reduced(false)), so leaf_kinetic_energy_j = kinetic_energy_j = v^T M v / 2 with
// that M, computed here from newmark's velocities, on every record (to rounding, 1e-12 of the largest),
// never negative. The two-leaf spring bonded on its elastic layer, steel leaves, the seat free
// vertically under a smooth force (it moves, so R's m w'^2 / 2 is not 0) and wound from rest. cvode's
// massive stack: the same two records, and its balance closing (to its tolerances, 1e-6 of the work).
BOOST_AUTO_TEST_CASE(the_windup_rig_kinetic_energy_is_the_leaves) {
    const System sys(Model::build(steel(two_leaves(InterfaceLaw::bonded, 0.0))));
    const Eigen::SparseMatrix<double> M = sys.mass_reduced(false);
    Loading L;
    L.seat_rotation_rad = from_rest(0.005, 2.0);
    L.kind = LoadingKind::applied_force;
    L.force_n = from_rest(1000.0, 2.0);
    SimulationOptions o;
    o.mode = Mode::newmark;
    o.dt_s = 1e-3;
    o.t_end_s = 0.25;
    o.loading = L;
    NewmarkStepper n(sys, o);
    double largest = 0.0, diff = 0.0, lowest = 0.0, body = 0.0;
    for (long k = 0; k <= 250; ++k) {
        const StepRecord& r = k == 0 ? n.current() : n.advance();
        const Eigen::VectorXd& v = n.velocities();
        const double leaves = 0.5 * v.dot(M * v);
        largest = std::max(largest, leaves);
        diff = std::max(diff, std::abs(r.leaf_kinetic_energy_j - leaves) + std::abs(r.kinetic_energy_j - leaves));
        lowest = std::min(lowest, r.leaf_kinetic_energy_j);
        body = std::max(body, 0.5 * sys.model().spec().rigid_body.mass_kg * r.w_dot_m_per_s * r.w_dot_m_per_s);
    }
    BOOST_TEST_MESSAGE("newmark: leaves' kinetic energy up to " << largest << " J, records against v^T M v / 2 " << diff
                                                               << " J, lowest " << lowest << " J; R's m w'^2 / 2 up to " << body << " J");
    BOOST_TEST(largest > 0.0);
    BOOST_TEST(body > 0.0);  // the seat moves: the old subtraction would show
    BOOST_TEST(diff <= 1e-12 * largest);
    BOOST_TEST(lowest >= 0.0);
    o.mode = Mode::cvode;
    o.dt_s = 0.01;
    const auto cv = simulate(sys, o);
    double balance = 0.0, work = 0.0, cv_lowest = 0.0, cv_diff = 0.0;
    for (const auto& x : cv) {
        balance = std::max(balance, std::abs(x.energy_balance_error_j));
        work = std::max(work, std::abs(x.external_work_j));
        cv_lowest = std::min(cv_lowest, x.leaf_kinetic_energy_j);
        cv_diff = std::max(cv_diff, std::abs(x.leaf_kinetic_energy_j - x.kinetic_energy_j));
    }
    BOOST_TEST_MESSAGE("cvode massive: lowest leaves' kinetic energy " << cv_lowest << " J, balance " << balance << " J of "
                                                                      << work << " J");
    BOOST_TEST(cv_lowest >= 0.0);
    BOOST_TEST(cv_diff == 0.0);
    BOOST_TEST(balance < 1e-6 * work);
}

// What remains refused names its key and the modes that take it: the windup rig in cvode's massless
// stepper (its contact forces are functions of w alone: a prescribed theta_R, like seat loads, would
// make them functions of time too; decision 069) and in the modal one (no rig at all, decision 026);
// seat loads in the massless stepper. The held-for-good stepper takes no loading but the initial
// conditions, so a seat load never reaches it (the automatic choice takes the massive stack).
BOOST_AUTO_TEST_CASE(the_remaining_refusals_are_named) {
    const System massless(Model::build(two_leaves(InterfaceLaw::coulomb, 0.3)));
    ModelSpec steel = two_leaves(InterfaceLaw::coulomb, 0.3);
    for (auto& l : steel.leaves) l.density_kg_per_m3 = 7850.0;
    const System massive(Model::build(steel));
    auto refusal = [](const System& sys, const Loading& L, LeafInertia li) -> std::string {
        SimulationOptions o;
        o.mode = Mode::cvode;
        o.cvode.leaf_inertia = li;
        o.loading = L;
        try {
            make_stepper(sys, o);
        } catch (const InputError& e) {
            BOOST_TEST_MESSAGE(e.what());
            BOOST_TEST(std::string(e.what()).find("mode newmark with massive leaves") != std::string::npos);
            return e.field();
        }
        return "accepted";
    };
    Loading moment;
    moment.seat_moment_n_m = constant(10.0);
    BOOST_TEST(refusal(massless, windup_loading(1), LeafInertia::automatic) == "loading.seat_rotation_rad");
    BOOST_TEST(refusal(massless, moment, LeafInertia::automatic) == "accepted");  // cvode-massless takes seat loads
    Loading smooth = windup_loading(1);  // leaf mass: a smooth rig
    smooth.seat_rotation_rad->shape = TimeFunction::Shape::harmonic;
    smooth.seat_rotation_rad->mean = smooth.seat_rotation_rad->amplitude = 0.01;
    smooth.seat_rotation_rad->phase_rad = -0.5 * kPi;
    BOOST_TEST(refusal(massive, smooth, LeafInertia::modal) == "loading.seat_rotation_rad");
    ModelSpec bonded = two_leaves(InterfaceLaw::bonded, 0.0);
    for (auto& l : bonded.leaves) l.density_kg_per_m3 = 7850.0;
    const System held(Model::build(bonded));
    SimulationOptions o;
    o.mode = Mode::cvode;
    o.loading = moment;
    BOOST_CHECK_NO_THROW(make_stepper(held, o));  // accepted (the automatic choice: the massive stack)
}
