// Scenario files: the paper example's files reproduce the built-in example (the
// same ModelSpec field by field, the same records to round-off), and bad input is
// rejected with the file's key path and location. (The command line's bad-input
// suite, tests/bad_input/*.toml, is in bad_input_tests.cmake.)
#define BOOST_TEST_MODULE scenario
#include <boost/test/unit_test.hpp>
#include <algorithm>
#include <cmath>
#include <string>

#include "stackbeam/errors.hpp"
#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/io/scenario.hpp"
#include "stackbeam/time/simulation.hpp"
#include "test_support.hpp"

namespace tt = boost::test_tools;
using namespace stackbeam;

#ifndef STACKBEAM_SOURCE_DIR
#error "STACKBEAM_SOURCE_DIR must be defined"
#endif

namespace {

std::string scenario_path(const char* name) { return std::string(STACKBEAM_SOURCE_DIR) + "/scenarios/" + name; }

void check_same_spec(const ModelSpec& a, const ModelSpec& b) {
    BOOST_TEST_REQUIRE(a.leaves.size() == b.leaves.size());
    for (std::size_t i = 0; i < a.leaves.size(); ++i) {
        BOOST_TEST_CONTEXT("leaves[" << i << "]") {
            const auto &x = a.leaves[i], &y = b.leaves[i];
            BOOST_TEST(x.length_m == y.length_m);
            BOOST_TEST(x.x_start_m == y.x_start_m);
            BOOST_TEST(x.height_m == y.height_m);
            BOOST_TEST(x.width_m == y.width_m);
            BOOST_TEST(x.youngs_modulus_pa == y.youngs_modulus_pa);
            BOOST_TEST(x.density_kg_per_m3 == y.density_kg_per_m3);
            BOOST_TEST(x.poisson_ratio == y.poisson_ratio);
            BOOST_TEST((x.left_support == y.left_support));
            BOOST_TEST((x.right_support == y.right_support));
        }
    }
    BOOST_TEST_REQUIRE(a.interfaces.size() == b.interfaces.size());
    for (std::size_t i = 0; i < a.interfaces.size(); ++i) {
        BOOST_TEST((a.interfaces[i].law == b.interfaces[i].law));
        BOOST_TEST(a.interfaces[i].friction_coefficient == b.interfaces[i].friction_coefficient);
        BOOST_TEST(a.interfaces[i].initial_gap_m == b.interfaces[i].initial_gap_m);
        BOOST_TEST((a.interfaces[i].contact == b.interfaces[i].contact));
        BOOST_TEST(a.interfaces[i].normal_stiffness_pa_per_m == b.interfaces[i].normal_stiffness_pa_per_m);
        BOOST_TEST(a.interfaces[i].tangential_stiffness_pa_per_m == b.interfaces[i].tangential_stiffness_pa_per_m);
    }
    BOOST_TEST_REQUIRE(a.clamps.size() == b.clamps.size());
    for (std::size_t i = 0; i < a.clamps.size(); ++i) {
        BOOST_TEST(a.clamps[i].x_m == b.clamps[i].x_m);
        BOOST_TEST(a.clamps[i].preload_n == b.clamps[i].preload_n);
        BOOST_TEST(a.clamps[i].length_m == b.clamps[i].length_m);
    }
    BOOST_TEST(a.rigid_body.mass_kg == b.rigid_body.mass_kg);
    BOOST_TEST(a.rigid_body.x_m == b.rigid_body.x_m);
    BOOST_TEST(a.rigid_body.tied_leaves == b.rigid_body.tied_leaves);
    BOOST_TEST(a.rigid_body.initial_displacement_m == b.rigid_body.initial_displacement_m);
    BOOST_TEST(a.rigid_body.initial_velocity_m_per_s == b.rigid_body.initial_velocity_m_per_s);
    BOOST_TEST(a.mesh.element_length_m == b.mesh.element_length_m);
    BOOST_TEST((a.symmetry == b.symmetry));
    BOOST_TEST_REQUIRE(a.probe.has_value() == b.probe.has_value());
    if (a.probe) {
        BOOST_TEST(a.probe->interface_index == b.probe->interface_index);
        BOOST_TEST(a.probe->x_m == b.probe->x_m);
    }
}

/// The records of `t_end_s` of closed-form steps from the scenario file and from
/// the built-in example agree to round-off (relative 1e-12 of each column's scale).
void check_reproduces(const char* file, PaperCase c, double t_end_s) {
    Scenario s = load_scenario(scenario_path(file));
    check_same_spec(s.model, paper_example(c));
    BOOST_TEST((s.simulation.mode == Mode::closed_form));
    BOOST_TEST(s.simulation.dt_s == 1e-3);
    BOOST_TEST(s.simulation.solver.tolerance_m == 2e-6);

    s.simulation.t_end_s = t_end_s;
    const System from_file(Model::build(s.model));
    const auto a = simulate(from_file, s.simulation);

    SimulationOptions o;  // the built-in example at the paper's settings (the defaults)
    o.t_end_s = t_end_s;
    const System builtin(Model::build(paper_example(c)));
    const auto b = simulate(builtin, o);

    BOOST_TEST_REQUIRE(a.size() == b.size());
    BOOST_TEST(a.size() >= 301u);
    const auto columns = step_record_columns();
    std::vector<double> scale(columns.size(), 0.0);
    for (const auto& r : b) {
        const auto v = step_record_values(r);
        for (std::size_t j = 0; j < v.size(); ++j) scale[j] = std::max(scale[j], std::abs(v[j]));
    }
    double worst = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const auto va = step_record_values(a[i]), vb = step_record_values(b[i]);
        for (std::size_t j = 0; j < va.size(); ++j) {
            const double d = std::abs(va[j] - vb[j]) / std::max(scale[j], 1e-300);
            worst = std::max(worst, d);
            if (d > 1e-12) BOOST_ERROR("step " << i << " column " << columns[j] << ": " << va[j] << " vs " << vb[j]);
        }
    }
    BOOST_TEST_MESSAGE(file << ": " << a.size() << " records, largest relative difference " << worst);
}

