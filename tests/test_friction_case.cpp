#include "stackbeam/time/closed_form_stepper.hpp"
// The friction case of the paper example (mu = 0.5, clamp force 1000 N): no
#include "stackbeam/time/closed_form_stepper.hpp"
// analytic solution, so it is proved by balances and convergence: half model =
#include "stackbeam/time/closed_form_stepper.hpp"
// full model, energy balance closing as O(dt^2), convergence in dt, and the
#include "stackbeam/time/closed_form_stepper.hpp"
// shape of the hysteresis loop.
#include "stackbeam/time/closed_form_stepper.hpp"
#define BOOST_TEST_MODULE friction_case
#include "stackbeam/time/closed_form_stepper.hpp"
#include <boost/test/unit_test.hpp>
#include "stackbeam/time/closed_form_stepper.hpp"
#include <algorithm>
#include "stackbeam/time/closed_form_stepper.hpp"
#include <cmath>
#include "stackbeam/time/closed_form_stepper.hpp"

#include "stackbeam/time/closed_form_stepper.hpp"
#include "test_support.hpp"
#include "stackbeam/time/closed_form_stepper.hpp"

#include "stackbeam/time/closed_form_stepper.hpp"
namespace tt = boost::test_tools;
#include "stackbeam/time/closed_form_stepper.hpp"
using namespace stackbeam;
#include "stackbeam/time/closed_form_stepper.hpp"
using namespace stackbeam::testing;
#include "stackbeam/time/closed_form_stepper.hpp"

#include "stackbeam/time/closed_form_stepper.hpp"
BOOST_AUTO_TEST_CASE(half_model_equals_full_model) {
#include "stackbeam/time/closed_form_stepper.hpp"
    // The full model (40 elements per leaf) is the half model mirrored: the same
#include "stackbeam/time/closed_form_stepper.hpp"
    // equations, so the same response up to round-off amplified by cond(W) ~ 1e5:
#include "stackbeam/time/closed_form_stepper.hpp"
    // 1e-10 m on w (of 76 mm), 1e-6 N on forces (of ~1000 N), 1e-9 J on energies.
#include "stackbeam/time/closed_form_stepper.hpp"
    // Over 1 s: through the first reversals and the clamps' last slips.
#include "stackbeam/time/closed_form_stepper.hpp"
    const auto h = run_paper(PaperCase::friction, 1.0, 1e-3, Symmetry::half);
#include "stackbeam/time/closed_form_stepper.hpp"
    const auto f = run_paper(PaperCase::friction, 1.0, 1e-3, Symmetry::full);
#include "stackbeam/time/closed_form_stepper.hpp"
    BOOST_TEST_REQUIRE(h.size() == f.size());
#include "stackbeam/time/closed_form_stepper.hpp"
    for (std::size_t i = 0; i < h.size(); ++i) {
#include "stackbeam/time/closed_form_stepper.hpp"
        BOOST_CHECK_SMALL(h[i].w_m - f[i].w_m, 1e-10);
#include "stackbeam/time/closed_form_stepper.hpp"
        BOOST_CHECK_SMALL(h[i].force_on_mass_n - f[i].force_on_mass_n, 1e-6);
#include "stackbeam/time/closed_form_stepper.hpp"
        BOOST_CHECK_SMALL(h[i].probe_friction_force_n - f[i].probe_friction_force_n, 1e-6);
#include "stackbeam/time/closed_form_stepper.hpp"
        BOOST_CHECK_SMALL(h[i].dissipated_energy_j - f[i].dissipated_energy_j, 1e-9);
#include "stackbeam/time/closed_form_stepper.hpp"
    }
#include "stackbeam/time/closed_form_stepper.hpp"
}
#include "stackbeam/time/closed_form_stepper.hpp"

