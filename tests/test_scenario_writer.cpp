// Scenario files written back (to_toml, lib/io/scenario_writer.cpp): every scenario of
// scenarios/ reads back from its TOML text to the same scenario, and runs the same.
// Why this proves it: to_toml writes every field of the model, the options and the outputs
// in a form that reads back to the same double (shortest round trip); so equal texts of
// to_toml(s) and to_toml(parse(to_toml(s))) mean every written field read back equal, and
// a run of both (bitwise equal records) shows that nothing the run uses was left out.
#define BOOST_TEST_MODULE scenario_writer
#include <boost/test/unit_test.hpp>
#include <cmath>
#include <string>

#include "stackbeam/errors.hpp"
#include "stackbeam/io/scenario.hpp"
#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/time/simulation.hpp"

using namespace stackbeam;

#ifndef STACKBEAM_SOURCE_DIR
#error "STACKBEAM_SOURCE_DIR must be defined"
#endif

namespace {

std::string scenario_path(const std::string& name) { return std::string(STACKBEAM_SOURCE_DIR) + "/scenarios/" + name; }

/// The records of a short run (`steps` records) of a scenario.
std::vector<StepRecord> short_run(Scenario s, int steps) {
    s.simulation.t_end_s = steps * s.simulation.dt_s;
    const System system(Model::build(s.model));
    return simulate(system, s.simulation);
}

}  // namespace

BOOST_AUTO_TEST_CASE(every_scenario_file_round_trips) {
    for (const char* name : {"paper_bonded.toml", "paper_friction.toml", "paper_frictionless.toml", "rig_friction.toml",
                             "base_friction.toml", "base_steel_elastic.toml", "calculix_six_leaf.toml",
                             "cambered_assembly.toml", "graduated_elastic.toml", "gravity_friction.toml",
                             "parabolic_two_leaf.toml"}) {
        BOOST_TEST_CONTEXT(name) {
            const Scenario s = load_scenario(scenario_path(name));
            const std::string text = to_toml(s);
            const Scenario back = parse_scenario(text, std::string(name) + " (written)");
            BOOST_TEST(to_toml(back) == text);
            BOOST_TEST(back.description == s.description);
            BOOST_TEST(back.outputs.csv_path == s.outputs.csv_path);
        }
    }
}

BOOST_AUTO_TEST_CASE(written_scenario_runs_the_same) {
    // the friction case (stick-slip, clamps, probe) and a rig with a periodic loading
    for (const char* name : {"paper_friction.toml", "rig_friction.toml"}) {
        BOOST_TEST_CONTEXT(name) {
            const Scenario s = load_scenario(scenario_path(name));
            const Scenario back = parse_scenario(to_toml(s), name);
            const auto a = short_run(s, 40), b = short_run(back, 40);
            BOOST_TEST_REQUIRE(a.size() == b.size());
            for (std::size_t i = 0; i < a.size(); ++i) {
                const auto x = step_record_values(a[i]), y = step_record_values(b[i]);
                for (std::size_t j = 0; j < x.size(); ++j)
                    BOOST_TEST((x[j] == y[j] || (std::isnan(x[j]) && std::isnan(y[j]))));
            }
        }
    }
}

BOOST_AUTO_TEST_CASE(built_model_with_every_table_round_trips) {
    // a model built in code with the optional tables the files above do not all have:
    // a profile, eyes and bushings, a clip, a probe, tied leaves, a table loading, text to escape
    Scenario s;
    s.description = "quotes \" and \\ backslash\nnew line";
    s.model = paper_example(PaperCase::friction);
    s.model.symmetry = Symmetry::full;
    s.model.leaves[0].profile.x_m = {0.0, 0.25, 0.5};
    s.model.leaves[0].profile.width_m = {0.04, 0.05, 0.04};
    s.model.leaves[0].width_m = 0.0;
    s.model.leaves[0].left_end.eye_offset_m = 0.001;
    s.model.leaves[1].right_support = SupportKind::bushing;
    s.model.leaves[1].right_end.bushing_x_n_per_m = 1e7;
    s.model.leaves[1].right_end.bushing_y_n_per_m = 1e6;
    s.model.clips.push_back(ClipSpec{0.05, 0, 2, 1e-3, 2e8});
    s.model.probe = ProbeSpec{1, 0.2};
    s.model.rigid_body.tied_leaves = {0, 1, 2};
    s.simulation.loading.kind = LoadingKind::applied_force;
    s.simulation.loading.force_n.shape = TimeFunction::Shape::table;
    s.simulation.loading.force_n.times_s = {0.0, 0.1, 0.3};
    s.simulation.loading.force_n.values = {0.0, 100.0, 1.0 / 3.0};
    s.simulation.cvode.rtol = 1e-9;
    s.outputs.pairs_path = "pairs.csv";
    s.outputs.nodes_path = "nodes.csv";
    s.outputs.stresses_path = "stresses.csv";
    const std::string text = to_toml(s);
    const Scenario back = parse_scenario(text, "built");
    BOOST_TEST(to_toml(back) == text);
    BOOST_TEST(back.description == s.description);
    BOOST_TEST(back.outputs.nodes_path == "nodes.csv");
    BOOST_TEST(back.outputs.stresses_path == "stresses.csv");
    BOOST_TEST(back.simulation.loading.force_n.values[2] == 1.0 / 3.0);  // shortest round trip, exact
    BOOST_TEST(back.model.leaves[0].profile.width_m[1] == 0.05);
    BOOST_TEST(back.model.clips.at(0).stiffness_n_per_m == 2e8);
    BOOST_TEST(back.model.probe->interface_index == 1);
}