/// The InputError of parsing `text`: its field and message ("accepted" if none).
const auto rejection = stackbeam::testing::scenario_refusal;

/// A small valid scenario: two cantilever leaves (fixed at x = 0), a clamp, the body at the tip of the longer.
const std::string kGood = R"(
[[leaves]]
length_m = 1.0
height_m = 0.01
width_m = 0.05
youngs_modulus_pa = 2.1e11
left_support = "fixed"

[[leaves]]
length_m = 0.6
height_m = 0.01
width_m = 0.05
youngs_modulus_pa = 2.1e11
left_support = "fixed"

[[interfaces]]
law = "coulomb"
friction_coefficient = 0.3

[[clamps]]
x_m = 0.3
preload_n = 500

[rigid_body]
mass_kg = 5
x_m = 1.0

[loading]
kind = "initial-conditions"
initial_velocity_m_per_s = 0.5

[mesh]
element_length_m = 0.05

[integrator]
mode = "closed-form"
dt_s = 1e-3
t_end_s = 0.05
)";

/// kGood with `from` replaced by `to` (which must occur).
std::string edit(const std::string& from, const std::string& to) {
    std::string s = kGood;
    const auto pos = s.find(from);
    BOOST_TEST_REQUIRE(pos != std::string::npos);
    return s.replace(pos, from.size(), to);
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// "test.toml:LINE:" of the last line of the first place where a line starts with `key`
/// (which may span lines; 1-based line numbers).
std::string place_of(const std::string& text, const std::string& key) {
    const auto pos = text.find("\n" + key);
    BOOST_TEST_REQUIRE(pos != std::string::npos);
    const long line = 2 + std::count(text.begin(), text.begin() + static_cast<long>(pos), '\n') +
                      std::count(key.begin(), key.end(), '\n');
    return "test.toml:" + std::to_string(line) + ":";
}

}  // namespace