#include "stackbeam/time/closed_form_stepper.hpp"
BOOST_AUTO_TEST_CASE(energy_balance_closes_as_dt_squared) {
#include "stackbeam/time/closed_form_stepper.hpp"
    // kinetic + strain + dissipated = 40 J (m v0^2 / 2). The dissipated work is the
#include "stackbeam/time/closed_form_stepper.hpp"
    // trapezoidal friction work over the slip increments, consistent with eq. 14;
#include "stackbeam/time/closed_form_stepper.hpp"
    // the balance error is then the O(dt^3) local error of that rule, O(dt^2) over
#include "stackbeam/time/closed_form_stepper.hpp"
    // the run: halving dt must divide it by 4 (measured 4.1 and 4.1: tolerance 10 %),
#include "stackbeam/time/closed_form_stepper.hpp"
    // and at the paper's dt it is below 1e-4 of the 40 J.
#include "stackbeam/time/closed_form_stepper.hpp"
    double prev = 0.0;
#include "stackbeam/time/closed_form_stepper.hpp"
    for (double dt : {1e-3, 5e-4, 2.5e-4}) {
#include "stackbeam/time/closed_form_stepper.hpp"
        const auto r = run_paper(PaperCase::friction, 0.3, dt);
#include "stackbeam/time/closed_form_stepper.hpp"
        double worst = 0.0;
#include "stackbeam/time/closed_form_stepper.hpp"
        for (const auto& x : r) {
#include "stackbeam/time/closed_form_stepper.hpp"
            worst = std::max(worst, std::abs(x.energy_balance_error_j));
#include "stackbeam/time/closed_form_stepper.hpp"
            BOOST_TEST(x.dissipated_energy_j >= -1e-12);  // friction only takes energy out
#include "stackbeam/time/closed_form_stepper.hpp"
        }
#include "stackbeam/time/closed_form_stepper.hpp"
        BOOST_TEST_MESSAGE("dt " << dt << ": max |energy balance error| " << worst << " J");
#include "stackbeam/time/closed_form_stepper.hpp"
        if (dt == 1e-3) BOOST_TEST(worst < 40.0 * 1e-4);
#include "stackbeam/time/closed_form_stepper.hpp"
        if (prev > 0.0) BOOST_TEST(prev / worst == 4.0, tt::tolerance(0.1));
#include "stackbeam/time/closed_form_stepper.hpp"
        prev = worst;
#include "stackbeam/time/closed_form_stepper.hpp"
    }
#include "stackbeam/time/closed_form_stepper.hpp"
}
#include "stackbeam/time/closed_form_stepper.hpp"

#include "stackbeam/time/closed_form_stepper.hpp"
BOOST_AUTO_TEST_CASE(response_converges_in_dt) {
#include "stackbeam/time/closed_form_stepper.hpp"
    // w(t) on 0 <= t <= 0.3 s against a run at dt = 1/8 ms. The scheme is second
#include "stackbeam/time/closed_form_stepper.hpp"
    // order between stick-slip events; a transition inside a step is resolved only at
#include "stackbeam/time/closed_form_stepper.hpp"
    // the step's end, which adds an error that falls at least as fast here (measured:
#include "stackbeam/time/closed_form_stepper.hpp"
    // 2.5e-5 m -> 3.8e-6 m, ratio 6.6). At least second order: ratio > 3.5.
#include "stackbeam/time/closed_form_stepper.hpp"
    const auto ref = run_paper(PaperCase::friction, 0.3, 1.25e-4);
#include "stackbeam/time/closed_form_stepper.hpp"
    auto deviation = [&](double dt) {
#include "stackbeam/time/closed_form_stepper.hpp"
        const auto r = run_paper(PaperCase::friction, 0.3, dt);
#include "stackbeam/time/closed_form_stepper.hpp"
        const int stride = static_cast<int>(std::lround(dt / 1.25e-4));
#include "stackbeam/time/closed_form_stepper.hpp"
        double d = 0.0;
#include "stackbeam/time/closed_form_stepper.hpp"
        for (std::size_t i = 0; i < r.size(); ++i) d = std::max(d, std::abs(r[i].w_m - ref[i * stride].w_m));
#include "stackbeam/time/closed_form_stepper.hpp"
        return d;
#include "stackbeam/time/closed_form_stepper.hpp"
    };
#include "stackbeam/time/closed_form_stepper.hpp"
    const double d1 = deviation(1e-3), d2 = deviation(5e-4);
#include "stackbeam/time/closed_form_stepper.hpp"
    BOOST_TEST_MESSAGE("max |w - w_ref|: dt 1 ms " << d1 << " m, 0.5 ms " << d2 << " m");
#include "stackbeam/time/closed_form_stepper.hpp"
    BOOST_TEST(d1 / d2 > 3.5);
#include "stackbeam/time/closed_form_stepper.hpp"
    BOOST_TEST(d1 < 2e-3 * 0.076);  // below 0.2 % of the first peak at the paper's dt
#include "stackbeam/time/closed_form_stepper.hpp"
}
#include "stackbeam/time/closed_form_stepper.hpp"

