// Loadings (loading.hpp) and loop figures (hysteresis.hpp) on the paper example,
// against closed-form answers: the static deflection m g / k under gravity, the
// step and harmonic responses of a linear spring, base excitation of a linear
// spring, and the test-rig loop (zero area without friction; with friction its
// area is the friction work of the cycle).
#define BOOST_TEST_MODULE loadings
#include <boost/test/unit_test.hpp>
#include <algorithm>
#include <cmath>

#include "stackbeam/time/closed_form_stepper.hpp"
#include "stackbeam/time/cvode_stepper.hpp"
#include "stackbeam/errors.hpp"
#include "stackbeam/post/hysteresis.hpp"
#include "test_support.hpp"

namespace tt = boost::test_tools;
using namespace stackbeam;
using namespace stackbeam::testing;

namespace {

constexpr double kMass = 20.0, kG = 9.81;

System paper_system(PaperCase c, double v0 = 0.0) {
    PaperExampleOptions o;
    o.initial_velocity_m_per_s = v0;
    return System(Model::build(paper_example(c, o)));
}

SimulationOptions options(Mode mode, double dt, double t_end, const Loading& loading) {
    SimulationOptions so = run_options(mode, t_end, dt, 1e-10, 1e-10);
    so.loading = loading;
    return so;
}

/// Stiffness of the paper case at R [N/m]: tied (bonded) or free (identical leaves, frictionless).
double stiffness(const System& s, PaperCase c) {
    return c == PaperCase::bonded ? s.tied_stiffness_n_per_m() : s.free_stiffness_n_per_m();
}

TimeFunction harmonic(double amplitude, double frequency_hz) {
    TimeFunction f;
    f.shape = TimeFunction::Shape::harmonic;
    f.amplitude = amplitude;
    f.frequency_hz = frequency_hz;
    return f;
}

}  // namespace

BOOST_AUTO_TEST_CASE(time_functions) {
    // Triangle: the rig's constant-speed stroke, exact values at the quarter points.
    TimeFunction tri;
    tri.shape = TimeFunction::Shape::triangle;
    tri.amplitude = 0.01;
    tri.frequency_hz = 2.0;
    tri.mean = 0.005;
    BOOST_TEST(tri.value(0.0) == 0.005, tt::tolerance(1e-15));
    BOOST_TEST(tri.value(0.125) == 0.015, tt::tolerance(1e-12));
    BOOST_TEST(tri.value(0.375) == -0.005, tt::tolerance(1e-12));
    BOOST_TEST(tri.derivative(0.1) == 4 * 0.01 * 2.0, tt::tolerance(1e-15));
    BOOST_TEST(tri.period_s() == 0.5);
    // Linear table: exact interpolation, constant outside.
    TimeFunction tab;
    tab.shape = TimeFunction::Shape::table;
    tab.times_s = {0.0, 1.0, 3.0};
    tab.values = {0.0, 10.0, 0.0};
    tab.validate("f", false);
    tab.prepare(false);
    BOOST_TEST(tab.value(0.5) == 5.0, tt::tolerance(1e-15));
    BOOST_TEST(tab.value(2.0) == 5.0, tt::tolerance(1e-15));
    BOOST_TEST(tab.value(5.0) == 0.0);
    // Spline of a sine sampled every h: a clamped cubic spline's second derivative
    // converges as h^2 away from the ends; halving h must cut the error about 4x
    // (measured 3.9-4.1x; accept 3.5-4.5), and at h = T/200 it is below
    // (Omega h)^2 / 12 of the acceleration amplitude (the spline's leading term).
    double previous = 0.0;
    for (int n : {100, 200, 400}) {
        TimeFunction s;
        s.shape = TimeFunction::Shape::table;
        const double Om = 2 * kPi;  // 1 Hz
        for (int i = 0; i <= 2 * n; ++i) {  // two periods, error read in the middle period
            s.times_s.push_back(i / double(n));
            s.values.push_back(std::sin(Om * i / double(n)));
        }
        s.validate("s", true);
        s.prepare(true);
        double err = 0.0;
        for (double t = 0.75; t <= 1.25; t += 0.001) err = std::max(err, std::abs(s.second_derivative(t) + Om * Om * std::sin(Om * t)));
        BOOST_TEST_MESSAGE("spline h = 1/" << n << ": max acceleration error " << err);
        if (n == 200) BOOST_TEST(err <= 1.01 * std::pow(Om / n, 2) / 12.0 * Om * Om);
        if (previous > 0.0) BOOST_TEST(previous / err == 4.0, tt::tolerance(0.125));
        previous = err;
    }
}