BOOST_AUTO_TEST_CASE(paper_bonded_file_reproduces_builtin) { check_reproduces("paper_bonded.toml", PaperCase::bonded, 0.3); }
BOOST_AUTO_TEST_CASE(paper_frictionless_file_reproduces_builtin) {
    check_reproduces("paper_frictionless.toml", PaperCase::frictionless, 0.3);
}
BOOST_AUTO_TEST_CASE(paper_friction_file_reproduces_builtin) {
    check_reproduces("paper_friction.toml", PaperCase::friction, 0.3);
}

BOOST_AUTO_TEST_CASE(paper_files_settings) {
    const Scenario f = load_scenario(scenario_path("paper_friction.toml"));
    BOOST_TEST(f.simulation.t_end_s == 2.0);
    BOOST_TEST(f.outputs.csv_path == "paper_friction.csv");
    BOOST_TEST(f.outputs.events_path.empty());
    BOOST_TEST((f.simulation.loading.kind == LoadingKind::initial_conditions));
    BOOST_TEST(!f.description.empty());
}

BOOST_AUTO_TEST_CASE(good_scenario_defaults_and_run) {
    const Scenario s = parse_scenario(kGood, "good.toml");
    BOOST_TEST(s.source == "good.toml");
    BOOST_TEST(s.model.leaves[0].x_start_m == 0.0);
    BOOST_TEST(s.model.leaves[1].density_kg_per_m3 == 0.0);
    BOOST_TEST((s.model.leaves[0].right_support == SupportKind::free));
    BOOST_TEST((s.model.symmetry == Symmetry::full));
    BOOST_TEST(s.model.clamps[0].preload_n == 500.0);  // an integer is accepted for a number
    BOOST_TEST(s.model.rigid_body.initial_displacement_m == 0.0);
    BOOST_TEST((s.simulation.solver.kind == SolverKind::exact));
    BOOST_TEST(s.outputs.csv_path.empty());
    const System sys(Model::build(s.model));
    const auto r = simulate(sys, s.simulation);
    BOOST_TEST(r.size() == 51u);
    BOOST_TEST(std::isfinite(r.back().w_m));
}

BOOST_AUTO_TEST_CASE(unknown_key_lists_allowed_keys) {
    const auto [field, what] = rejection(edit("width_m = 0.05\nyoungs_modulus_pa = 2.1e11\nleft_support = \"fixed\"\n\n[[leaves]]",
                                              "width_m = 0.05\nyoungs_modulus_pa = 2.1e11\nleft_support = \"fixed\"\nwidht_m = 1\n\n[[leaves]]"));
    BOOST_TEST(field == "leaves[0].widht_m");
    BOOST_TEST(contains(what, "unknown key 'widht_m'"));
    BOOST_TEST(contains(what, "allowed keys are length_m, x_start_m, height_m, width_m"));
    BOOST_TEST(contains(what, "test.toml:8:"));  // file:line:column of the key
}

BOOST_AUTO_TEST_CASE(wrong_type_missing_and_range) {
    auto r = rejection(edit("height_m = 0.01\nwidth_m = 0.05\nyoungs_modulus_pa = 2.1e11\nleft_support = \"fixed\"\n\n[[interfaces]]",
                            "height_m = \"thin\"\nwidth_m = 0.05\nyoungs_modulus_pa = 2.1e11\nleft_support = \"fixed\"\n\n[[interfaces]]"));
    BOOST_TEST(r.first == "leaves[1].height_m");
    BOOST_TEST(contains(r.second, "wrong type, a string: must be a number"));

    r = rejection(edit("mass_kg = 5\n", ""));
    BOOST_TEST(r.first == "rigid_body.mass_kg");
    BOOST_TEST(contains(r.second, "required key is missing"));

    r = rejection(edit("mass_kg = 5", "mass_kg = -5"));  // range: Model::build, path and location of the file
    BOOST_TEST(r.first == "rigid_body.mass_kg");
    BOOST_TEST(contains(r.second, "value -5 is not allowed: must be finite and > 0 [kg]"));
    BOOST_TEST(r.second.rfind("test.toml:", 0) == 0);  // "file:line:column: key: message"

    r = rejection(edit("mass_kg = 5", "mass_kg = nan"));
    BOOST_TEST(r.first == "rigid_body.mass_kg");
    BOOST_TEST(contains(r.second, "value nan is not allowed"));

    r = rejection(edit("initial_velocity_m_per_s = 0.5", "initial_velocity_m_per_s = inf"));
    BOOST_TEST(r.first == "loading.initial_velocity_m_per_s");  // Model names rigid_body.*: translated

    r = rejection(edit("dt_s = 1e-3", "dt_s = -1e-3"));
    BOOST_TEST(r.first == "integrator.dt_s");  // SimulationOptions names "dt": translated
    BOOST_TEST(contains(r.second, "value -0.001 is not allowed"));

    r = rejection(edit("mode = \"closed-form\"", "mode = \"euler\""));
    BOOST_TEST(r.first == "integrator.mode");
    BOOST_TEST(contains(r.second, "allowed closed-form"));
}

