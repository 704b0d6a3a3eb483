// Calibration (stackbeam/study/fit.hpp): loops made by stackbeam at known parameters, with
// seeded noise, fitted back; a parameter the data cannot identify; threads; bad input.
#define BOOST_TEST_MODULE fit
#include <boost/test/unit_test.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <unistd.h>

#include "stackbeam/post/hysteresis.hpp"
#include "stackbeam/study/fit.hpp"

using namespace stackbeam;

namespace {

/// The paper's friction spring on the rig (scenarios/rig_friction.toml) made small for the
/// tests: 10 elements per half leaf, 100 records per cycle, 2 cycles (the second is steady:
/// a triangle stroke from w = 0 repeats its loop from the first return through 0 on).
std::string paper_rig(const std::string& interface_extra = "", double mu = 0.5, const char* law = "coulomb") {
    std::ostringstream s;
    for (int i = 0; i < 3; ++i)
        s << "[[leaves]]\nlength_m = 0.5\nx_start_m = 0.0\nheight_m = 0.005\nwidth_m = 0.05\nyoungs_modulus_pa = 2e10\n"
             "density_kg_per_m3 = 0.0\nleft_support = \"pinned\"\nright_support = \"pinned\"\n";
    for (int i = 0; i < 2; ++i)
        s << "[[interfaces]]\nlaw = \"" << law << "\"\nfriction_coefficient = " << mu << "\n" << interface_extra;
    for (double x : {0.1, 0.2, 0.3, 0.4}) s << "[[clamps]]\nx_m = " << x << "\npreload_n = 1000.0\n";
    s << "[rigid_body]\nmass_kg = 20.0\nx_m = 0.25\n"
         "[loading]\nkind = \"prescribed-displacement\"\n[loading.displacement_m]\nshape = \"triangle\"\namplitude = 0.02\n"
         "frequency_hz = 1.0\n[mesh]\nelement_length_m = 0.025\nsymmetry = \"half\"\n"
         "[integrator]\nmode = \"closed-form\"\ndt_s = 0.01\nt_end_s = 2.0\n[integrator.solver]\nkind = \"exact\"\n"
         "tolerance_m = 1e-9\n";
    return s.str();
}

/// A graduated 3-leaf spring (scenarios/graduated_elastic.toml's shape) with elastic interfaces, on the rig.
std::string graduated_rig() {
    std::ostringstream s;
    const double lengths[] = {0.5, 0.38, 0.26};
    for (int i = 0; i < 3; ++i)
        s << "[[leaves]]\nlength_m = " << lengths[i] << "\nx_start_m = " << 0.5 * (0.5 - lengths[i])
          << "\nheight_m = 0.005\nwidth_m = 0.05\nyoungs_modulus_pa = 2e10\ndensity_kg_per_m3 = 0.0\n"
          << (i == 0 ? "left_support = \"pinned\"\nright_support = \"pinned\"\n" : "left_support = \"free\"\nright_support = \"free\"\n");
    for (int i = 0; i < 2; ++i)
        s << "[[interfaces]]\nlaw = \"coulomb\"\nfriction_coefficient = 0.4\ncontact = \"elastic\"\n"
             "tangential_stiffness_pa_per_m = 2e8\n";
    for (double x : {0.2, 0.3}) s << "[[clamps]]\nx_m = " << x << "\npreload_n = 1000.0\n";
    s << "[rigid_body]\nmass_kg = 20.0\nx_m = 0.25\n"
         "[loading]\nkind = \"prescribed-displacement\"\n[loading.displacement_m]\nshape = \"triangle\"\namplitude = 0.02\n"
         "frequency_hz = 1.0\n[mesh]\nelement_length_m = 0.01\nsymmetry = \"half\"\n"
         "[integrator]\nmode = \"closed-form\"\ndt_s = 0.001\nt_end_s = 2.0\n[integrator.solver]\nkind = \"exact\"\n"
         "tolerance_m = 1e-9\n";
    return s.str();
}

/// The scenario `text` with `values` set at their keys (a sweep point).
SweepPoint point_of(const std::string& text, const std::vector<std::pair<std::string, double>>& values) {
    SweepSpec s;
    s.source = "test";
    s.scenario_path = "test.toml";
    s.scenario_text = text;
    for (const auto& [key, value] : values) s.axes.push_back({key, {value}, ""});
    if (s.axes.empty()) s.axes.push_back({"description", {std::string("test")}, ""});
    return SweepPoints(s).point(0);
}

struct Made {
    std::string csv;      ///< the last cycle, w_m and force_n, noise added
    double area_j = 0.0;  ///< the loop area without noise
};

/// The last cycle of the scenario run at `values`, its force with Gaussian noise of standard
/// deviation `noise` times the force half-range (seeded).
Made make_loop(const std::string& text, const std::vector<std::pair<std::string, double>>& values, double noise,
               unsigned seed) {
    const SweepPoint p = point_of(text, values);
    Made made;
    run_point(p, nullptr, [&](const PointResult& r) {
        BOOST_REQUIRE(r.status == PointStatus::ok);
        const auto cycle = last_cycle(*r.records, p.scenario.simulation.loading.period_s());
        const HysteresisMetrics m = hysteresis_metrics(*r.records, cycle.first, cycle.second);
        made.area_j = m.loop_area_j;
        std::mt19937 rng(seed);
        std::normal_distribution<double> normal(0.0, noise * 0.5 * (m.force_max_n - m.force_min_n));
        std::ostringstream csv;
        csv.precision(17);
        csv << "time_s,w_m,force_n\n";
        for (const StepRecord& rec : *r.records)
            if (rec.t_s >= cycle.first && rec.t_s <= cycle.second)
                csv << rec.t_s << "," << rec.w_m << "," << rec.spring_force_n + normal(rng) << "\n";
        made.csv = csv.str();
    });
    return made;
}

FitSpec spec_of(const std::string& scenario, const std::string& csv, const std::vector<FitParameter>& parameters) {
    FitSpec spec;
    spec.source = "test";
    spec.scenario_path = "test.toml";
    spec.scenario_text = scenario;
    spec.parameters = parameters;
    MeasuredLoop loop;
    loop.name = "loops[0]";
    loop.displacement_column = "w_m";
    loop.force_column = "force_n";
    read_loop_csv(csv, loop, 0.05, "loops[0]");
    spec.loops.push_back(loop);
    return spec;
}

const std::string kMu = "interfaces[*].friction_coefficient";
const std::string kKt = "interfaces[*].tangential_stiffness_pa_per_m";

/// A directory of files for the spec reader's tests (removed at the end).
struct Files {
    std::filesystem::path dir = std::filesystem::temp_directory_path() / ("stackbeam_test_fit_" + std::to_string(getpid()));
    Files() { std::filesystem::create_directories(dir); }
    ~Files() { std::filesystem::remove_all(dir); }
    std::string write(const std::string& name, const std::string& text) const {
        std::ofstream(dir / name) << text;
        return (dir / name).string();
    }
};

template <class F>
void expect_error(F f, const std::string& field, const std::string& words) {
    try {
        f();
        BOOST_ERROR("no InputError (expected " << field << ": " << words << ")");
    } catch (const InputError& e) {
        BOOST_TEST_INFO(e.what());
        BOOST_TEST(e.field() == field);
        BOOST_TEST(std::string(e.what()).find(words) != std::string::npos);
    }
}

}  // namespace