BOOST_AUTO_TEST_CASE(gravity_static_deflection_is_mg_over_k) {
    // At rest under R's weight the stack carries m g: the static deflection is -m g / k
    // on a linear stack (bonded: the tied stiffness 107,404 N/m; frictionless identical
    // leaves: 12,000 N/m, no contact force). The equilibrium comes from one contact
    // solve at tolerance 1e-10 m on ||v||, so w is exact to ~1e-10 m (1e-8 relative
    // of 1.8 mm); starting there, R stays at rest: |w - w_s| stays at round-off
    // (1e-12 relative) in both modes. On the friction case the equilibrium is
    // path-dependent, but the balance of R holds: the spring force is -m g.
    for (PaperCase c : {PaperCase::bonded, PaperCase::frictionless, PaperCase::friction}) {
        for (Mode mode : {Mode::closed_form, Mode::cvode}) {
            BOOST_TEST_CONTEXT(to_string(c) << ", " << to_string(mode)) {
                const System sys = paper_system(c);
                Loading l;
                l.gravity_m_per_s2 = kG;
                const auto r = simulate(sys, options(mode, 1e-3, 0.05, l));
                BOOST_TEST(r.front().spring_force_n == -kMass * kG, tt::tolerance(1e-8));
                if (c != PaperCase::friction) {
                    const double ws = -kMass * kG / stiffness(sys, c);
                    BOOST_TEST_MESSAGE(to_string(c) << ": static deflection " << r.front().w_m << " m, m g / k = " << ws);
                    BOOST_TEST(r.front().w_m == ws, tt::tolerance(1e-8));
                }
                for (const auto& x : r) {
                    BOOST_CHECK_SMALL(x.w_m - r.front().w_m, 1e-12 * std::abs(r.front().w_m));
                    BOOST_CHECK_SMALL(x.energy_balance_error_j, 1e-9);
                }
            }
        }
    }
}

BOOST_AUTO_TEST_CASE(gravity_shifts_the_free_vibration_by_the_static_deflection) {
    // Bonded stack, v0 = 2 m/s under gravity: a linear spring oscillates about -m g/k
    // with the same amplitude v0/omega as without gravity. Closed-form, dt = 1 ms: the
    // two runs differ by the static deflection exactly up to the solves' tolerance
    // (the step is linear in the loads: superposition); 1e-9 m.
    const System sys = paper_system(PaperCase::bonded, 2.0);
    Loading l;
    l.gravity_m_per_s2 = kG;
    const auto a = simulate(sys, options(Mode::closed_form, 1e-3, 0.3, l));
    const auto b = simulate(sys, options(Mode::closed_form, 1e-3, 0.3, Loading{}));
    const double ws = -kMass * kG / sys.tied_stiffness_n_per_m();
    for (std::size_t i = 0; i < a.size(); ++i) BOOST_CHECK_SMALL(a[i].w_m - ws - b[i].w_m, 1e-9);
    // Energy: the weight's work balances; the scheme's swing as without gravity (0.016 J, test_linear_cases).
    for (const auto& x : a) BOOST_CHECK_SMALL(x.energy_balance_error_j, 0.02);
}

