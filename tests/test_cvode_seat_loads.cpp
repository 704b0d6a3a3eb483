// Seat loads in cvode's massless stepper (issue 44; decision 069, "cvode-massless takes seat loads"):
// a seat moment and a longitudinal force at a height, each with a vertical applied force, condensed as
// closed-form's (System::SeatCondensation: s = C'p + c w + B S(t) - d, R's force k w - c^T p + g^T S,
// [theta_R; u_R] = B^T p - g w + F S), proved against closed-form on the same massless problems, by the
// energy balance (the seat loads' work integrated as a state), and by the registry's row.
//
// Tolerances. Both modes solve the same massless problem: R's ODE m w'' = c^T p(w, S) - k w - g^T S + F(t)
// with the leaves in static equilibrium. cvode integrates it to rtol 1e-10 (w to ~1e-10 of its size);
// closed-form moves R exactly within a step with the loads linear in the step, which is second order in
// dt. Its error is measured here: closed-form at dt and dt/2 differ by 4/3 of the finer run's error
// (Richardson), and cvode must lie within 2x the finer run's estimated error plus 1e-8 relative
// (the cvode tolerance on a response of a few periods), and within a tenth of closed-form's error of its
// Richardson extrapolation fine + (fine - coarse) / 3 (what is left is closed-form's dt^3 and cvode's
// tolerance). With friction the same bounds hold (no stick-slip event falls between the grids' steps
// closely enough to make closed-form's error first order here; the figures are printed).
#define BOOST_TEST_MODULE cvode_seat_loads
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "single_leaf.hpp"
#include "windup_cases.hpp"
#include "stackbeam/errors.hpp"
#include "stackbeam/fe/system.hpp"
#include "stackbeam/time/simulation.hpp"
#include "stackbeam/time/stepper.hpp"

using namespace stackbeam;

namespace {

constexpr double kL = 1.2, kT = 0.01, kB = 0.05, kE = 206e9, kPi = 3.14159265358979323846;

using testing::two_leaves;  // windup_cases.hpp

/// a (1 - cos 2 pi f t): from rest, so the massless start carries no step of the load.
TimeFunction from_rest(double a, double f_hz) {
    TimeFunction f;
    f.shape = TimeFunction::Shape::harmonic;
    f.frequency_hz = f_hz;
    f.phase_rad = -0.5 * kPi;
    f.mean = f.amplitude = a;
    return f;
}

/// A vertical applied force with (0) a seat moment or (1) a longitudinal force 0.3 m below the seat's
/// reference (braking at a tyre's contact patch), each from rest, the seat load faster than the force.
Loading seat_loading(int which) {
    Loading L;
    L.kind = LoadingKind::applied_force;
    L.force_n = from_rest(1000.0, 1.0);
    if (which == 0) {
        L.seat_moment_n_m = from_rest(40.0, 3.0);
    } else {
        L.longitudinal_force_n = from_rest(300.0, 3.0);
        L.longitudinal_force_height_m = -0.3;
    }
    return L;
}

SimulationOptions options(Mode mode, const Loading& L, double dt_s) {
    SimulationOptions o;
    o.mode = mode;
    o.dt_s = dt_s;
    o.t_end_s = 0.4;
    o.loading = L;
    o.cvode.rtol = 1e-10;
    o.cvode.atol_m = 1e-14;
    return o;
}

struct Gap {
    double w = 0, theta = 0, u = 0, moment = 0;  // largest differences [m, rad, m, N m]
    double w_size = 0, theta_size = 0, u_size = 0;
};
/// Largest differences of w, theta_R, u_R, seat_moment between run a and run b on a's grid (b every
/// `stride`-th record of its own run); with `coarse` (b's run at stride 1 on a's grid), against b's
/// Richardson extrapolation b + (b - coarse) / 3 (second order) instead.
Gap gap(const std::vector<StepRecord>& a, const std::vector<StepRecord>& b, int stride,
        const std::vector<StepRecord>* coarse = nullptr) {
    Gap g;
    auto ref = [&](std::size_t i, double StepRecord::*f) {
        const double fine = b[i * static_cast<std::size_t>(stride)].*f;
        return coarse ? fine + (fine - (*coarse)[i].*f) / 3.0 : fine;
    };
    for (std::size_t i = 0; i < a.size(); ++i) {
        g.w = std::max(g.w, std::abs(a[i].w_m - ref(i, &StepRecord::w_m)));
        g.theta = std::max(g.theta, std::abs(a[i].seat_rotation_rad - ref(i, &StepRecord::seat_rotation_rad)));
        g.u = std::max(g.u, std::abs(a[i].seat_axial_m - ref(i, &StepRecord::seat_axial_m)));
        g.moment = std::max(g.moment, std::abs(a[i].seat_moment_n_m - ref(i, &StepRecord::seat_moment_n_m)));
        g.w_size = std::max(g.w_size, std::abs(a[i].w_m));
        g.theta_size = std::max(g.theta_size, std::abs(a[i].seat_rotation_rad));
        g.u_size = std::max(g.u_size, std::abs(a[i].seat_axial_m));
    }
    return g;
}

}  // namespace

