// The caller's stop check (SimulationOptions::stop_requested): a run asked to stop ends
// promptly with RunStopped at the time it reached, inside the event driver's step loop in mode
// cvode (between two outputs; the event steppers and the held one) and between outputs in every mode.
#define BOOST_TEST_MODULE stop_check
#include <boost/test/unit_test.hpp>
#include <string>

#include "stackbeam/errors.hpp"
#include "stackbeam/time/simulation.hpp"
#include "test_support.hpp"

using namespace stackbeam;
using namespace stackbeam::testing;

namespace {

SimulationOptions cvode_options() {
    SimulationOptions o;
    o.mode = Mode::cvode;
    o.t_end_s = 0.6;
    o.dt_s = 0.6;  // one output interval: every step of the run lies between two outputs
    return o;
}

/// Asked to stop at the 3rd poll (simulate() polls once before the output, the driver then at
/// 64 and 128 CVODE steps), the run of `s` stops after 128 steps, long before t_end, and says so.
void stops_at_the_third_poll(const System& s) {
    SimulationOptions o = cvode_options();
    int polls = 0;
    o.stop_requested = [&polls] { return ++polls >= 3; };
    try {
        simulate(s, o);
        BOOST_FAIL("the run did not stop");
    } catch (const RunStopped& e) {
        BOOST_TEST(polls == 3);
        BOOST_TEST(e.step() >= 2 * 64);
        BOOST_TEST(e.step() < 3 * 64);
        BOOST_TEST(e.time_s() > 0.0);
        BOOST_TEST(e.time_s() < o.t_end_s);
        BOOST_TEST(std::string(e.what()).find("stopped on request") != std::string::npos);
    }
}

}  // namespace

// The stop is seen inside the driver's loop: with a single output interval no record reaches
// the caller before t_end, so only the driver's poll (every 64 CVODE steps) can stop the run
// (the friction case takes thousands of steps).
BOOST_AUTO_TEST_CASE(cvode_run_stops_inside_a_step) {
    stops_at_the_third_poll(System(Model::build(paper_example(PaperCase::friction))));
}

// The held stepper (steel leaves on the bonded stack: every pair held, no events) runs in the
// same driver loop (its 0.6 s take about 20,000 steps: BDF on the leaf modes).
BOOST_AUTO_TEST_CASE(cvode_held_run_stops_inside_a_step) {
    stops_at_the_third_poll(System(Model::build(paper_with_mass(PaperCase::bonded, 7850.0, false))));
}

// Without a request the same run ends normally (the check is polled and answers false).
BOOST_AUTO_TEST_CASE(cvode_run_without_request_completes) {
    const System s(Model::build(paper_example(PaperCase::friction)));
    SimulationOptions o = cvode_options();
    int polls = 0;
    o.stop_requested = [&polls] { ++polls; return false; };
    const auto records = simulate(s, o);
    BOOST_TEST(records.size() == 2u);
    BOOST_TEST(polls > 0);
}

// Every mode: a request between outputs ends the run after the records already delivered.
BOOST_AUTO_TEST_CASE(closed_form_run_stops_between_outputs) {
    const System s(Model::build(paper_example(PaperCase::friction)));
    SimulationOptions o;
    o.t_end_s = 0.01;
    o.dt_s = 1e-3;
    long delivered = 0;
    o.stop_requested = [&delivered] { return delivered >= 4; };
    BOOST_CHECK_THROW(simulate(s, o, [&delivered](const StepRecord&) { ++delivered; }), RunStopped);
    BOOST_TEST(delivered == 4);
}
