// Close clamps share a node (lib/model/model.cpp, merge_close_clamps; docs/model-and-scenarios.md,
// "Mesh"; decision 071): two clamps closer than a tenth of mesh.element_length_m meet at
// their midpoint, one node, their preloads and lengths added, where neither ties the leaves
// rigidly; the mesh then has no element of a fraction of a millimetre (12 EI / l^3 ~ 3e14 N/m)
// whose round-off floor stayed in newmark's energy balance (soak seed 31, decision 065).
#define BOOST_TEST_MODULE close_clamps
#include <boost/test/unit_test.hpp>
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "stackbeam/fe/system.hpp"
#include "stackbeam/run/run.hpp"
#include "stackbeam/run/summary_json.hpp"
#include "stackbeam/study/sweep.hpp"
#include "stackbeam/time/stepper.hpp"
#include "test_support.hpp"

namespace tt = boost::test_tools;
using namespace stackbeam;

namespace {

/// Two steel leaves (0.9 and 0.75 m, 9 mm, 40 mm wide; the top one pinned at both ends, the
/// lower one free, the seat at mid-span), mu 0.3 on an elastic interface (the layer of the
/// leaves' own sections); clamp pairs 10 mm long at +-d1 and +-d2 [m] from mid-span with
/// preloads 300 and 1500 N; elements of h [m].
ModelSpec two_clamp_pairs(double d1_m, double d2_m, double h_m) {
    testing::ClampedPairSpec c;
    c.top_length_m = 0.9;
    c.lower_length_m = 0.75;
    c.thickness_m = 0.009;
    c.width_m = 0.04;
    c.friction_coefficient = 0.3;
    c.contact = InterfaceContact::elastic;
    c.body_mass_kg = 100.0;
    c.element_length_m = h_m;
    ModelSpec s = testing::clamped_pair_stack(c);
    for (const auto& [d, preload] : {std::pair{d1_m, 300.0}, std::pair{d2_m, 1500.0}})
        for (double x : {0.45 - d, 0.45 + d}) s.clamps.push_back({x, preload, 0.01});
    return s;
}

int clamp_pairs(const Model& m) {
    return static_cast<int>(std::count_if(m.candidate_pairs().begin(), m.candidate_pairs().end(),
                                          [](const PairSpec& p) { return p.kind == PairKind::clamp; }));
}

/// The shortest element of the mesh [m].
double shortest_element_m(const Model& m) {
    double h = 1.0;
    for (std::size_t i = 1; i < m.nodes_x().size(); ++i) h = std::min(h, m.nodes_x()[i] - m.nodes_x()[i - 1]);
    return h;
}

/// A quasi-static rig cycle under the closed-form stepper: down to -10 mm at t = 0.25 s, up to
/// +10 mm, back to 0 at 1 s (dt 1 ms). The rig's force at -10 mm [N] and the friction work of
/// the cycle [J].
std::pair<double, double> rig_cycle(const ModelSpec& spec) {
    const System sys(Model::build(spec));
    SimulationOptions o;
    o.mode = Mode::closed_form;
    o.loading.kind = LoadingKind::prescribed_displacement;
    o.loading.displacement_m.shape = TimeFunction::Shape::table;
    o.loading.displacement_m.times_s = {0.0, 0.25, 0.75, 1.0};
    o.loading.displacement_m.values = {0.0, -0.01, 0.01, 0.0};
    o.t_end_s = 1.0;
    o.dt_s = 1e-3;
    o.solver.tolerance_m = 1e-9;  // the elastic layer's approach resolved (as test_soak)
    auto st = make_stepper(sys, o);
    double force_n = 0.0;
    for (int i = 1; i <= 1000; ++i) {
        const StepRecord& r = st->advance();
        if (i == 250) force_n = r.spring_force_n;
    }
    return {force_n, st->current().dissipated_energy_j};
}

}  // namespace