// The paper's rig spring, mu = 0.5, 1 % force noise (seeded): mu fitted back from 0.75
// (50 % off). With 100 samples of 1 % noise the standard error of mu is about
// 1 % / sqrt(100) of the loop's sensitivity, ~0.1 % of mu: the brief's 2 % bound holds with
// a wide margin, and the fit's own standard error must say it (below 1 %). The loop area
// of the fitted loop against the noise-free one: within 1 % (the noise averages out of the
// closed integral, and mu's error moves the area in proportion).
BOOST_AUTO_TEST_CASE(paper_rig_friction_round_trip) {
    const std::string scenario = paper_rig();
    const Made made = make_loop(scenario, {}, 0.01, 46);
    FitSpec spec = spec_of(scenario, made.csv, {{kMu, 0.1, 1.0, 0.75, ""}});
    const FitResult r = fit(spec, FitOptions{1, nullptr, {}, {}});
    BOOST_TEST_MESSAGE("mu " << r.parameters[0].value << " +- " << r.parameters[0].standard_error << ", " << r.runs
                             << " runs, " << r.iterations << " iterations: " << r.termination);
    BOOST_TEST(r.parameters[0].identifiable);
    BOOST_TEST(std::abs(r.parameters[0].value - 0.5) < 0.02 * 0.5);
    BOOST_TEST(r.parameters[0].standard_error < 0.01 * 0.5);
    BOOST_TEST(std::abs(r.loops[0].fitted_area_j - made.area_j) < 0.01 * made.area_j);
    BOOST_TEST(r.warnings.empty());
    // the fitted scenario holds the value
    BOOST_TEST(r.fitted_scenario_text.find("friction_coefficient") != std::string::npos);
    const Scenario fitted = parse_scenario(r.fitted_scenario_text, "fitted");
    BOOST_TEST(fitted.model.interfaces[0].friction_coefficient == r.parameters[0].value);
}

