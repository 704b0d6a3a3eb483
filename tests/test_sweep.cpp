// Sweeps (stackbeam/study/sweep.hpp): the spec, the points, and run_sweep on threads.
// Built twice: in the Release and sanitizer builds, and alone in build-tsan/ under
// ThreadSanitizer (scripts/run-tests.sh), where run_sweep's threads running points of the
// library at once prove that the library keeps no mutable state shared between runs
// (a data race is a TSan report, which fails the test).
#define BOOST_TEST_MODULE sweep
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <set>

#include "stackbeam/study/sweep.hpp"
#include "stackbeam/study/sweep_output.hpp"
#include "stackbeam/run/run.hpp"

using namespace stackbeam;

namespace {

const std::string kBase = std::string(STACKBEAM_SOURCE_DIR) + "/tests/sweep/rig_small.toml";
// the spec's source name places it in tests/sweep/, so the scenario is found beside it
const std::string kSource = std::string(STACKBEAM_SOURCE_DIR) + "/tests/sweep/in_code.toml";

/// Bitwise equal figures (NaN equal to NaN: the same missing figure).
bool same(const std::vector<double>& a, const std::vector<double>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

SweepSpec small_map() {
    return parse_sweep_spec("scenario = \"rig_small.toml\"\n"
                            "[[axes]]\nkey = \"loading.displacement_m.amplitude\"\nvalues = [0.01, 0.02]\n"
                            "[[axes]]\nkey = \"interfaces[*].friction_coefficient\"\nvalues = [0.2, 0.5]\n",
                            kSource);
}

}  // namespace

BOOST_AUTO_TEST_CASE(ranges_and_points) {
    const SweepSpec spec = parse_sweep_spec("scenario = \"rig_small.toml\"\n"
                                            "[[axes]]\nkey = \"loading.displacement_m.frequency_hz\"\n"
                                            "from = 0.5\nto = 8.0\ncount = 5\nspacing = \"log\"\n"
                                            "[[axes]]\nkey = \"mesh.element_length_m\"\nvalues = [0.05, 0.025]\n",
                                            kSource);
    BOOST_REQUIRE_EQUAL(spec.axes.size(), 2u);
    const auto& f = spec.axes[0].values;
    BOOST_REQUIRE_EQUAL(f.size(), 5u);
    // the ends exactly as written; between them a geometric progression (ratio 2 here), to round-off
    BOOST_TEST(std::get<double>(f[0]) == 0.5);
    BOOST_TEST(std::get<double>(f[4]) == 8.0);
    for (int i = 1; i < 4; ++i) BOOST_TEST(std::get<double>(f[i]) == 0.5 * std::pow(2.0, i), boost::test_tools::tolerance(1e-14));
    BOOST_TEST(point_count(spec) == 10);
    const auto points = expand_points(spec);
    BOOST_REQUIRE_EQUAL(points.size(), 10u);
    // the product: the last axis varies fastest; each point's scenario carries its values
    BOOST_TEST(points[3].scenario.simulation.loading.displacement_m.frequency_hz == std::get<double>(f[1]));
    BOOST_TEST(points[3].scenario.model.mesh.element_length_m == 0.025);
    BOOST_TEST(points[4].scenario.model.mesh.element_length_m == 0.05);
    // [*]: every interface
    const SweepSpec mu = small_map();
    const auto mp = expand_points(mu);
    BOOST_REQUIRE_EQUAL(mp.size(), 4u);
    for (const auto& i : mp[1].scenario.model.interfaces) BOOST_TEST(i.friction_coefficient == 0.5);
    BOOST_TEST(mp[1].scenario.simulation.loading.displacement_m.amplitude == 0.01);
    // the point's scenario has no [outputs] (the sweep writes its own)
    BOOST_TEST(mp[0].scenario.outputs.csv_path.empty());
}

BOOST_AUTO_TEST_CASE(zip_and_errors) {
    const SweepSpec zip = parse_sweep_spec("scenario = \"rig_small.toml\"\ncombine = \"zip\"\n"
                                           "[[axes]]\nkey = \"clamps[*].preload_n\"\nvalues = [500.0, 800, 1000.0]\n"
                                           "[[axes]]\nkey = \"interfaces[1].friction_coefficient\"\nvalues = [0.1, 0.2, 0.3]\n",
                                           kSource);
    const auto zp = expand_points(zip);
    BOOST_REQUIRE_EQUAL(zp.size(), 3u);
    BOOST_TEST(zp[1].scenario.model.clamps[3].preload_n == 800.0);  // an integer value where a float is wanted
    BOOST_TEST(zp[2].scenario.model.interfaces[1].friction_coefficient == 0.3);
    BOOST_TEST(zp[2].scenario.model.interfaces[0].friction_coefficient == 0.5);  // the base's
    // an error names the spec's line, the key and the point
    try {
        expand_points(parse_sweep_spec("scenario = \"rig_small.toml\"\n[[axes]]\nkey = \"leaves[*].height_m\"\n"
                                       "values = [0.005, -0.001]\n",
                                       kSource));
        BOOST_FAIL("a negative height was accepted");
    } catch (const InputError& e) {
        BOOST_TEST(e.location() == kSource + ":3");
        BOOST_TEST(e.field() == "leaves[0].height_m");
        BOOST_TEST(std::string(e.what()).find("at point 1 (leaves[*].height_m = -0.001)") != std::string::npos, e.what());
    }
    BOOST_CHECK_THROW(parse_sweep_spec("scenario = \"rig_small.toml\"\n[[axes]]\nkey = \"a..b\"\nvalues = [1]\n", kSource),
                      InputError);
}

BOOST_AUTO_TEST_CASE(rows_round_trip) {
    const SweepSpec spec = small_map();
    const auto points = expand_points(spec);
    PointResult r;
    r.index = 2;
    r.status = PointStatus::failed;
    r.message = "solver failure, at \"t\" = 0.1";
    r.figures.assign(point_figure_columns().size(), std::nan(""));
    r.figures[0] = 0.1;
    r.figures[3] = -1.0 / 3.0;
    r.wall_s = 0.25;
    const PointResult back = parse_point_row(spec, format_point_row(points[2], r));
    BOOST_TEST(back.index == 2);
    BOOST_TEST(back.message == r.message);
    BOOST_TEST(to_string(back.status) == std::string("failed"));
    BOOST_TEST(same(back.figures, r.figures));
    BOOST_CHECK_THROW(parse_point_row(spec, "2,0.01,0.5,ok"), std::invalid_argument);
}

// Threads: the points run on 3 threads give, bit for bit, what they give one after the
// other, each point once (and under ThreadSanitizer, no data race in the library).
BOOST_AUTO_TEST_CASE(threads_give_the_serial_figures) {
    const SweepSpec spec = small_map();
    const auto points = expand_points(spec);
    std::vector<std::vector<double>> serial(points.size()), threaded(points.size());
    SweepRunOptions one;
    one.jobs = 1;
    bool records = true;  // (no Boost.Test macro on the workers' threads)
    BOOST_TEST(run_sweep(points, one, [&](const PointResult& r) {
                   records = records && r.records != nullptr && !r.records->empty();
                   serial[static_cast<std::size_t>(r.index)] = r.figures;
               }) == 4);
    BOOST_TEST(records);
    SweepRunOptions three;
    three.jobs = 3;
    three.skip = {false, true, false, false};  // a point finished earlier (resume) is not run
    std::multiset<int> seen;
    BOOST_TEST(run_sweep(points, three, [&](const PointResult& r) {
                   seen.insert(r.index);
                   threaded[static_cast<std::size_t>(r.index)] = r.figures;
               }) == 3);
    BOOST_TEST((seen == std::multiset<int>{0, 2, 3}));
    for (std::size_t i : {0u, 2u, 3u}) {
        BOOST_TEST(same(serial[i], threaded[i]), "point " << i);
        BOOST_TEST(std::isfinite(serial[i][0]), "point " << i << " has no loop area");
    }
    // a stop flag set before the sweep: nothing runs
    std::atomic<bool> stop{true};
    SweepRunOptions stopped;
    stopped.jobs = 2;
    stopped.stop = &stop;
    BOOST_TEST(run_sweep(points, stopped, [](const PointResult&) {}) == 0);
}

// Mode cvode on threads: each run has its own SUNDIALS context and CVODE memory; the paper's
// free vibration (mode cvode, 20 ms, a coarse mesh), three friction coefficients at once, give
// bit for bit the serial figures (the energy balance error: no loop in a free vibration).
BOOST_AUTO_TEST_CASE(cvode_runs_on_threads) {
    const SweepSpec spec = parse_sweep_spec(
        "scenario = \"../../scenarios/paper_friction.toml\"\ncombine = \"zip\"\n"
        "[[axes]]\nkey = \"interfaces[*].friction_coefficient\"\nvalues = [0.3, 0.4, 0.5]\n"
        "[[axes]]\nkey = \"integrator.mode\"\nvalues = [\"cvode\", \"cvode\", \"cvode\"]\n"
        "[[axes]]\nkey = \"integrator.t_end_s\"\nvalues = [0.02, 0.02, 0.02]\n"
        "[[axes]]\nkey = \"mesh.element_length_m\"\nvalues = [0.05, 0.05, 0.05]\n",
        kSource);
    const auto points = expand_points(spec);
    std::vector<std::vector<double>> serial(points.size()), threaded(points.size());
    std::vector<std::string> status(points.size());
    SweepRunOptions one, three;
    one.jobs = 1;
    three.jobs = 3;
    run_sweep(points, one, [&](const PointResult& r) {
        serial[static_cast<std::size_t>(r.index)] = r.figures;
        status[static_cast<std::size_t>(r.index)] = to_string(r.status);
    });
    run_sweep(points, three, [&](const PointResult& r) { threaded[static_cast<std::size_t>(r.index)] = r.figures; });
    for (std::size_t i = 0; i < points.size(); ++i) {
        BOOST_TEST(status[i] == "ok", "point " << i);
        BOOST_TEST(same(serial[i], threaded[i]), "point " << i);
    }
}

// [outputs] stresses = true (issue 43 item 5): the points' stress columns are the run layer's
// figures (the largest |fibre stress| over the leaves' extremes, the same numbers: one
// computation); without it they are NaN and the other figures do not change (the flag only
// reads the state); a value not a bool is refused with its line.
BOOST_AUTO_TEST_CASE(stress_columns) {
    const std::string axes = "[[axes]]\nkey = \"interfaces[*].friction_coefficient\"\nvalues = [0.3]\n";
    const SweepSpec on = parse_sweep_spec("scenario = \"rig_small.toml\"\n[outputs]\nstresses = true\n" + axes, kSource);
    const SweepSpec off = parse_sweep_spec("scenario = \"rig_small.toml\"\n" + axes, kSource);
    BOOST_TEST(on.stresses);
    BOOST_TEST(!off.stresses);
    const auto& columns = point_figure_columns();
    BOOST_REQUIRE_EQUAL(columns.size(), 24u);  // the windup columns (19 to 23) after them: test_windup_figures
    BOOST_TEST(columns[17] == "stress_max_abs_pa");
    BOOST_TEST(columns[18] == "fatigue_least_safety_factor");
    const SweepPoint p_on = expand_points(on)[0], p_off = expand_points(off)[0];
    const PointResult with = run_point(p_on), without = run_point(p_off);
    BOOST_REQUIRE(with.status == PointStatus::ok);
    BOOST_TEST(std::isnan(without.figures[17]));
    BOOST_TEST(std::isnan(without.figures[18]));
    for (std::size_t i = 0; i < 17; ++i) BOOST_TEST(same({with.figures[i]}, {without.figures[i]}), "figure " << i);
    // the reference: the run layer's summary of the same scenario
    const System system(Model::build(p_on.scenario.model));
    RunRequest request;
    request.options = p_on.scenario.simulation;
    request.outputs.stresses = true;
    const RunSummary summary = run_scenario(system, request);
    double largest = 0.0;
    for (const LeafExtremes& e : summary.stresses->summary.extremes)
        largest = std::max({largest, std::abs(e.tension.stress_pa), std::abs(e.compression.stress_pa)});
    BOOST_TEST(with.figures[17] == largest);
    BOOST_TEST(largest > 0.0);
    BOOST_TEST(std::isnan(with.figures[18]));  // rig_small's leaves have no material
    try {
        parse_sweep_spec("scenario = \"rig_small.toml\"\n[outputs]\nstresses = \"yes\"\n" + axes, kSource);
        BOOST_FAIL("stresses = \"yes\" was accepted");
    } catch (const InputError& e) {
        BOOST_TEST(e.field() == "outputs.stresses");
        BOOST_TEST(e.location() == kSource + ":3");
    }
}