// Clamps 0.35 mm apart on h = 0.05 m (soak seed 31's distance): one node at their midpoint, each
// clamp moved by 0.175 mm (<= 0.1 h / 2 = 2.5 mm), one clamp pair a side with the preloads (and
// the layer's lengths) added; the shortest element is then the mesh's own, not 0.35 mm.
BOOST_AUTO_TEST_CASE(clamps_closer_than_a_tenth_of_an_element_share_a_node) {
    const Model m = Model::build(two_clamp_pairs(0.15, 0.15035, 0.05));
    BOOST_TEST(clamp_pairs(m) == 2);
    const Model one = Model::build([] {  // one clamp a side, 20 mm long, 1800 N, at the midpoint
        ModelSpec s = two_clamp_pairs(0.150175, 0.3, 0.05);
        s.clamps = {{0.45 - 0.150175, 1800.0, 0.02}, {0.45 + 0.150175, 1800.0, 0.02}};
        return s;
    }());
    for (const PairSpec& p : m.candidate_pairs())
        if (p.kind == PairKind::clamp) {
            BOOST_TEST(p.preload_n == 1800.0, tt::tolerance(1e-12));
            BOOST_TEST(std::abs(std::abs(p.x_m - 0.45) - 0.150175) <= 1e-12);
            const auto twin = std::find_if(one.candidate_pairs().begin(), one.candidate_pairs().end(),
                                           [&](const PairSpec& q) { return q.kind == PairKind::clamp && std::abs(q.x_m - p.x_m) < 1e-12; });
            BOOST_TEST_REQUIRE((twin != one.candidate_pairs().end()));
            BOOST_TEST(p.normal_compliance_m_per_n == twin->normal_compliance_m_per_n, tt::tolerance(1e-12));
        }
    for (const ClampSpec& c : m.spec().clamps) BOOST_TEST(std::abs(std::abs(c.x_m - 0.45) - 0.150175) <= 1e-12);
    BOOST_TEST(shortest_element_m(m) > 0.01);
}

// Farther apart than 0.1 h: kept, each on its own node (6 mm on h = 0.05 m); 4.9 mm: merged.
BOOST_AUTO_TEST_CASE(clamps_farther_apart_keep_their_nodes) {
    const Model m = Model::build(two_clamp_pairs(0.15, 0.156, 0.05));
    BOOST_TEST(clamp_pairs(m) == 4);
    BOOST_TEST(shortest_element_m(m) == 0.006, tt::tolerance(1e-9));
    BOOST_TEST(clamp_pairs(Model::build(two_clamp_pairs(0.15, 0.1549, 0.05))) == 2);
}

// Rigid ties stay apart: two ties l apart lock the leaves' relative slope for any l > 0 and one
// does not, so merging would change the answer (the rig cycle below on a rigid interface: 894 N at
// -10 mm with two ties 0.35 mm apart, on every mesh from h = 50 mm to 3 mm; 670 N merged). A
// rigid interface, a point clamp (length 0) on an elastic one: both keep their two nodes.
BOOST_AUTO_TEST_CASE(rigid_ties_stay_apart) {
    ModelSpec rigid = two_clamp_pairs(0.15, 0.15035, 0.05);
    rigid.interfaces[0].contact = InterfaceContact::rigid;
    BOOST_TEST(clamp_pairs(Model::build(rigid)) == 4);
    ModelSpec point = two_clamp_pairs(0.15, 0.15035, 0.05);
    point.clamps[0].length_m = 0.0;
    point.clamps[1].length_m = 0.0;
    BOOST_TEST(clamp_pairs(Model::build(point)) == 4);
}

// Two clamps either side of the seat stay apart (the half model mirrors its clamps about it).
BOOST_AUTO_TEST_CASE(clamps_across_the_seat_stay_apart) {
    ModelSpec s = two_clamp_pairs(0.15, 0.25, 0.05);
    s.clamps = {{0.449, 500.0, 0.01}, {0.451, 500.0, 0.01}};
    BOOST_TEST(clamp_pairs(Model::build(s)) == 2);
}