#include "stackbeam/time/closed_form_stepper.hpp"
BOOST_AUTO_TEST_CASE(hysteresis_loop_has_the_paper_shape) {
#include "stackbeam/time/closed_form_stepper.hpp"
    // Force on R vs w (paper Fig. 6, like Cebon 1986): while every clamp slips, the
#include "stackbeam/time/closed_form_stepper.hpp"
    // friction forces sit at their limits, nearly constant, so the branch is a line of
#include "stackbeam/time/closed_form_stepper.hpp"
    // the frictionless slope 12,000 N/m, shifted against the motion (friction opposes
#include "stackbeam/time/closed_form_stepper.hpp"
    // it); at each reversal the clamps stick and the loop turns on a much stiffer
#include "stackbeam/time/closed_form_stepper.hpp"
    // branch (bounded by the bonded stack's 107,404 N/m). The clamp reactions vary the
#include "stackbeam/time/closed_form_stepper.hpp"
    // limits by under 1 %: slope tolerance 2 %.
#include "stackbeam/time/closed_form_stepper.hpp"
    const System sys(Model::build(paper_example(PaperCase::friction)));
#include "stackbeam/time/closed_form_stepper.hpp"
    const double k_free = sys.free_stiffness_n_per_m();
#include "stackbeam/time/closed_form_stepper.hpp"
    const double k_bonded = System(Model::build(paper_example(PaperCase::bonded))).tied_stiffness_n_per_m();
#include "stackbeam/time/closed_form_stepper.hpp"
    const auto r = run_paper(PaperCase::friction, 0.45, 1e-3);
#include "stackbeam/time/closed_form_stepper.hpp"
    int slip_segments = 0, stick_segments = 0;
#include "stackbeam/time/closed_form_stepper.hpp"
    for (std::size_t i = 1; i < r.size(); ++i) {
#include "stackbeam/time/closed_form_stepper.hpp"
        const auto &a = r[i - 1], &b = r[i];
#include "stackbeam/time/closed_form_stepper.hpp"
        const double slope = -(b.force_on_mass_n - a.force_on_mass_n) / (b.w_m - a.w_m);
#include "stackbeam/time/closed_form_stepper.hpp"
        if (a.n_stick == 0 && b.n_stick == 0 && a.n_slip == 8 && b.n_slip == 8) {
#include "stackbeam/time/closed_form_stepper.hpp"
            ++slip_segments;
#include "stackbeam/time/closed_form_stepper.hpp"
            BOOST_TEST(slope == k_free, tt::tolerance(0.02));
#include "stackbeam/time/closed_form_stepper.hpp"
            // offset of the branch: F + k w opposes the motion over the step (the slip
#include "stackbeam/time/closed_form_stepper.hpp"
            // is the step's increment; at a reversal the end velocity may already have turned)
#include "stackbeam/time/closed_form_stepper.hpp"
            BOOST_TEST((b.force_on_mass_n + k_free * b.w_m) * (b.w_m - a.w_m) < 0.0);
#include "stackbeam/time/closed_form_stepper.hpp"
        } else if (a.n_slip == 0 && b.n_slip == 0 && std::abs(b.w_m - a.w_m) > 1e-6) {
#include "stackbeam/time/closed_form_stepper.hpp"
            ++stick_segments;  // all pairs in contact stick: the stiff branch at a reversal
#include "stackbeam/time/closed_form_stepper.hpp"
            BOOST_TEST(slope > 3.0 * k_free);
#include "stackbeam/time/closed_form_stepper.hpp"
            BOOST_TEST(slope < k_bonded);
#include "stackbeam/time/closed_form_stepper.hpp"
        }
#include "stackbeam/time/closed_form_stepper.hpp"
    }
#include "stackbeam/time/closed_form_stepper.hpp"
    BOOST_TEST(slip_segments > 200);
#include "stackbeam/time/closed_form_stepper.hpp"
    BOOST_TEST(stick_segments >= 1);
#include "stackbeam/time/closed_form_stepper.hpp"
}
#include "stackbeam/time/closed_form_stepper.hpp"

