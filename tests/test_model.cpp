// The model description: meshing, pairs of the paper example, and bad input
// rejected with the field named.
#define BOOST_TEST_MODULE model
#include <boost/test/unit_test.hpp>
#include <cmath>
#include <functional>
#include <limits>

#include "stackbeam/errors.hpp"
#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/fe/system.hpp"

namespace tt = boost::test_tools;
using namespace stackbeam;

namespace {
std::string rejected_field(const ModelSpec& s) {
    try {
        System sys(Model::build(s));
    } catch (const InputError& e) {
        return e.field();
    }
    return "accepted";
}
}  // namespace

BOOST_AUTO_TEST_CASE(paper_example_mesh_and_pairs) {
    const Model m = Model::build(paper_example(PaperCase::friction));
    BOOST_TEST(m.nodes_x().size() == 21u);                       // 20 elements on the half leaf
    BOOST_TEST(m.nodes_x()[8] == 0.1, tt::tolerance(1e-12));      // clamps at nodes 8 and 16
    BOOST_TEST(m.nodes_x()[16] == 0.2, tt::tolerance(1e-12));
    BOOST_TEST(m.candidate_pairs().size() == 42u);                // 2 interfaces x 21 nodes
    const System s(m);
    // Dropped: both components at the pinned end (normal fixed by the supports, so no
    // friction limit) and at midspan (the seat ties both leaves): 2 x 19 pairs remain,
    // of which 2 x 2 are clamps.
    BOOST_TEST(s.pairs().size() == 38u);
    int clamps = 0;
    for (const auto& p : s.pairs()) clamps += p.kind == PairKind::clamp;
    BOOST_TEST(clamps == 4);
    BOOST_TEST(s.num_components() == 76);
    BOOST_TEST(s.pair_spec(s.probe_pair()).x_m == 0.1, tt::tolerance(1e-12));
    BOOST_TEST(s.pair_spec(s.probe_pair()).interface_index == 0);
    // Bonded: the tangential tie at the pinned end stays (it stiffens the stack).
    const System b(Model::build(paper_example(PaperCase::bonded)));
    BOOST_TEST(b.num_components() == 78);
    // Frictionless: only normal components.
    const System f(Model::build(paper_example(PaperCase::frictionless)));
    BOOST_TEST(f.num_components() == 38);
}

BOOST_AUTO_TEST_CASE(mesh_refines_between_key_points) {
    PaperExampleOptions o;
    o.elements_per_half_leaf = 7;  // 0.25/7 m does not divide 0.1: segments are split evenly
    const Model m = Model::build(paper_example(PaperCase::friction, o));
    for (double x : {0.1, 0.2, 0.25}) {
        BOOST_TEST(std::any_of(m.nodes_x().begin(), m.nodes_x().end(), [&](double n) { return std::abs(n - x) < 1e-12; }));
    }
    for (std::size_t i = 1; i < m.nodes_x().size(); ++i) BOOST_TEST(m.nodes_x()[i] - m.nodes_x()[i - 1] <= 0.25 / 7 + 1e-12);
}

BOOST_AUTO_TEST_CASE(bad_input_names_the_field) {
    const ModelSpec good = paper_example(PaperCase::friction);
    BOOST_TEST(rejected_field(good) == "accepted");
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    struct Case { const char* field; std::function<void(ModelSpec&)> edit; };
    const std::vector<Case> cases = {
        {"leaves[2].height_m", [](ModelSpec& s) { s.leaves[2].height_m = -0.005; }},
        {"leaves[0].length_m", [&](ModelSpec& s) { s.leaves[0].length_m = nan; }},
        {"leaves[1].width_m", [](ModelSpec& s) { s.leaves[1].width_m = 0.0; }},
        {"leaves[1].youngs_modulus_pa", [&](ModelSpec& s) { s.leaves[1].youngs_modulus_pa = inf; }},
        {"leaves[0].density_kg_per_m3", [](ModelSpec& s) { s.leaves[0].density_kg_per_m3 = -1.0; }},
        {"interfaces", [](ModelSpec& s) { s.interfaces.pop_back(); }},
        {"interfaces[1].friction_coefficient", [](ModelSpec& s) { s.interfaces[1].friction_coefficient = -0.5; }},
        {"rigid_body.mass_kg", [](ModelSpec& s) { s.rigid_body.mass_kg = 0.0; }},
        {"rigid_body.x_m", [](ModelSpec& s) { s.rigid_body.x_m = 0.7; }},
        {"clamps[2].x_m", [](ModelSpec& s) { s.clamps[2].x_m = 0.9; }},
        {"clamps[1].x_m", [](ModelSpec& s) { s.clamps[1].x_m = 0.1; }},
        {"clamps[0].preload_n", [](ModelSpec& s) { s.clamps[0].preload_n = -5.0; }},
        {"mesh.element_length_m", [](ModelSpec& s) { s.mesh.element_length_m = 0.0; }},
        {"interfaces[0].leaves", [](ModelSpec& s) { s.leaves[1].x_start_m = 0.6; s.symmetry = Symmetry::full; }},
        {"clamps[0].x_m", [](ModelSpec& s) { s.clamps[0].preload_n = 10.0; }},  // half model: not mirrored
        {"probe.interface_index", [](ModelSpec& s) { s.probe = ProbeSpec{2, 0.1}; }},
        {"leaves", [](ModelSpec& s) { s.leaves.clear(); s.interfaces.clear(); }},
    };
    for (const auto& c : cases) {
        ModelSpec s = good;
        c.edit(s);
        BOOST_TEST(rejected_field(s) == c.field);
    }
}

BOOST_AUTO_TEST_CASE(error_messages_say_value_and_allowed_range) {
    ModelSpec s = paper_example(PaperCase::friction);
    s.leaves[2].height_m = -0.005;
    try {
        Model::build(s);
        BOOST_FAIL("accepted a negative height");
    } catch (const InputError& e) {
        const std::string msg = e.what();
        BOOST_TEST(msg.find("leaves[2].height_m") != std::string::npos);
        BOOST_TEST(msg.find("-0.005") != std::string::npos);
        BOOST_TEST(msg.find("> 0") != std::string::npos);
    }
}

BOOST_AUTO_TEST_CASE(unrestrained_leaf_is_rejected) {
    // A short leaf with free ends and not tied by the seat floats: the stiffness with R
    // held is singular, which must be reported, not factorised into garbage.
    ModelSpec s;
    s.leaves.push_back({0.5, 0.0, 0.005, 0.05, 2e10, 0.0, SupportKind::pinned, SupportKind::pinned});
    s.leaves.push_back({0.2, 0.0, 0.005, 0.05, 2e10, 0.0, SupportKind::free, SupportKind::free});
    s.interfaces.push_back({InterfaceLaw::coulomb, 0.3, 0.0});
    s.rigid_body = {20.0, 0.25, {}, 0.0, 1.0};
    s.mesh.element_length_m = 0.025;
    BOOST_TEST(rejected_field(s) == "leaves");
}