// Two threads give the same fit as one, figure for figure: the runs are deterministic and
// their residuals go to their place whatever the order they finish in.
BOOST_AUTO_TEST_CASE(threads_give_the_same_fit) {
    const std::string scenario = paper_rig();
    const Made made = make_loop(scenario, {{kMu, 0.4}}, 0.01, 7);
    FitSpec spec = spec_of(scenario, made.csv, {{kMu, 0.1, 1.0, 0.6, ""}, {"clamps[*].preload_n", 500.0, 2000.0, 1200.0, ""}});
    spec.max_iterations = 4;
    const FitResult one = fit(spec, FitOptions{1, nullptr, {}, {}});
    const FitResult two = fit(spec, FitOptions{2, nullptr, {}, {}});
    for (std::size_t j = 0; j < 2; ++j) {
        BOOST_TEST(one.parameters[j].value == two.parameters[j].value);
        BOOST_TEST(one.parameters[j].standard_error == two.parameters[j].standard_error);
    }
    BOOST_TEST(one.cost == two.cost);
    BOOST_TEST(one.runs == two.runs);
    BOOST_TEST(one.history.size() == two.history.size());
}

// A frictionless loop (mu = 0): the clamp preload has no effect on it, so its column of
// the Jacobian is zero. It must come back as not identifiable with an infinite standard
// error and a warning, not as a confident value.
BOOST_AUTO_TEST_CASE(preload_on_a_frictionless_loop_is_not_identifiable) {
    const std::string scenario = paper_rig("", 0.0);
    const Made made = make_loop(scenario, {}, 0.01, 3);
    FitSpec spec = spec_of(scenario, made.csv, {{"clamps[*].preload_n", 500.0, 2000.0, 1500.0, ""}});
    const FitResult r = fit(spec, FitOptions{1, nullptr, {}, {}});
    BOOST_TEST(!r.parameters[0].identifiable);
    BOOST_TEST(std::isinf(r.parameters[0].standard_error));
    BOOST_REQUIRE(!r.warnings.empty());
    BOOST_TEST(r.warnings[0].find("not identifiable") != std::string::npos);
}

// A graduated spring with elastic interfaces (k_t = 2e8 Pa/m, mu = 0.4), two loops (20 mm
// and 4 mm strokes), 1 % noise: mu and k_t fitted back from 50 % off (0.6 and 3e8), mu
// within 2 %, k_t within 5 %, loop area within 1 %, for every one of six noise seeds.
// How much data that takes: k_t shapes only the turning zones of the 20 mm loop (the 4 mm
// and smaller loops add almost nothing: below 2 mm the spring sticks whole and its rate
// hardly depends on k_t), so k_t's standard error falls only as 1/sqrt(samples). Measured over
// 12 seeds: 1000 samples a loop (a 1 kHz rig) give 3.9 % (errors up to 7.6 %: 5 % is 1.3
// standard errors, 3 of 12 seeds fail), 4000 give 1.95 % (up to 3.5 %), 10,000 (a 10 kHz rig)
// 1.24 % (up to 2.9 %): the brief's 5 % is then 4 standard errors. So the "measured" loops are
// sampled at 10 kHz (dt 0.1 ms) while the model runs at dt 1 ms, its loop interpolated at the
// measured w: without noise that fits k_t back within 0.07 % (the friction path's
// dependence on the step), mu within 3e-6: well inside both bounds. The fit's own standard
// error must say so (below 2.5 %, twice the measured 1.24 %).
BOOST_AUTO_TEST_CASE(graduated_elastic_round_trip, *boost::unit_test::label("slow")) {
    const std::string scenario = graduated_rig();
    const std::string amplitude = "loading.displacement_m.amplitude";
    const std::pair<std::string, double> rig_10_khz{"integrator.dt_s", 1e-4};
    for (const unsigned seed : {59u, 100u, 200u, 300u, 400u, 500u}) {
        BOOST_TEST_CONTEXT("noise seed " << seed) {
            const Made big = make_loop(scenario, {rig_10_khz}, 0.01, seed);
            const Made small = make_loop(scenario, {{amplitude, 0.004}, rig_10_khz}, 0.01, seed + 1);
            FitSpec spec = spec_of(scenario, big.csv, {{kMu, 0.1, 1.0, 0.6, ""}, {kKt, 5e7, 1e9, 3e8, ""}});
            MeasuredLoop loop;
            loop.name = "small";
            loop.displacement_column = "w_m";
            loop.force_column = "force_n";
            loop.settings.emplace_back(amplitude, 0.004);
            read_loop_csv(small.csv, loop, 0.05, "loops[1]");
            spec.loops.push_back(loop);
            const FitResult r = fit(spec, FitOptions{2, nullptr, {}, {}});
            BOOST_TEST_MESSAGE("seed " << seed << ": mu " << r.parameters[0].value << " +- " << r.parameters[0].standard_error
                                       << ", k_t " << r.parameters[1].value << " +- " << r.parameters[1].standard_error << ", "
                                       << r.runs << " runs: " << r.termination);
            BOOST_TEST(std::abs(r.parameters[0].value - 0.4) < 0.02 * 0.4);
            BOOST_TEST(std::abs(r.parameters[1].value - 2e8) < 0.05 * 2e8);
            BOOST_TEST(std::abs(r.loops[0].fitted_area_j - big.area_j) < 0.01 * big.area_j);
            BOOST_TEST(std::abs(r.loops[1].fitted_area_j - small.area_j) < 0.01 * small.area_j);
            BOOST_TEST(r.parameters[1].identifiable);
            BOOST_TEST(r.parameters[1].standard_error < 0.025 * 2e8);
        }
    }
}