BOOST_AUTO_TEST_CASE(massless_cvode_follows_closed_form_under_seat_loads) {
    for (const double mu : {0.0, 0.3}) {
        const System sys(Model::build(two_leaves(InterfaceLaw::coulomb, mu)));
        for (int which = 0; which < 2; ++which) {
            const Loading L = seat_loading(which);
            constexpr double dt = 2e-4;
            const auto cvode = simulate(sys, options(Mode::cvode, L, dt));
            const auto coarse = simulate(sys, options(Mode::closed_form, L, dt));
            const auto fine = simulate(sys, options(Mode::closed_form, L, dt / 2));
            const Gap cf = gap(coarse, fine, 2);  // closed-form's own error: ~4/3 of fine's (second order)
            const Gap cv = gap(cvode, fine, 2);
            const Gap ex = gap(cvode, fine, 2, &coarse);  // against closed-form's extrapolation to dt -> 0
            BOOST_TEST_MESSAGE("mu " << mu << ", " << (which == 0 ? "moment" : "longitudinal force") << ": cvode - closed-form w "
                                     << cv.w << " of " << cv.w_size << " m (closed-form dt vs dt/2 " << cf.w << "), theta_R "
                                     << cv.theta << " of " << cv.theta_size << " (" << cf.theta << "), u_R " << cv.u << " of "
                                     << cv.u_size << " (" << cf.u << "), moment " << cv.moment
                                     << "; against the extrapolation w " << ex.w << ", theta_R " << ex.theta << ", u_R " << ex.u);
            BOOST_TEST(ex.w <= 0.1 * cf.w + 1e-8 * cv.w_size);  // the extrapolation removes closed-form's dt^2 term
            BOOST_TEST(ex.theta <= 0.1 * cf.theta + 1e-8 * cv.theta_size);
            BOOST_TEST(ex.u <= 0.1 * cf.u + 1e-8 * cv.u_size);
            BOOST_TEST(cv.w <= 2.0 * cf.w + 1e-8 * cv.w_size);
            BOOST_TEST(cv.theta <= 2.0 * cf.theta + 1e-8 * cv.theta_size);
            BOOST_TEST(cv.u <= 2.0 * cf.u + 1e-8 * cv.u_size);
            BOOST_TEST(cv.moment <= 1e-12 * 40.0);  // S(t) itself: the same function at the same times
            BOOST_TEST(cv.theta_size > 0.0);
            BOOST_TEST(cv.u_size > 0.0);
            // the energy balance closes: the seat loads' and the force's work integrated as states, to
            // the cvode tolerance (1e-6 of the work, as the other cvode steppers' bound)
            double balance = 0.0, work = 0.0;
            for (const auto& x : cvode) {
                balance = std::max(balance, std::abs(x.energy_balance_error_j));
                work = std::max(work, std::abs(x.external_work_j));
            }
            BOOST_TEST_MESSAGE("  cvode balance " << balance << " J of " << work << " J, dissipated "
                                                  << cvode.back().dissipated_energy_j << " J");
            BOOST_TEST(balance <= 1e-6 * work);
            if (mu > 0.0) BOOST_TEST(cvode.back().dissipated_energy_j > 0.0);
        }
    }
}

// Without a seat load the stepper is the one before (its own tests: bitwise); with one the registry's
// row says so, and the windup rig is still refused by its key.
BOOST_AUTO_TEST_CASE(massless_cvode_row_takes_seat_loads_not_the_windup_rig) {
    const System sys(Model::build(two_leaves(InterfaceLaw::coulomb, 0.0)));
    SimulationOptions o = options(Mode::cvode, seat_loading(0), 1e-2);
    o.t_end_s = 0.02;
    BOOST_CHECK_NO_THROW(simulate(sys, o));
    Loading rig;
    rig.seat_rotation_rad = testing::ramp(0.01);
    rig.kind = LoadingKind::prescribed_displacement;
    rig.displacement_m = testing::constant(0.0);
    o.loading = rig;
    try {
        simulate(sys, o);
        BOOST_FAIL("the windup rig was accepted by the massless cvode stepper");
    } catch (const InputError& e) {
        BOOST_TEST_MESSAGE(e.what());
        BOOST_TEST(e.field() == "loading.seat_rotation_rad");
    }
    // a seat load that does not start from 0: the start's forces are solved again with S(0) (the stage
    // solves them without it), and the balance closes from there
    Loading step = seat_loading(0);
    step.seat_moment_n_m = testing::constant(40.0);
    o.loading = step;
    o.t_end_s = 0.2;
    const auto r = simulate(sys, o);
    double balance = 0.0;
    for (const auto& x : r) balance = std::max(balance, std::abs(x.energy_balance_error_j));
    BOOST_TEST_MESSAGE("constant moment from t = 0: balance " << balance << " J of " << r.back().external_work_j << " J");
    BOOST_TEST(balance <= 1e-6 * std::abs(r.back().external_work_j));
    BOOST_TEST(r.front().seat_rotation_rad != 0.0);
}