BOOST_AUTO_TEST_CASE(step_and_harmonic_force_on_the_frictionless_spring) {
    // Identical frictionless leaves: no contact force, a linear spring k = 12,000 N/m.
    // A constant force F from rest: w = F/k (1 - cos omega t). The closed-form step
    // (eq. 16) is exact for a constant force: round-off, 1e-12 m.
    const System sys = paper_system(PaperCase::frictionless);
    const double k = sys.free_stiffness_n_per_m(), om = std::sqrt(k / kMass);
    Loading step;
    step.kind = LoadingKind::applied_force;
    step.force_n.mean = 100.0;
    for (const auto& x : simulate(sys, options(Mode::closed_form, 1e-3, 0.5, step)))
        BOOST_CHECK_SMALL(x.w_m - 100.0 / k * (1 - std::cos(om * x.t_s)), 1e-12);
    // F = F0 sin(Omega t) from rest: w = F0/(k (1 - r^2)) (sin Omega t - r sin omega t),
    // r = Omega/omega. The closed-form step interpolates F linearly over a step (eq. 14),
    // an O(dt^2) error: halving dt must cut it 4x (accept 3.6-4.4); CVODE at rtol 1e-10
    // follows it to 2 N rtol A (as test_cvode) and its external work closes the balance
    // to 4 N rtol E (E = F0 A scale).
    Loading h;
    h.kind = LoadingKind::applied_force;
    h.force_n = harmonic(100.0, 2.0);
    const double Om = 2 * kPi * 2.0, r = Om / om, A = 100.0 / (k * (1 - r * r));
    auto exact = [&](double t) { return A * (std::sin(Om * t) - r * std::sin(om * t)); };
    double previous = 0.0;
    for (double dt : {1e-3, 5e-4}) {
        double err = 0.0;
        for (const auto& x : simulate(sys, options(Mode::closed_form, dt, 1.0, h))) err = std::max(err, std::abs(x.w_m - exact(x.t_s)));
        BOOST_TEST_MESSAGE("harmonic force, closed-form dt " << dt << ": max error " << err << " m of amplitude " << A);
        if (previous > 0.0) BOOST_TEST(previous / err == 4.0, tt::tolerance(0.1));
        previous = err;
    }
    RunReport rep;
    const auto c = simulate(sys, options(Mode::cvode, 1e-3, 1.0, h), {}, &rep);
    double err = 0.0, bal = 0.0;
    for (const auto& x : c) {
        err = std::max(err, std::abs(x.w_m - exact(x.t_s)));
        bal = std::max(bal, std::abs(x.energy_balance_error_j));
    }
    BOOST_TEST_MESSAGE("harmonic force, cvode rtol 1e-10: max error " << err << " m, balance " << bal << " J, "
                                                                       << rep.cvode.steps << " steps");
    BOOST_TEST(err <= 2.0 * rep.cvode.steps * 1e-10 * 2 * A);
    BOOST_TEST(bal <= 4.0 * rep.cvode.steps * 1e-10 * 100.0 * 2 * A);
}

BOOST_AUTO_TEST_CASE(base_excitation_at_low_frequency_moves_the_mass_with_the_base) {
    // Bonded stack (linear, omega = 73.3 rad/s), supports moving y_b = Y sin(Omega t) at
    // 1 Hz (r = Omega/omega = 0.086). With the initial absolute velocity Y Omega/(1 - r^2)
    // there is no transient: R moves as x = y_b + w = Y/(1 - r^2) sin(Omega t), i.e. with
    // the base to r^2/(1 - r^2) = 0.74 %. The relative motion w is r^2 Y/(1 - r^2) sin:
    // closed-form (dt = 1 ms) errs on it by the bonded scheme's O((omega dt)^2) = 2e-4
    // relative (test_linear_cases) plus the free vibration its start-up error excites,
    // both far below 1e-3 of w's amplitude; cvode at rtol 1e-10 to 2 N rtol Y.
    const double Y = 0.01, Om = 2 * kPi;
    PaperExampleOptions o;
    const System sys0(Model::build(paper_example(PaperCase::bonded, o)));
    const double om = std::sqrt(sys0.tied_stiffness_n_per_m() / kMass), r = Om / om;
    o.initial_velocity_m_per_s = Y * Om / (1 - r * r);
    const System sys(Model::build(paper_example(PaperCase::bonded, o)));
    Loading l;
    l.kind = LoadingKind::base_excitation;
    l.displacement_m = harmonic(Y, 1.0);
    for (Mode mode : {Mode::closed_form, Mode::cvode}) {
        RunReport rep;
        const auto run = simulate(sys, options(mode, 1e-3, 2.0, l), {}, &rep);
        double err = 0.0, with_base = 0.0, bal = 0.0;
        for (const auto& x : run) {
            const double abs_x = x.w_m + x.base_displacement_m;
            err = std::max(err, std::abs(abs_x - Y / (1 - r * r) * std::sin(Om * x.t_s)));
            with_base = std::max(with_base, std::abs(abs_x - x.base_displacement_m));
            bal = std::max(bal, std::abs(x.energy_balance_error_j));
        }
        BOOST_TEST_MESSAGE(to_string(mode) << ": max |x - exact| = " << err << " m; max |x - y_b| = " << with_base
                                           << " m; balance " << bal << " J");
        BOOST_TEST(with_base <= 1.01 * r * r / (1 - r * r) * Y);
        if (mode == Mode::closed_form) BOOST_TEST(err <= 1e-3 * r * r * Y);
        else BOOST_TEST(err <= 2.0 * rep.cvode.steps * 1e-10 * Y);
    }
}