BOOST_AUTO_TEST_CASE(interface_laws_and_loading_kind) {
    auto r = rejection(edit("law = \"coulomb\"", "law = \"bonded\""));  // bonded takes no mu
    BOOST_TEST(r.first == "interfaces[0].friction_coefficient");
    r = rejection(edit("law = \"coulomb\"", "law = \"sticky\""));
    BOOST_TEST(r.first == "interfaces[0].law");
    BOOST_TEST(contains(r.second, "'coulomb', 'frictionless', 'bonded'"));
    r = rejection(edit("kind = \"initial-conditions\"", "kind = \"harmonic-force\""));
    BOOST_TEST(r.first == "loading.kind");
    BOOST_TEST(contains(r.second, "'initial-conditions', 'applied-force', 'prescribed-displacement', 'base-excitation'"));
}

BOOST_AUTO_TEST_CASE(text_must_be_utf8) {
    // Invalid UTF-8 is refused before the TOML parser sees it (toml11 3.7.1 reads out of
    // bounds reporting it in a literal string: found by fuzz/fuzz_scenario), with the
    // byte, line and column; valid multi-byte text (2, 3 and 4 bytes) passes.
    BOOST_TEST(rejection("description = 'caf\xC3\xA9 \xE2\x80\x94 \xF0\x9F\x94\xA7'\n" + kGood).first == "accepted");
    const std::pair<const char*, const char*> bad[] = {
        {"\xA5", "byte 0xA5 at line 2, column 20"},          // a continuation byte alone
        {"\xC0\xAF", "byte 0xC0 at line 2, column 20"},     // an overlong '/'
        {"\xED\xA0\x80", "byte 0xED at line 2, column 20"}, // a surrogate (U+D800)
        {"\xF4\x90\x80\x80", "byte 0xF4"},                 // above U+10FFFF
        {"\xE2\x80", "byte 0xE2"},                           // cut short
    };
    for (const auto& [bytes, where] : bad) {
        const auto r = rejection("# a comment\ndescription = 'bad " + std::string(bytes) + "'\n" + kGood);
        BOOST_TEST(r.first == "test.toml");
        BOOST_TEST(contains(r.second, "not UTF-8 text: " + std::string(where)), r.second);
    }
    const auto r = rejection(kGood + "\xE2\x80");  // cut short at the very end
    BOOST_TEST(contains(r.second, "not UTF-8 text: byte 0xE2"), r.second);
}

BOOST_AUTO_TEST_CASE(malformed_and_unreadable) {
    auto r = rejection(edit("[mesh]", "[mesh"));
    BOOST_TEST(r.first == "test.toml");
    BOOST_TEST(contains(r.second, "TOML syntax error"));
    r = rejection(kGood + "\n[mesh]\nelement_length_m = 0.1\n");  // a table defined twice
    BOOST_TEST(r.first == "test.toml");
    BOOST_CHECK_THROW(load_scenario(scenario_path("no_such_file.toml")), InputError);

    const std::string deep = std::string(40, '[') + std::string(40, ']');
    r = rejection("a = " + deep + "\n" + kGood);  // refused before the parser recurses
    BOOST_TEST(r.first == "test.toml");
    BOOST_TEST(contains(r.second, "nested deeper than 32 levels at line 1"));
    // brackets in strings and comments do not count
    const std::string text = "description = \"" + deep + "\"  # " + deep + "\n" + "# '''\"\"\" " + deep + "\n" + kGood;
    BOOST_TEST(rejection(text).first == "accepted");
    BOOST_TEST(parse_scenario(text, "t").description == deep);
}