// The shift is below the discretisation error. The rig cycle (rig_cycle) with clamps 0.35 mm
// apart: on h = 50 mm they are merged (moved by 0.175 mm each); the model as given, converged, is
// the run on h = 1.5625 mm (0.1 h = 0.16 mm: not merged; 4 clamp pairs). The merge's own effect
// on that fine mesh (the clamps placed at their midpoint, 1800 N and 20 mm, against the two as
// given) is measured at 0.43 N of the rig's 553 N and 0.0056 J of the cycle's 0.75 J; the coarse
// run's discretisation error is 46 N and 0.14 J (the friction work converges slowly: pairs at
// nodes). Bound: the merge's effect at most a tenth of the discretisation error it sits under.
BOOST_AUTO_TEST_CASE(the_merge_moves_the_answer_less_than_the_mesh_does) {
    const double fine_m = 0.0015625;
    const ModelSpec given = two_clamp_pairs(0.15, 0.15035, fine_m);
    BOOST_TEST_REQUIRE(clamp_pairs(Model::build(given)) == 4);
    ModelSpec midpoint = two_clamp_pairs(0.150175, 0.3, fine_m);
    midpoint.clamps = {{0.45 - 0.150175, 1800.0, 0.02}, {0.45 + 0.150175, 1800.0, 0.02}};
    const auto [f_converged, d_converged] = rig_cycle(given);
    const auto [f_merged_fine, d_merged_fine] = rig_cycle(midpoint);
    const auto [f_coarse, d_coarse] = rig_cycle(two_clamp_pairs(0.15, 0.15035, 0.05));
    BOOST_TEST_MESSAGE("rig force at -10 mm: converged " << f_converged << " N, merged on the fine mesh " << f_merged_fine
                                                         << " N, merged on h = 50 mm " << f_coarse << " N");
    BOOST_TEST_MESSAGE("friction work: converged " << d_converged << " J, merged on the fine mesh " << d_merged_fine
                                                   << " J, merged on h = 50 mm " << d_coarse << " J");
    BOOST_TEST(std::abs(f_merged_fine - f_converged) <= 0.1 * std::abs(f_coarse - f_converged));
    BOOST_TEST(std::abs(d_merged_fine - d_converged) <= 0.1 * std::abs(d_coarse - d_converged));
}

namespace {

/// A short run of `model` through the run layer (10 steps of rig_cycle's stroke) and its JSON summary.
std::pair<RunSummary, std::string> short_run(const Model& model) {
    const System sys(model);
    RunRequest request;
    request.options.mode = Mode::closed_form;
    request.options.loading.kind = LoadingKind::prescribed_displacement;
    request.options.loading.displacement_m.shape = TimeFunction::Shape::table;
    request.options.loading.displacement_m.times_s = {0.0, 0.25};
    request.options.loading.displacement_m.values = {0.0, -0.01};
    request.options.dt_s = 1e-3;
    request.options.t_end_s = 0.01;
    request.options.solver.tolerance_m = 1e-9;
    RunSummary summary = run_scenario(sys, request);
    summary.wall_s = 0.0;  // the one figure that differs between two runs of the same model
    std::string json = summary_json(summary, model);
    return {std::move(summary), std::move(json)};
}

}  // namespace

// The merge is told (Model::adjustments(), decision 077): one sentence per merged pair naming the
// clamps as the user wrote them (their index in clamps and their x), the gap, the merged x and why.
// The independent values: the spec two_clamp_pairs(0.15, 0.15035, 0.05) writes clamps[0] at 0.45 -
// 0.15 = 0.3 m and clamps[2] at 0.45 - 0.15035 = 0.29965 m (0.35 mm apart, < 0.1 h = 5 mm), their
// midpoint 0.299825 m; clamps[1] at 0.6 m and clamps[3] at 0.60035 m, midpoint 0.600175 m. Clamps
// kept apart (6 mm on h = 50 mm, or rigid ties) give no sentence.
BOOST_AUTO_TEST_CASE(the_merge_is_told_naming_the_clamps_as_written) {
    const Model m = Model::build(two_clamp_pairs(0.15, 0.15035, 0.05));
    const std::vector<std::string>& notes = m.adjustments();
    BOOST_TEST_REQUIRE(notes.size() == 2u);
    for (const std::string& n : notes) BOOST_TEST_MESSAGE(n);
    const auto has = [](const std::string& note, const std::string& part) {
        BOOST_TEST(note.find(part) != std::string::npos, "'" << part << "' not in: " << note);
    };
    has(notes[0], "clamps[0] (x = 0.3 m) and clamps[2] (x = 0.29965 m), 0.00035 m apart, act as one clamp at x = 0.299825 m");
    has(notes[1], "clamps[1] (x = 0.6 m) and clamps[3] (x = 0.60035 m), 0.00035 m apart, act as one clamp at x = 0.600175 m");
    for (const std::string& n : notes) {
        has(n, "their preloads and lengths added");
        has(n, "closer than a tenth of mesh.element_length_m (0.005 m of 0.05 m)");
    }
    // the sentence's merged x is where the model put both clamps
    BOOST_TEST(m.spec().clamps[0].x_m == 0.299825, tt::tolerance(1e-12));
    BOOST_TEST(m.spec().clamps[3].x_m == 0.600175, tt::tolerance(1e-12));
    BOOST_TEST(Model::build(two_clamp_pairs(0.15, 0.156, 0.05)).adjustments().empty());
    ModelSpec rigid = two_clamp_pairs(0.15, 0.15035, 0.05);
    rigid.interfaces[0].contact = InterfaceContact::rigid;
    BOOST_TEST(Model::build(rigid).adjustments().empty());
}

