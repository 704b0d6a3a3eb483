// The run layer (stackbeam/run/): run_scenario gives simulate()'s records, its stats and loop
// figures are those of the records, a stop ends it cleanly, the JSON summary carries them; the
// enums' word tables (stackbeam/words.hpp) read back what they write.
#define BOOST_TEST_MODULE run_layer
#include <boost/test/unit_test.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "stackbeam/io/scenario.hpp"
#include "stackbeam/run/run.hpp"
#include "stackbeam/run/summary_json.hpp"
#include "stackbeam/study/sweep.hpp"
#include "stackbeam/time/stepper.hpp"

using namespace stackbeam;

namespace {

/// The rig scenario (three leaves, triangle stroke of 1 Hz), shortened to two periods so that
/// the last cycle is a whole one after a first.
Scenario rig() {
    Scenario s = load_scenario(std::string(STACKBEAM_SOURCE_DIR) + "/scenarios/rig_friction.toml");
    s.simulation.t_end_s = 2.0;
    return s;
}

bool same(const StepRecord& a, const StepRecord& b) {
    const auto x = step_record_values(a), y = step_record_values(b);
    return std::memcmp(x.data(), y.data(), x.size() * sizeof(double)) == 0;
}

/// A request to run `options`, its rows to `sink` (the outputs off).
RunRequest request_of(const SimulationOptions& options, RunSink* sink) {
    RunRequest request;
    request.options = options;
    request.sink = sink;
    return request;
}

struct CountingSink : RunSink {
    long records = 0, pair_calls = 0, pairs = 0;
    double last_t_s = -1.0;
    void on_record(const StepRecord& r) override {
        ++records;
        last_t_s = r.t_s;
    }
    void on_pairs(double, const std::vector<PairRecord>& prs) override {
        ++pair_calls;
        pairs += static_cast<long>(prs.size());
    }
};

}  // namespace

BOOST_AUTO_TEST_CASE(run_scenario_is_simulate_with_its_figures) {
    const Scenario s = rig();
    const System system(Model::build(s.model));
    // the reference: simulate(), the library's plain loop; the run layer steps the same stepper,
    // so the records must be bitwise equal (no tolerance: the same arithmetic)
    const std::vector<StepRecord> reference = simulate(system, s.simulation);
    CountingSink sink;
    RunRequest request = request_of(s.simulation, &sink);
    request.outputs.pairs = true;
    const RunSummary summary = run_scenario(system, request);
    BOOST_TEST(!summary.interrupted);
    BOOST_REQUIRE_EQUAL(summary.records.size(), reference.size());
    for (std::size_t i = 0; i < reference.size(); ++i) BOOST_TEST_REQUIRE(same(summary.records[i], reference[i]), "record " << i);
    BOOST_TEST(sink.records == static_cast<long>(reference.size()));
    BOOST_TEST(sink.pair_calls == sink.records);
    BOOST_TEST(sink.pairs == sink.records * static_cast<long>(system.pairs().size()));
    // the stats are the records' extremes and sums, exactly
    double w_max = reference[0].w_m, balance = 0.0;
    long iterations = 0;
    for (const StepRecord& r : reference) {
        w_max = std::max(w_max, r.w_m);
        balance = std::max(balance, std::abs(r.energy_balance_error_j));
        iterations += r.contact_iterations;
    }
    BOOST_TEST(summary.stats.records == static_cast<long>(reference.size()));
    BOOST_TEST(summary.stats.w_max_m == w_max);
    BOOST_TEST(summary.stats.max_abs_balance_j == balance);
    BOOST_TEST(summary.stats.contact_iterations == iterations);
    BOOST_TEST(summary.t_reached_s == reference.back().t_s);
    // the loop figures: those of hysteresis_metrics over last_cycle and the Fancher fit over the
    // same records, called directly (exactly equal: one computation)
    BOOST_REQUIRE(summary.loop.metrics.has_value());
    const auto cycle = last_cycle(reference, s.simulation.loading.period_s());
    const HysteresisMetrics m = hysteresis_metrics(reference, cycle.first, cycle.second);
    BOOST_TEST(summary.loop.metrics->loop_area_j == m.loop_area_j);
    BOOST_TEST(summary.loop.metrics->secant_stiffness_n_per_m == m.secant_stiffness_n_per_m);
    BOOST_REQUIRE(summary.loop.fancher.has_value());
    const FancherFit fit = fit_fancher_loop(reference, m.t_start_s, m.t_end_s).fit;
    BOOST_TEST(summary.loop.fancher->parameters.beta_m == fit.parameters.beta_m);
    // the sweep's point figures come from the same function: the same numbers
    std::string note;
    const std::vector<double> f = point_figures(reference, s.simulation, note);
    BOOST_TEST(f[0] == m.loop_area_j);
    BOOST_TEST(f[14] == fit.parameters.beta_m);
    BOOST_TEST(f[16] == balance);
    // the stepper as the registry describes it: the closed-form mode keeps no event log
    BOOST_TEST(summary.stepper.name == "closed-form");
    BOOST_TEST(!summary.stepper.cvode_stats);
    // the JSON summary has the figures and the setup
    const std::string json = summary_json(summary, system.model());
    BOOST_TEST(json.find("\"interrupted\": false") != std::string::npos);
    BOOST_TEST(json.find("\"loop_area_j\"") != std::string::npos);
}