// Issue 18: the elastic interface's keys reach the ModelSpec; absent, the defaults hold
// (rigid, stiffnesses derived, nu = 0.3, point clamps).
BOOST_AUTO_TEST_CASE(elastic_interface_keys) {
    const Scenario d = parse_scenario(kGood, "good.toml");
    BOOST_TEST((d.model.interfaces[0].contact == InterfaceContact::rigid));
    BOOST_TEST(d.model.interfaces[0].normal_stiffness_pa_per_m == 0.0);
    BOOST_TEST(d.model.interfaces[0].tangential_stiffness_pa_per_m == 0.0);
    for (const auto& l : d.model.leaves) BOOST_TEST(l.poisson_ratio == 0.3);
    BOOST_TEST(d.model.clamps[0].length_m == 0.0);

    std::string text = edit("friction_coefficient = 0.3\n",
                            "friction_coefficient = 0.3\ncontact = \"elastic\"\nnormal_stiffness_pa_per_m = 2.5e13\n"
                            "tangential_stiffness_pa_per_m = 1e13\n");
    text.replace(text.find("preload_n = 500\n"), 16, "preload_n = 500\nlength_m = 0.04\n");
    text.replace(text.find("youngs_modulus_pa = 2.1e11\n"), 27, "youngs_modulus_pa = 2.1e11\npoisson_ratio = 0.29\n");
    const Scenario s = parse_scenario(text, "test.toml");
    BOOST_TEST((s.model.interfaces[0].contact == InterfaceContact::elastic));
    BOOST_TEST(s.model.interfaces[0].normal_stiffness_pa_per_m == 2.5e13);
    BOOST_TEST(s.model.interfaces[0].tangential_stiffness_pa_per_m == 1e13);
    BOOST_TEST(s.model.leaves[0].poisson_ratio == 0.29);
    BOOST_TEST(s.model.leaves[1].poisson_ratio == 0.3);
    BOOST_TEST(s.model.clamps[0].length_m == 0.04);
    BOOST_TEST(s.key_locations.count("interfaces[0].contact") == 1u);

    // elastic without stiffnesses: derived (0 in the spec)
    const Scenario e = parse_scenario(edit("friction_coefficient = 0.3\n", "friction_coefficient = 0.3\ncontact = \"elastic\"\n"),
                                      "test.toml");
    BOOST_TEST((e.model.interfaces[0].contact == InterfaceContact::elastic));
    BOOST_TEST(e.model.interfaces[0].normal_stiffness_pa_per_m == 0.0);
}

