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
        {"leaves[1].poisson_ratio", [](ModelSpec& s) { s.leaves[1].poisson_ratio = 0.5; }},
        {"leaves[0].poisson_ratio", [](ModelSpec& s) { s.leaves[0].poisson_ratio = -1.0; }},
        {"interfaces[0].normal_stiffness_pa_per_m",
         [](ModelSpec& s) { s.interfaces[0].contact = InterfaceContact::elastic; s.interfaces[0].normal_stiffness_pa_per_m = -1.0; }},
        {"interfaces[1].tangential_stiffness_pa_per_m", [](ModelSpec& s) { s.interfaces[1].tangential_stiffness_pa_per_m = 1e13; }},
        {"clamps[0].length_m", [](ModelSpec& s) { s.clamps[0].length_m = -1.0; }},
        {"clamps[0].x_m", [](ModelSpec& s) { s.clamps[0].length_m = 0.01; }},  // half model: not mirrored
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

// ---- the elastic interface's layer (issue 18; model.hpp, interface_layer) -------------------

namespace {
// k_n, k_t, l are closed-form expressions of the spec: the only error is round-off
constexpr double kRoundOff = 1e-12;

/// Two leaves from x = 0 to 0.4 m, fixed at x = 0, one elastic interface, a clamp at
/// x = 0.2 m, the body at the tip; 0.05 m elements: nodes 0, 0.05, ..., 0.4 (9 pairs).
ModelSpec two_leaves(double clamp_length_m) {
    ModelSpec s;
    s.leaves.push_back({0.4, 0.0, 0.007, 0.06, 200e9, 0.0, SupportKind::fixed, SupportKind::free});
    s.leaves.push_back({0.4, 0.0, 0.007, 0.05, 200e9, 0.0, SupportKind::fixed, SupportKind::free});
    InterfaceSpec f;
    f.friction_coefficient = 0.3;
    f.contact = InterfaceContact::elastic;
    s.interfaces.push_back(f);
    s.clamps.push_back({0.2, 500.0, clamp_length_m});
    s.rigid_body = {5.0, 0.4, {}, 0.0, 0.5};
    s.mesh.element_length_m = 0.05;
    return s;
}
}  // namespace

BOOST_AUTO_TEST_CASE(derived_layer_stiffness_of_equal_steel_leaves) {
    // E = 200 GPa, nu = 0.3, 7 mm on 7 mm: 1/k_n = 2 (t/2) / E' with E' = E / (1 - nu^2) = E / 0.91,
    // 1/k_t = 2 (t/2) / G with G = E / 2.6
    ModelSpec s = two_leaves(0.0);
    const InterfaceLayer layer = interface_layer(s, 0);
    BOOST_TEST(layer.normal_stiffness_pa_per_m == 2e11 / 0.91 / 0.007, tt::tolerance(kRoundOff));  // 3.1397e13
    BOOST_TEST(layer.tangential_stiffness_pa_per_m == 2e11 / 2.6 / 0.007, tt::tolerance(kRoundOff));  // 1.0989e13
    BOOST_TEST(layer.normal_stiffness_pa_per_m == 3.1397e13, tt::tolerance(1e-4));  // the docs' rounded value
    BOOST_TEST(layer.contact_width_m == 0.05);  // the narrower leaf
    // a given value replaces the derived one, each on its own
    s.interfaces[0].normal_stiffness_pa_per_m = 1e12;
    const InterfaceLayer given = interface_layer(s, 0);
    BOOST_TEST(given.normal_stiffness_pa_per_m == 1e12);
    BOOST_TEST(given.tangential_stiffness_pa_per_m == 2e11 / 2.6 / 0.007, tt::tolerance(kRoundOff));
}

BOOST_AUTO_TEST_CASE(derived_layer_of_two_materials) {
    // A: steel, 7 mm, nu 0.3, b 60 mm; B: aluminium, E = 70 GPa, nu 0.33, 5 mm, b 50 mm. By hand:
    //   t_A/(2 E'_A) = 0.0035 * 0.91 / 2e11 = 1.5925e-14,  t_B/(2 E'_B) = 0.0025 * 0.8911 / 7e10 = 3.1825e-14
    //   1/k_n = 4.775e-14 m/Pa:  k_n = 2.0942408377e13 Pa/m
    //   t_A/(2 G_A) = 0.0035 * 2.6 / 2e11 = 4.55e-14,       t_B/(2 G_B) = 0.0025 * 2.66 / 7e10 = 9.5e-14
    //   1/k_t = 1.405e-13 m/Pa:  k_t = 7.1174377224e12 Pa/m
    //   EI_A = 2e11 * 0.06 * 0.007^3 / 12 = 343 N m^2, EI_B = 7e10 * 0.05 * 0.005^3 / 12 = 36.458333 N m^2,
    //   EI_eq = 343 * 36.458333 / 379.458333 = 32.955419 N m^2, b = 0.05 m:
    //   l = (4 * 32.955419 / (2.0942408e13 * 0.05))^(1/4) = 3.3496355e-3 m
    ModelSpec s = two_leaves(0.0);
    s.leaves[1].youngs_modulus_pa = 70e9;
    s.leaves[1].poisson_ratio = 0.33;
    s.leaves[1].height_m = 0.005;
    const InterfaceLayer layer = interface_layer(s, 0);
    BOOST_TEST(layer.normal_stiffness_pa_per_m == 1.0 / 4.775e-14, tt::tolerance(kRoundOff));
    BOOST_TEST(layer.tangential_stiffness_pa_per_m == 1.0 / 1.405e-13, tt::tolerance(kRoundOff));
    BOOST_TEST(layer.decay_length_m == 3.3496355e-3, tt::tolerance(1e-7));  // 8 digits written above
}