BOOST_AUTO_TEST_CASE(bad_input_is_named) {
    const Files files;
    files.write("rig.toml", paper_rig());
    const Made made = make_loop(paper_rig(), {}, 0.0, 1);
    files.write("loop.csv", made.csv);
    auto spec_text = [](const std::string& csv, const std::string& extra_loop = "", const std::string& lower = "0.1") {
        return "scenario = \"rig.toml\"\n[[parameters]]\nkey = \"interfaces[*].friction_coefficient\"\nlower = " + lower +
               "\nupper = 1.0\n[[loops]]\ncsv = \"" + csv + "\"\ndisplacement_column = \"w_m\"\nforce_column = \"force_n\"\n" +
               extra_loop;
    };
    const std::string source = (files.dir / "fit.toml").string();
    // a good spec reads
    BOOST_CHECK_NO_THROW(parse_fit_spec(spec_text("loop.csv"), source));
    // a column the CSV does not have
    expect_error([&] { parse_fit_spec(spec_text("loop.csv").replace(spec_text("loop.csv").find("force_n"), 7, "load_n"), source); },
                 "loops[0].force_column", "'load_n' is not a column");
    // a non-numeric cell, named with its line
    std::string bad = made.csv;
    bad.replace(bad.find('\n', bad.find('\n') + 1) + 1, 0, "0.5,x,12\n");
    files.write("text.csv", bad);
    expect_error([&] { parse_fit_spec(spec_text("text.csv"), source); }, "loops[0].csv", "text.csv:3: column 'w_m' value 'x'");
    // a row short of the force column
    files.write("short.csv", "time_s,w_m,force_n\n0,0\n");
    expect_error([&] { parse_fit_spec(spec_text("short.csv"), source); }, "loops[0].csv", "column 'force_n' is missing");
    // a loop that does not close: the first half cycle only
    const std::string half = made.csv.substr(0, made.csv.find('\n', made.csv.size() / 2) + 1);
    files.write("half.csv", half);
    expect_error([&] { parse_fit_spec(spec_text("half.csv"), source); }, "loops[0].csv", "does not close");
    // bounds the scenario refuses (a negative friction coefficient)
    expect_error([&] { parse_fit_spec(spec_text("loop.csv", "", "-0.1"), source); }, "parameters[0]",
                 "refuses the bound -0.1");
    // a loading that cannot produce the measured stroke: the loop's amplitude set to 10 mm
    const FitSpec small = parse_fit_spec(spec_text("loop.csv", "[loops.set]\n\"loading.displacement_m.amplitude\" = 0.01\n"), source);
    expect_error([&] { fit(small, FitOptions{1, nullptr, {}, {}}); }, "loops[0]", "strokes its last cycle over");
}