BOOST_AUTO_TEST_CASE(a_stop_ends_the_run_at_a_whole_record) {
    const Scenario s = rig();
    const System system(Model::build(s.model));
    CountingSink sink;
    RunRequest request = request_of(s.simulation, &sink);
    // asked to stop once the sink has 10 records: the 11th is dropped (or not made), the run ends
    request.stop = [&] { return sink.records >= 10; };
    const RunSummary summary = run_scenario(system, request);
    BOOST_TEST(summary.interrupted);
    BOOST_TEST(sink.records == 10);
    BOOST_TEST(summary.records.size() == 10u);
    BOOST_TEST(summary.stats.records == 10);
    BOOST_TEST(summary.t_reached_s == sink.last_t_s);
    BOOST_TEST(!summary.loop.metrics.has_value());
    BOOST_TEST(summary.loop.note == "interrupted run: no loop figures");
    BOOST_TEST(summary.report.steps == 0);  // no report for an interrupted run (documented)
    const std::string json = summary_json(summary, system.model());
    BOOST_TEST(json.find("\"interrupted\": true") != std::string::npos);
}

BOOST_AUTO_TEST_CASE(modes_with_a_feature_are_those_whose_stepper_takes_it) {
    // the front-ends' question before a system exists (modes_with) against the stepper make_stepper
    // chooses for a built system (describe_stepper): a mode is listed for massive leaves exactly
    // when make_stepper builds one for the bonded paper example with steel leaves (no refusal),
    // and for the event log exactly when its stepper for the massless example keeps one
    const std::vector<Mode> massive = modes_with(StepperFeature::massive_leaves);
    const std::vector<Mode> events = modes_with(StepperFeature::event_log);
    BOOST_TEST(mode_list(massive, " or ") == "newmark or cvode");  // docs/time-integration.md
    BOOST_TEST(mode_list(events, " or ") == "cvode");
    ModelSpec steel = paper_example(PaperCase::bonded);
    for (auto& leaf : steel.leaves) leaf.density_kg_per_m3 = 7850.0;
    const System massive_system(Model::build(steel));
    const System massless_system(Model::build(paper_example(PaperCase::bonded)));
    for (const auto& w : enum_words<Mode>()) {
        SimulationOptions o;
        o.mode = w.value;
        const bool listed = std::find(massive.begin(), massive.end(), w.value) != massive.end();
        bool taken = true;
        try {
            make_stepper(massive_system, o);
        } catch (const InputError&) {
            taken = false;
        }
        BOOST_TEST(listed == taken, "mode " << w.word);
        const bool logs = std::find(events.begin(), events.end(), w.value) != events.end();
        BOOST_TEST(logs == describe_stepper(massless_system, o).cvode_stats, "mode " << w.word);
    }
}