BOOST_AUTO_TEST_CASE(rig_loop_without_friction_has_no_area) {
    // Prescribed w = 20 mm sin(2 pi t) on the frictionless and bonded stacks: the spring
    // force is k w (linear, elastic), so the loop closes on a line: the trapezoidal
    // area telescopes to zero (round-off: 1e-12 of k w_a^2), the secant stiffness and
    // the dynamic rate are k (round-off and the contact tolerance 1e-10 m: 1e-8
    // relative), the loss factor is zero.
    for (PaperCase c : {PaperCase::frictionless, PaperCase::bonded}) {
        BOOST_TEST_CONTEXT(to_string(c)) {
            const System sys = paper_system(c);
            Loading l;
            l.kind = LoadingKind::prescribed_displacement;
            l.displacement_m = harmonic(0.02, 1.0);
            const auto run = simulate(sys, options(Mode::closed_form, 1e-3, 2.0, l));
            const auto cyc = last_cycle(run, l.period_s());
            BOOST_TEST(cyc.first == 1.0, tt::tolerance(1e-12));
            const HysteresisMetrics h = hysteresis_metrics(run, cyc.first, cyc.second);
            const double k = stiffness(sys, c);
            BOOST_CHECK_SMALL(h.loop_area_j, 1e-12 * k * 0.02 * 0.02);
            BOOST_TEST(h.secant_stiffness_n_per_m == k, tt::tolerance(1e-8));
            BOOST_TEST(h.dynamic_rate_n_per_m == k, tt::tolerance(1e-8));
            BOOST_CHECK_SMALL(h.loss_factor, 1e-8);
            BOOST_CHECK_SMALL(h.dissipated_j, 1e-9);
            for (const auto& x : run) BOOST_CHECK_SMALL(x.energy_balance_error_j, 1e-9 * k * 0.02 * 0.02);
        }
    }
}

BOOST_AUTO_TEST_CASE(rig_loop_with_friction_dissipates_its_area) {
    // The friction case on the rig: triangle stroke of +-20 mm at 1 Hz (quasi-static:
    // the rig's steps are static), three cycles, the last one read. Independent
    // figures: (1) the loop area equals the friction work of the cycle from the per-step
    // balance (dissipated energy), as the strain energy returns after a steady cycle.
    // Both are trapezoidal sums over the steps, of the rig's work and of the slip work;
    // they differ only in the steps where a pair changes state, an O(dt^2) term:
    // measured 3e-8 of the area at 1000 steps per cycle and 2e-10 at 2000; required
    // below 1e-6 of it and falling at least 2.5x per halving of dt. (2) The cycle is
    // steady: the second and third loops agree to 1e-6. (3) The area has converged in
    // dt: the two runs agree to 1e-4 (measured 6e-6). (4) The loop dissipates: area > 0,
    // loss factor in (0, 1), secant stiffness between the free and the tied stack's.
    double previous_area = 0.0;
    double previous_gap = 0.0;
    for (double dt : {1e-3, 5e-4}) {
        BOOST_TEST_CONTEXT("dt " << dt) {
            const System sys = paper_system(PaperCase::friction);
            const Loading l =
                periodic_loading(LoadingKind::prescribed_displacement, TimeFunction::Shape::triangle, 0.02, 1.0);
            auto so = options(Mode::closed_form, dt, 3.0, l);
            so.solver.tolerance_m = 1e-9;
            const auto run = simulate(sys, so);
            const auto cyc = last_cycle(run, 1.0);
            const HysteresisMetrics h3 = hysteresis_metrics(run, cyc.first, cyc.second);
            const HysteresisMetrics h2 = hysteresis_metrics(run, 1.0, 2.0);
            const double gap = std::abs(h3.loop_area_j - h3.dissipated_j);
            BOOST_TEST_MESSAGE("dt " << dt << ": loop area " << h3.loop_area_j << " J, friction work " << h3.dissipated_j
                                     << " J, strain change " << h3.strain_energy_change_j << " J, secant "
                                     << h3.secant_stiffness_n_per_m << " N/m, dynamic rate " << h3.dynamic_rate_n_per_m
                                     << " N/m, loss factor " << h3.loss_factor << ", zeta " << h3.equivalent_damping_ratio
                                     << "; cycle 2 area " << h2.loop_area_j << "; |area - friction work| " << gap);
            BOOST_TEST(h3.loop_area_j > 0.0);
            BOOST_TEST(gap <= 1e-6 * h3.loop_area_j);
            BOOST_TEST(h3.loop_area_j == h2.loop_area_j, tt::tolerance(1e-6));
            if (previous_area > 0.0) BOOST_TEST(h3.loop_area_j == previous_area, tt::tolerance(1e-4));
            previous_area = h3.loop_area_j;
            BOOST_TEST(h3.loss_factor > 0.0);
            BOOST_TEST(h3.loss_factor < 1.0);
            // the loop lies between the frictionless (free) and the bonded (tied) stiffness
            BOOST_TEST(h3.secant_stiffness_n_per_m > sys.free_stiffness_n_per_m());
            BOOST_TEST(h3.secant_stiffness_n_per_m < sys.tied_stiffness_n_per_m());
            if (previous_gap > 0.0) BOOST_TEST(previous_gap / gap > 2.5);
            previous_gap = gap;
        }
    }
}