// Every front-end shows it through the run layer: RunSummary::model_adjustments is the model's, and
// the JSON summary (the command line's --summary, Python's result.summary) has them under
// "model_adjustments", which is its only difference from the same summary without them. A model
// without close clamps has none and its summary no such key: byte for byte what it was before.
BOOST_AUTO_TEST_CASE(the_run_summary_shows_the_merge_and_only_when_there_is_one) {
    const Model merged = Model::build(two_clamp_pairs(0.15, 0.15035, 0.05));
    auto [summary, json] = short_run(merged);
    BOOST_TEST(summary.model_adjustments == merged.adjustments());
    const std::string key = "\"model_adjustments\": [";
    const std::size_t at = json.find(key);
    BOOST_TEST_REQUIRE(at != std::string::npos);
    BOOST_TEST(json.find("act as one clamp at x = 0.299825 m") != std::string::npos);
    // the key's lines taken out, the summary is the one without adjustments
    const std::size_t line = json.rfind('\n', at), end = json.find("\n  ],", at);
    BOOST_TEST_REQUIRE(end != std::string::npos);
    std::string without_key = json;
    without_key.erase(line, end + 5 - line);
    summary.model_adjustments.clear();
    BOOST_TEST(summary_json(summary, merged) == without_key);

    const Model apart = Model::build(two_clamp_pairs(0.15, 0.156, 0.05));
    const auto [plain, plain_json] = short_run(apart);
    BOOST_TEST(plain.model_adjustments.empty());
    BOOST_TEST(plain_json.find("model_adjustments") == std::string::npos);
}

// A sweep point's message (points.csv's `message` column) carries the sentence too: the point runs
// through the same run layer (run_point), so its row says which clamps its model merged.
BOOST_AUTO_TEST_CASE(a_sweep_point_tells_the_merge_in_its_message) {
    SweepPoint point;
    point.scenario.model = two_clamp_pairs(0.15, 0.15035, 0.05);
    point.scenario.simulation.mode = Mode::closed_form;
    point.scenario.simulation.loading.kind = LoadingKind::prescribed_displacement;
    point.scenario.simulation.loading.displacement_m.shape = TimeFunction::Shape::table;
    point.scenario.simulation.loading.displacement_m.times_s = {0.0, 0.25};
    point.scenario.simulation.loading.displacement_m.values = {0.0, -0.01};
    point.scenario.simulation.dt_s = 1e-3;
    point.scenario.simulation.t_end_s = 0.01;
    const PointResult r = run_point(point);
    BOOST_TEST((r.status == PointStatus::ok), r.message);
    BOOST_TEST(r.message.find("clamps[0] (x = 0.3 m) and clamps[2] (x = 0.29965 m)") != std::string::npos, r.message);
    BOOST_TEST(r.message.find("clamps[1] (x = 0.6 m) and clamps[3] (x = 0.60035 m)") != std::string::npos, r.message);
    point.scenario.model = two_clamp_pairs(0.15, 0.156, 0.05);
    BOOST_TEST(run_point(point).message.find("clamps[") == std::string::npos);
}