BOOST_AUTO_TEST_CASE(word_tables_read_back_what_they_write) {
    for (const auto& w : enum_words<Mode>()) BOOST_TEST((parse_mode(to_string(w.value), "mode") == w.value));
    for (const auto& w : enum_words<LeafInertia>())
        BOOST_TEST((parse_leaf_inertia(to_string(w.value), "leaf_inertia") == w.value));
    for (const auto& w : enum_words<PaperCase>()) BOOST_TEST((parse_paper_case(to_string(w.value), "case") == w.value));
    for (const auto& w : enum_words<InterfaceContact>())
        BOOST_TEST((parse_interface_contact(to_string(w.value), "contact") == w.value));
    for (const auto& w : enum_words<SupportKind>()) BOOST_TEST(std::string(to_string(w.value)) == w.word);
    for (const auto& w : enum_words<LoadingKind>()) BOOST_TEST(std::string(to_string(w.value)) == w.word);
    BOOST_TEST(word_list<Mode>() == "closed-form, cvode, newmark");
    BOOST_TEST(word_list<Symmetry>("'", ", ", " or ") == "'full' or 'half'");
    BOOST_TEST(word_list<SolverKind>("", " | ") == "exact | accelerated | block-jacobi | paper");
    BOOST_TEST(!find_word<Mode>("rk4").has_value());
    try {
        parse_mode("rk4", "--mode");
        BOOST_FAIL("no error");
    } catch (const InputError& e) {
        BOOST_TEST(std::string(e.what()) == "--mode: value 'rk4' is not a mode: allowed closed-form, cvode, newmark");
    }
}

namespace {

/// Keeps every record's stresses the run layer hands over.
struct StressSink : RunSink {
    std::vector<double> t_s;
    std::vector<Stresses> stresses;
    void on_stresses(double t, const Stresses& s) override {
        t_s.push_back(t);
        stresses.push_back(s);
    }
};

}  // namespace

// RunOutputs::stresses (issue 43 item 5): the run's StressSummary is the one a StressMonitor
// gives when fed the same stresses by hand, and every interface's peak pressure is the largest
// of the pressures handed to the sink; the records do not change (the flag only reads the state).
// Exact comparisons: one computation, the same inputs.
BOOST_AUTO_TEST_CASE(the_stresses_flag_gives_the_monitors_summary) {
    const Scenario s = rig();
    const System system(Model::build(s.model));
    const RunRequest plain = request_of(s.simulation, nullptr);
    const RunSummary without = run_scenario(system, plain);
    BOOST_TEST(!without.stresses.has_value());  // not asked: nothing made (and no note)
    BOOST_TEST(without.stresses_note.empty());
    BOOST_TEST(summary_json(without, system.model()).find("\"stresses\"") == std::string::npos);

    StressSink sink;
    RunRequest request = plain;
    request.outputs.stresses = true;
    request.sink = &sink;
    const RunSummary with = run_scenario(system, request);
    BOOST_REQUIRE_EQUAL(with.records.size(), without.records.size());
    for (std::size_t i = 0; i < with.records.size(); ++i) BOOST_TEST_REQUIRE(same(with.records[i], without.records[i]), "record " << i);
    BOOST_REQUIRE(with.stresses.has_value());
    BOOST_REQUIRE_EQUAL(sink.stresses.size(), with.records.size());

    // the reference: a monitor over the last period (the rig's loading is periodic, 1 s; the run 2 s)
    StressMonitorOptions o;
    o.period_s = s.simulation.loading.period_s();
    o.t_end_s = with.records.back().t_s;
    StressMonitor monitor(s.model, o);
    for (std::size_t i = 0; i < sink.stresses.size(); ++i) monitor.add(sink.t_s[i], sink.stresses[i]);
    const StressSummary ref = monitor.summary();
    const StressSummary& got = with.stresses->summary;
    BOOST_TEST(got.samples == ref.samples);
    BOOST_TEST(got.cycle_samples == ref.cycle_samples);
    BOOST_TEST(got.cycle_start_s == ref.cycle_start_s);
    BOOST_REQUIRE_EQUAL(got.extremes.size(), s.model.leaves.size());
    for (std::size_t l = 0; l < got.extremes.size(); ++l) {
        BOOST_TEST(got.extremes[l].tension.stress_pa == ref.extremes[l].tension.stress_pa);
        BOOST_TEST(got.extremes[l].compression.x_m == ref.extremes[l].compression.x_m);
        BOOST_TEST(got.extremes[l].tension.stress_pa > 0.0);  // a loaded leaf bends: both signs somewhere
        BOOST_TEST(got.extremes[l].compression.stress_pa < 0.0);
    }
    BOOST_TEST(got.largest_range.range_pa == ref.largest_range.range_pa);
    BOOST_TEST(got.largest_range.range_pa > 0.0);
    // the peaks: the largest pressure on each interface over every record handed over
    BOOST_REQUIRE_EQUAL(with.stresses->interfaces.size(), s.model.interfaces.size());
    for (std::size_t i = 0; i < with.stresses->interfaces.size(); ++i) {
        double peak = 0.0;
        for (const Stresses& st : sink.stresses) peak = std::max(peak, st.interfaces[i].pressure_pa);
        BOOST_TEST(with.stresses->interfaces[i].peak.pressure_pa == peak);
        BOOST_TEST(peak > 0.0);  // the leaves press on each other under load
    }
    // the JSON summary's section
    const std::string json = summary_json(with, system.model());
    BOOST_TEST(json.find("\"stresses\": {") != std::string::npos);
    BOOST_TEST(json.find("\"largest_tension\"") != std::string::npos);
    BOOST_TEST(json.find("\"peak_pressure_pa\"") != std::string::npos);
}