#include "stackbeam/time/closed_form_stepper.hpp"
BOOST_AUTO_TEST_CASE(clamps_stick_for_good_and_motion_becomes_near_periodic) {
#include "stackbeam/time/closed_form_stepper.hpp"
    // Energy drains through the clamps until their friction can hold the spring force;
#include "stackbeam/time/closed_form_stepper.hpp"
    // then the clamp points stick for good (paper: "nearly periodic" motion). After
#include "stackbeam/time/closed_form_stepper.hpp"
    // that only a little slip near the clamps remains: over the last 0.5 s of a 2 s
#include "stackbeam/time/closed_form_stepper.hpp"
    // run the successive periods agree within 1 % and less than 1 % of 40 J is dissipated.
#include "stackbeam/time/closed_form_stepper.hpp"
    const auto r = run_paper(PaperCase::friction, 2.0, 1e-3, Symmetry::half, 1e-10);
#include "stackbeam/time/closed_form_stepper.hpp"
    const System sys(Model::build(paper_example(PaperCase::friction)));
#include "stackbeam/time/closed_form_stepper.hpp"
    double last_clamp_slip = 0.0;
#include "stackbeam/time/closed_form_stepper.hpp"
    {
#include "stackbeam/time/closed_form_stepper.hpp"
        SimulationOptions so;
#include "stackbeam/time/closed_form_stepper.hpp"
        so.solver.tolerance_m = 1e-10;
#include "stackbeam/time/closed_form_stepper.hpp"
        ClosedFormStepper st(sys, so);
#include "stackbeam/time/closed_form_stepper.hpp"
        while (st.current().t_s < 2.0 - 1e-9) {
#include "stackbeam/time/closed_form_stepper.hpp"
            st.advance();
#include "stackbeam/time/closed_form_stepper.hpp"
            const auto states = st.pair_states();
#include "stackbeam/time/closed_form_stepper.hpp"
            for (std::size_t k = 0; k < states.size(); ++k)
#include "stackbeam/time/closed_form_stepper.hpp"
                if (sys.pairs()[k].kind == PairKind::clamp && states[k] == PairState::slip) last_clamp_slip = st.current().t_s;
#include "stackbeam/time/closed_form_stepper.hpp"
        }
#include "stackbeam/time/closed_form_stepper.hpp"
    }
#include "stackbeam/time/closed_form_stepper.hpp"
    BOOST_TEST_MESSAGE("clamps stick for good after t = " << last_clamp_slip << " s");
#include "stackbeam/time/closed_form_stepper.hpp"
    BOOST_TEST(last_clamp_slip > 0.3);
#include "stackbeam/time/closed_form_stepper.hpp"
    BOOST_TEST(last_clamp_slip < 1.5);
#include "stackbeam/time/closed_form_stepper.hpp"
    // periods of the oscillation about its mean over the last 0.5 s
#include "stackbeam/time/closed_form_stepper.hpp"
    double mean = 0.0;
#include "stackbeam/time/closed_form_stepper.hpp"
    int n = 0;
#include "stackbeam/time/closed_form_stepper.hpp"
    for (const auto& x : r)
#include "stackbeam/time/closed_form_stepper.hpp"
        if (x.t_s >= 1.5) mean += x.w_m, ++n;
#include "stackbeam/time/closed_form_stepper.hpp"
    mean /= n;
#include "stackbeam/time/closed_form_stepper.hpp"
    std::vector<double> up;  // upward crossings of the mean, interpolated between steps
#include "stackbeam/time/closed_form_stepper.hpp"
    for (std::size_t i = 1; i < r.size(); ++i)
#include "stackbeam/time/closed_form_stepper.hpp"
        if (r[i].t_s >= 1.5 && r[i - 1].w_m < mean && r[i].w_m >= mean)
#include "stackbeam/time/closed_form_stepper.hpp"
            up.push_back(r[i - 1].t_s + 1e-3 * (mean - r[i - 1].w_m) / (r[i].w_m - r[i - 1].w_m));
#include "stackbeam/time/closed_form_stepper.hpp"
    BOOST_TEST_REQUIRE(up.size() >= 3);
#include "stackbeam/time/closed_form_stepper.hpp"
    for (std::size_t i = 2; i < up.size(); ++i) BOOST_TEST(up[i] - up[i - 1] == up[1] - up[0], tt::tolerance(0.01));
#include "stackbeam/time/closed_form_stepper.hpp"
    const auto at = [&](double t) { return r[static_cast<std::size_t>(std::lround(t / 1e-3))]; };
#include "stackbeam/time/closed_form_stepper.hpp"
    BOOST_TEST(at(2.0).dissipated_energy_j - at(1.5).dissipated_energy_j < 0.4);
#include "stackbeam/time/closed_form_stepper.hpp"
}