BOOST_AUTO_TEST_CASE(elastic_interface_keys_rejected_at_their_line) {
    struct Case {
        std::string from, to, field, key, text;
    };
    const std::vector<Case> cases = {
        {"friction_coefficient = 0.3\n", "friction_coefficient = 0.3\ncontact = \"soft\"\n", "interfaces[0].contact",
         "contact", "value 'soft' is not allowed: must be 'rigid' or 'elastic'"},
        {"friction_coefficient = 0.3\n", "friction_coefficient = 0.3\ncontact = 1\n", "interfaces[0].contact", "contact",
         "wrong type, an integer: must be a string"},
        {"friction_coefficient = 0.3\n",
         "friction_coefficient = 0.3\ncontact = \"elastic\"\nnormal_stiffness_pa_per_m = -1e13\n",
         "interfaces[0].normal_stiffness_pa_per_m", "normal_stiffness_pa_per_m",
         "value -1e+13 is not allowed: must be finite and >= 0 [Pa/m]"},
        {"friction_coefficient = 0.3\n", "friction_coefficient = 0.3\ntangential_stiffness_pa_per_m = 1e13\n",
         "interfaces[0].tangential_stiffness_pa_per_m", "tangential_stiffness_pa_per_m",
         "value 1e+13 is given but interfaces[0].contact is 'rigid'"},
        {"youngs_modulus_pa = 2.1e11\n", "youngs_modulus_pa = 2.1e11\npoisson_ratio = 0.5\n", "leaves[0].poisson_ratio",
         "poisson_ratio", "value 0.5 is not allowed: must be in (-1, 0.5)"},
        {"preload_n = 500\n", "preload_n = 500\nlength_m = -1\n", "clamps[0].length_m", "preload_n = 500\nlength_m",
         "value -1 is not allowed: must be finite and >= 0 [m]"},
        {"friction_coefficient = 0.3\n", "friction_coefficient = 0.3\nnormal_stifness_pa_per_m = 1\n",
         "interfaces[0].normal_stifness_pa_per_m", "normal_stifness", "allowed keys are law, friction_coefficient, "
         "initial_gap_m, contact, normal_stiffness_pa_per_m, tangential_stiffness_pa_per_m"},
    };
    for (const auto& c : cases) {
        const std::string text = edit(c.from, c.to);
        const auto [field, what] = rejection(text);
        BOOST_TEST_CONTEXT(c.field << ": " << what) {
            BOOST_TEST(field == c.field);
            BOOST_TEST(what.rfind(place_of(text, c.key), 0) == 0);  // "test.toml:LINE:COLUMN: field: ..."
            BOOST_TEST(contains(what, ": " + c.field + ": "));
            BOOST_TEST(contains(what, c.text));
        }
    }
}

BOOST_AUTO_TEST_CASE(graduated_elastic_scenario_is_the_test_suites_graduated_spring) {
    // scenarios/graduated_elastic.toml is graduated_stack(160, 4) (tests/test_support.hpp: the
    // paper's leaves, main leaf pinned, three shorter free leaves, two 1000 N clamps, mu = 0.5)
    // with every interface elastic: the same leaves to the 4 decimals the file gives (lengths
    // 0.5 - 0.12 k m exactly), and its friction-mesh ratio is the elastic one, mu t / l = 0.8
    // with l = 3.12 mm (test_friction_mesh_ratio), against 1.6 and more for the same mesh rigid.
    const Scenario s = load_scenario(scenario_path("graduated_elastic.toml"));
    BOOST_TEST_REQUIRE(s.model.leaves.size() == 4u);
    for (std::size_t k = 0; k < 4; ++k) {
        BOOST_TEST(s.model.leaves[k].length_m == 0.5 - 0.12 * static_cast<double>(k), boost::test_tools::tolerance(1e-12));
        BOOST_TEST(s.model.leaves[k].x_start_m == 0.06 * static_cast<double>(k), boost::test_tools::tolerance(1e-12));
    }
    for (const auto& f : s.model.interfaces) {
        BOOST_TEST((f.contact == InterfaceContact::elastic));
        BOOST_TEST(f.friction_coefficient == 0.5);
    }
    const Model elastic = Model::build(s.model);
    ModelSpec rigid_spec = s.model;
    for (auto& f : rigid_spec.interfaces) f.contact = InterfaceContact::rigid;
    const Model rigid = Model::build(rigid_spec);
    BOOST_TEST(friction_mesh_ratio(elastic).ratio == 0.5 * 0.005 / friction_mesh_ratio(elastic).decay_length_m,
               boost::test_tools::tolerance(1e-12));
    BOOST_TEST(friction_mesh_ratio(elastic).ratio < 0.81);
    // rigid: mu t / h with h the shortest pair spacing (1.54 mm between a leaf end and a clamp)
    BOOST_TEST(friction_mesh_ratio(rigid).ratio == 0.5 * 0.005 / friction_mesh_ratio(rigid).pair_spacing_m,
               boost::test_tools::tolerance(1e-12));
    BOOST_TEST(friction_mesh_ratio(rigid).ratio > 1.6);
}