// With a material on every leaf (S_u 1.6 GPa, S_e 600 MPa, Goodman) the run's fatigue figures are
// the periodic path's: at every node and fibre one cycle of the last period, s_a = (max - min) / 2,
// s_m = (max + min) / 2, n = 1 / (s_a / S_e + s_m / S_u) for s_m > 0 and S_e / s_a otherwise
// (Shigley, 10th ed., table 6-7), recomputed here from the stresses handed to the sink; the least
// n over the leaf agrees to round-off (1e-12 relative: a few operations on numbers of one size).
BOOST_AUTO_TEST_CASE(the_stresses_flag_gives_the_fatigue_figures) {
    Scenario s = rig();
    FatigueMaterial steel;
    steel.ultimate_strength_pa = 1.6e9;
    steel.endurance_limit_pa = 6e8;
    for (LeafSpec& l : s.model.leaves) l.material = steel;
    const System system(Model::build(s.model));
    StressSink sink;
    RunRequest request = request_of(s.simulation, &sink);
    request.outputs.stresses = true;
    const RunSummary summary = run_scenario(system, request);
    BOOST_REQUIRE(summary.stresses.has_value());
    const StressSummary& got = summary.stresses->summary;
    BOOST_TEST((got.counting == CycleCounting::periodic));
    const double t_last = sink.t_s.back(), period = s.simulation.loading.period_s();
    for (std::size_t l = 0; l < s.model.leaves.size(); ++l) {
        const std::size_t nodes = sink.stresses[0].leaves[l].x_m.size();
        double least = std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < nodes; ++i)
            for (int fibre = 0; fibre < 2; ++fibre) {
                double lo = std::numeric_limits<double>::infinity(), hi = -lo;
                for (std::size_t k = 0; k < sink.t_s.size(); ++k) {
                    if (sink.t_s[k] < t_last - period - 1e-9) continue;
                    const LeafStresses& ls = sink.stresses[k].leaves[l];
                    const double v = fibre == 0 ? ls.top_stress_pa[i] : ls.bottom_stress_pa[i];
                    lo = std::min(lo, v);
                    hi = std::max(hi, v);
                }
                const double sa = 0.5 * (hi - lo), sm = 0.5 * (hi + lo);
                const double n = sm > 0.0 ? 1.0 / (sa / steel.endurance_limit_pa + sm / steel.ultimate_strength_pa)
                                          : steel.endurance_limit_pa / sa;
                least = std::min(least, n);
            }
        BOOST_REQUIRE(got.fatigue[l].has_material);
        BOOST_REQUIRE(got.fatigue[l].fatigue.has_safety_factor);
        BOOST_TEST(got.fatigue[l].fatigue.least_safety_factor == least, boost::test_tools::tolerance(1e-12));
        BOOST_TEST(least > 1.0);  // the rig's 50 MPa amplitudes are far below S_e
    }
    const std::string json = summary_json(summary, system.model());
    BOOST_TEST(json.find("\"least_safety_factor\"") != std::string::npos);
}