BOOST_AUTO_TEST_CASE(loading_input_is_checked) {
    const System sys = paper_system(PaperCase::friction, 2.0);
    Loading l;
    l.kind = LoadingKind::prescribed_displacement;
    l.displacement_m = harmonic(0.02, 1.0);
    try {  // the rig fixes w'(0): the model's 2 m/s contradicts it
        ClosedFormStepper stepper(sys, options(Mode::closed_form, 1e-3, 0.1, l));
        BOOST_FAIL("no error");
    } catch (const InputError& e) {
        BOOST_TEST(e.field() == "rigid_body.initial_velocity_m_per_s");
    }
    auto expect = [](const Loading& bad, const std::string& field) {
        try {
            bad.validate();
            BOOST_ERROR("no error for " << field);
        } catch (const InputError& e) {
            BOOST_TEST(e.field() == field);
        }
    };
    Loading g;
    g.gravity_m_per_s2 = -9.81;
    expect(g, "loading.gravity_m_per_s2");
    Loading f;
    f.kind = LoadingKind::applied_force;
    f.force_n = harmonic(-1.0, 1.0);
    expect(f, "loading.force_n.amplitude");
    f.force_n = harmonic(1.0, 0.0);
    expect(f, "loading.force_n.frequency_hz");
    Loading b;
    b.kind = LoadingKind::base_excitation;
    b.displacement_m.shape = TimeFunction::Shape::triangle;
    b.displacement_m.amplitude = 0.01;
    b.displacement_m.frequency_hz = 1.0;
    expect(b, "loading.displacement_m.shape");
    b.displacement_m.shape = TimeFunction::Shape::table;
    b.displacement_m.times_s = {0.0, 1.0, 1.0};
    b.displacement_m.values = {0.0, 1.0, 2.0};
    expect(b, "loading.displacement_m.times_s[2]");
    SimulationOptions so = options(Mode::cvode, 1e-3, 0.1, l);
    try {  // the rig in mode cvode with massless leaves (no equation of motion; leaf mass: test_leaf_mass_loadings)
        simulate(paper_system(PaperCase::frictionless), so);
        BOOST_ERROR("no error for cvode with a rig");
    } catch (const InputError& e) {
        BOOST_TEST(e.field() == "loading.kind");
    }
}

BOOST_AUTO_TEST_CASE(force_table_ramp_on_the_frictionless_spring) {
    // A piecewise-linear force table with its points on the step grid: F rises linearly
    // to F1 over T = 0.1 s, then holds. The closed-form step assumes F linear over each
    // step (eq. 14), which is then exact: w = F1/(k T) (t - sin(omega t)/omega) for t <= T,
    // and after T the free vibration about F1/k from the state at T. Round-off: 1e-12 m.
    const System sys = paper_system(PaperCase::frictionless);
    const double k = sys.free_stiffness_n_per_m(), om = std::sqrt(k / kMass), F1 = 150.0, T = 0.1;
    Loading l;
    l.kind = LoadingKind::applied_force;
    l.force_n.shape = TimeFunction::Shape::table;
    l.force_n.times_s = {0.0, T};
    l.force_n.values = {0.0, F1};
    const double wT = F1 / (k * T) * (T - std::sin(om * T) / om), vT = F1 / (k * T) * (1 - std::cos(om * T));
    auto exact = [&](double t) {
        if (t <= T) return F1 / (k * T) * (t - std::sin(om * t) / om);
        return F1 / k + (wT - F1 / k) * std::cos(om * (t - T)) + vT / om * std::sin(om * (t - T));
    };
    for (const auto& x : simulate(sys, options(Mode::closed_form, 1e-3, 0.4, l)))
        BOOST_CHECK_SMALL(x.w_m - exact(x.t_s), 1e-12);
}

