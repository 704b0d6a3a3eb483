// The elastic layer's normal dashpots (SimulationOptions::damping.layer_normal_time_s, the massive
// stack under mode cvode: lib/time/cvode/cvode_massive.cpp; docs/time-integration.md, "Structural
// damping"; decision 071): a Kelvin-Voigt layer, eta = tau_L k_n on every closed pair with a layer.
#define BOOST_TEST_MODULE layer_damping
#include <boost/test/unit_test.hpp>
#include <algorithm>
#include <cmath>
#include <string>

#include "stackbeam/errors.hpp"
#include "stackbeam/time/stepper.hpp"
#include "test_support.hpp"

namespace tt = boost::test_tools;
using namespace stackbeam;
using namespace stackbeam::testing;

namespace {

/// The paper's friction case at 10 elements per half leaf, elastic interfaces, 10 mm clamps,
/// steel leaves (as test_cvode_massive).
System steel_friction_stack() {
    ModelSpec spec = with_elastic_interfaces(paper_stack(PaperCase::friction, 10, 3));
    for (auto& leaf : spec.leaves) leaf.density_kg_per_m3 = kSteel;
    for (auto& cl : spec.clamps) cl.length_m = 0.01;
    return System(Model::build(spec));
}

SimulationOptions massive_options(double tau_s) {
    SimulationOptions so;
    so.mode = Mode::cvode;
    so.cvode.leaf_inertia = LeafInertia::massive;
    so.dt_s = 1e-4;
    so.t_end_s = 2e-3;
    so.cvode.rtol = 1e-8;
    so.solver.tolerance_m = 1e-9;
    so.damping.rayleigh_beta_s = 1e-6;
    so.damping.layer_normal_time_s = tau_s;
    return so;
}

}  // namespace

// The dashpots damp the layer's own vibration, not the stack's motion, and their work is booked:
// 2 ms of the friction case (Rayleigh beta = 1e-6 s on the leaves, as test_cvode_massive) with
// tau_L = 1e-6 s against tau_L = 0. R's motion (the stack's 12 Hz mode, zeta = tau_L omega / 2
// ~ 4e-5 from the layer) moves by at most 1e-9 m (measured 8.6e-11 m at tau_L = 4e-7 s, ~R's
// amplitude times 1e-8); the energy balance closes to CVODE's bound, 1e3 rtol E0, with the
// dashpots' work in the damping energy.
BOOST_AUTO_TEST_CASE(dashpots_leave_the_stack_s_motion_and_close_the_balance) {
    const System sys = steel_friction_stack();
    const auto undamped = simulate(sys, massive_options(0.0));
    RunReport rep;
    const auto r = simulate(sys, massive_options(1e-6), {}, &rep);
    BOOST_TEST_REQUIRE(r.size() == undamped.size());
    double dw = 0.0;
    for (std::size_t i = 0; i < r.size(); ++i) dw = std::max(dw, std::abs(r[i].w_m - undamped[i].w_m));
    const double e0 = r.front().kinetic_energy_j + r.front().strain_energy_j;
    BOOST_TEST_MESSAGE("max |w - w(tau_L = 0)| " << dw << " m; balance " << max_balance_error(r) << " J of " << e0
                                               << " J; damping " << r.back().damping_energy_j << " J; " << rep.cvode.events
                                               << " events, " << rep.steps << " steps");
    BOOST_TEST(dw < 1e-9);
    BOOST_TEST(max_balance_error(r) < 1e3 * 1e-8 * e0);
    BOOST_TEST(r.back().damping_energy_j > 0.0);
}

// Only the massive stack takes the dashpots (a massless contact layer does not vibrate on the
// layer): every other stepper refuses the key by name; mode cvode's automatic choice takes the
// massive stack for it where every row is elastic.
BOOST_AUTO_TEST_CASE(refused_where_not_taken_and_chooses_the_massive_stack) {
    SimulationOptions so = massive_options(1e-6);
    so.damping.rayleigh_beta_s = 0.0;  // refused by the modal stepper too
    so.cvode.leaf_inertia = LeafInertia::modal;
    try {
        make_stepper(steel_friction_stack(), so);
        BOOST_FAIL("the layer's dashpots were accepted by the modal stepper");
    } catch (const InputError& e) {
        BOOST_TEST(e.field() == "damping.layer_normal_time_s");
        BOOST_TEST(std::string(e.what()).find("whole massive stack") != std::string::npos, e.what());
    }
    so.cvode.leaf_inertia = LeafInertia::automatic;
    so.t_end_s = 1e-4;
    RunReport rep;
    simulate(steel_friction_stack(), so, {}, &rep);
    BOOST_TEST(rep.cvode.retained_modes == 0);  // not the modal stepper
}