BOOST_AUTO_TEST_CASE(pair_compliance_over_the_tributary_length) {
    // c = 1 / (k b L): L = one element (0.05 m) at an interior node, half of it at the ends
    // of the overlap (x = 0 and 0.4), the clamp's own length at the clamp (0.04 m).
    const Model m = Model::build(two_leaves(0.04));
    const double kn = 2e11 / 0.91 / 0.007, kt = 2e11 / 2.6 / 0.007, b = 0.05;
    BOOST_TEST_REQUIRE(m.candidate_pairs().size() == 9u);
    for (const PairSpec& p : m.candidate_pairs()) {
        const double L = p.kind == PairKind::clamp ? 0.04 : (p.node == 0 || p.node == 8) ? 0.025 : 0.05;
        BOOST_TEST_CONTEXT("pair at x = " << p.x_m) {
            BOOST_TEST((p.kind == PairKind::clamp) == (std::abs(p.x_m - 0.2) < 1e-12));
            BOOST_TEST(p.normal_compliance_m_per_n == 1.0 / (kn * b * L), tt::tolerance(kRoundOff));
            BOOST_TEST(p.tangential_compliance_m_per_n == 1.0 / (kt * b * L), tt::tolerance(kRoundOff));
        }
    }
    // a point clamp stays rigid; the rest of the interface keeps its layer
    const Model point_clamp = Model::build(two_leaves(0.0));  // kept alive: the loop reads its pairs
    for (const PairSpec& p : point_clamp.candidate_pairs()) {
        BOOST_TEST(((p.kind == PairKind::clamp) == (p.normal_compliance_m_per_n == 0.0)));
        BOOST_TEST(((p.kind == PairKind::clamp) == (p.tangential_compliance_m_per_n == 0.0)));
    }
    // a rigid interface: no compliance anywhere, even with a clamp length
    ModelSpec rigid = two_leaves(0.04);
    rigid.interfaces[0].contact = InterfaceContact::rigid;
    const Model rigid_model = Model::build(rigid);
    for (const PairSpec& p : rigid_model.candidate_pairs()) {
        BOOST_TEST(p.normal_compliance_m_per_n == 0.0);
        BOOST_TEST(p.tangential_compliance_m_per_n == 0.0);
    }
}

BOOST_AUTO_TEST_CASE(clamp_on_the_half_models_symmetry_plane) {
    // The paper example (half model, 20 elements of 12.5 mm, 5 mm leaves, E = 2e10 Pa, nu 0.3,
    // b = 0.05 m), elastic, its clamps 20 mm long, one more clamp (30 mm) on the symmetry
    // plane x = 0.25 m: that pair carries half of it, 15 mm. Pinned end (node 0): half an element.
    ModelSpec s = paper_example(PaperCase::friction);
    for (auto& f : s.interfaces) f.contact = InterfaceContact::elastic;
    for (auto& c : s.clamps) c.length_m = 0.02;
    s.clamps.push_back({0.25, 100.0, 0.03});
    const Model m = Model::build(s);
    const double kn = 2e10 / 0.91 / 0.005, b = 0.05, h = 0.0125;
    for (const PairSpec& p : m.candidate_pairs()) {
        double L = h;
        if (p.node == 0) L = 0.5 * h;
        if (p.kind == PairKind::clamp) L = p.node == m.attachment_node() ? 0.015 : 0.02;
        BOOST_TEST_CONTEXT("interface " << p.interface_index << ", x = " << p.x_m) {
            BOOST_TEST(p.normal_compliance_m_per_n == 1.0 / (kn * b * L), tt::tolerance(kRoundOff));
        }
    }
    BOOST_TEST((m.candidate_pairs().back().kind == PairKind::clamp));
}