BOOST_AUTO_TEST_CASE(pair_output_agrees_with_the_records) {
    // The per-pair output (simulate's PairObserver) against the step records of the same
    // run, both modes: the state counts and the probe pair's friction force are the
    // same numbers (exactly), every closed pair has zero gap and every open one zero
    // normal force, and no unilateral pair pulls (p_n <= 0, to 1e-9 N of round-off; clamp
    // pairs are bilateral and may).
    const System sys = paper_system(PaperCase::friction, 2.0);
    for (Mode mode : {Mode::closed_form, Mode::cvode}) {
        BOOST_TEST_CONTEXT(to_string(mode)) {
            std::vector<std::vector<PairRecord>> pairs;
            const auto r = simulate(sys, options(mode, 1e-3, 0.1, Loading{}), {}, nullptr,
                                    [&](double, const std::vector<PairRecord>& p) { pairs.push_back(p); });
            BOOST_TEST(pairs.size() == r.size());
            for (std::size_t i = 0; i < r.size(); ++i) {
                int stick = 0, slip = 0, open = 0;
                for (const auto& p : pairs[i]) {
                    if (p.state == PairState::stick) ++stick;
                    else if (p.state == PairState::slip) ++slip;
                    else ++open;
                    if (sys.pairs()[p.pair].kind == PairKind::coulomb) BOOST_TEST(p.p_n_n <= 1e-9);
                    if (p.state == PairState::open) BOOST_CHECK_SMALL(p.p_n_n, 1e-9);
                    if (p.p_n_n < -1e-6) BOOST_CHECK_SMALL(p.gap_m, 1e-9);
                }
                BOOST_TEST(stick == r[i].n_stick);
                BOOST_TEST(slip == r[i].n_slip);
                BOOST_TEST(open == r[i].n_open);
                BOOST_TEST(pairs[i][sys.probe_pair()].p_t_n == r[i].probe_friction_force_n);
            }
        }
    }
}

BOOST_AUTO_TEST_CASE(sparse_path_equals_dense_path_under_loadings) {
    // The sparse contact path poses the same problems on the banded stiffness (the rig's
    // as R held at w(t), gravity's static step with R free, eq. 16 with F_e): both paths
    // must agree to the contact tolerance's effect (1e-10 m on ||v|| -> forces to ~1e-10
    // of C'^-1 scale): spring force to 1e-6 N, w to 1e-10 m, energies to 1e-8 J.
    const System sys = paper_system(PaperCase::friction, 2.0);
    const System rig_sys = paper_system(PaperCase::friction);
    const Loading rig = periodic_loading(LoadingKind::prescribed_displacement, TimeFunction::Shape::triangle, 0.02, 2.0);
    Loading grav;
    grav.gravity_m_per_s2 = kG;
    Loading force;
    force.kind = LoadingKind::applied_force;
    force.force_n = harmonic(200.0, 5.0);
    const std::pair<const System*, Loading> cases[] = {{&rig_sys, rig}, {&sys, grav}, {&sys, force}};
    for (const auto& [s, l] : cases) {
        BOOST_TEST_CONTEXT(to_string(l.kind) << (l.gravity_m_per_s2 > 0 ? " + gravity" : "")) {
            auto so = options(Mode::closed_form, 1e-3, 0.5, l);
            so.contact_path = ContactPath::dense;
            const auto a = simulate(*s, so);
            so.contact_path = ContactPath::sparse;
            const auto b = simulate(*s, so);
            for (std::size_t i = 0; i < a.size(); ++i) {
                BOOST_CHECK_SMALL(a[i].w_m - b[i].w_m, 1e-10);
                BOOST_CHECK_SMALL(a[i].spring_force_n - b[i].spring_force_n, 1e-6);
                BOOST_CHECK_SMALL(a[i].dissipated_energy_j - b[i].dissipated_energy_j, 1e-8);
                BOOST_CHECK_SMALL(a[i].energy_balance_error_j - b[i].energy_balance_error_j, 1e-8);
            }
        }
    }
}
