// Graduated leaves: a stack whose lower leaf is shorter (free ends), as in an
// automotive leaf spring. Bonded stiffness against the composite-beam hand
// calculation; a friction run that must close its energy balance.
#define BOOST_TEST_MODULE graduated
#include <boost/test/unit_test.hpp>
#include <cmath>

#include "stackbeam/time/simulation.hpp"
#include "stackbeam/fe/system.hpp"

namespace tt = boost::test_tools;
using namespace stackbeam;

namespace {
constexpr double L = 0.5, b = 0.05, h = 0.005, E = 2e10, short_len = 0.25;

ModelSpec two_leaves(InterfaceLaw law, double mu, int elements_per_half) {
    ModelSpec s;
    s.leaves.push_back({L, 0.0, h, b, E, 0.0, SupportKind::pinned, SupportKind::pinned});
    s.leaves.push_back({short_len, 0.5 * (L - short_len), h, b, E, 0.0, SupportKind::free, SupportKind::free});
    s.interfaces.push_back({law, mu, 0.0});
    s.rigid_body.mass_kg = 20.0;
    s.rigid_body.x_m = 0.5 * L;
    s.rigid_body.initial_velocity_m_per_s = 1.0;
    s.mesh.element_length_m = 0.5 * L / elements_per_half;
    s.symmetry = Symmetry::half;
    return s;
}

double bonded_k(int n) { return System(Model::build(two_leaves(InterfaceLaw::bonded, 0.0, n))).tied_stiffness_n_per_m(); }
}  // namespace

BOOST_AUTO_TEST_CASE(bonded_graduated_stack_matches_the_stepped_beam) {
    // Bonded, the stack is a pinned beam whose centre part |x - L/2| < 0.125 m is twice
    // as high (I2 = 8 I1). Unit-load method, load P at midspan, M = P x / 2:
    //   delta / P = (1/6) [a^3 / (E I1) + ((L/2)^3 - a^3) / (E I2)],  a = (L - short_len)/2.
    // Tying at nodes converges here only as O(h), not O(h^2) as on the uniform stack:
    // at the short leaf's free tip the bond starts at a node, so about one element
    // length of the stepped part does not act compositely. The error must halve per
    // halving (tolerance 10 %), and a first-order Richardson step (2 k80 - k40) must
    // land on the hand value to the O(h^2) that remains: 1e-4.
    const double I1 = b * h * h * h / 12.0, I2 = 8.0 * I1, a = 0.5 * (L - short_len);
    const double k_hand = 1.0 / ((a * a * a / (E * I1) + (std::pow(0.5 * L, 3) - a * a * a) / (E * I2)) / 6.0);
    const double k40 = bonded_k(40), k80 = bonded_k(80);
    BOOST_TEST_MESSAGE("hand " << k_hand << " N/m, FE 40: " << k40 << ", 80: " << k80);
    BOOST_TEST(k80 < k_hand);
    BOOST_TEST((k_hand - k40) / (k_hand - k80) == 2.0, tt::tolerance(0.1));
    BOOST_TEST(2.0 * k80 - k40 == k_hand, tt::tolerance(1e-4));
    // full model = half model
    ModelSpec full = two_leaves(InterfaceLaw::bonded, 0.0, 20);
    full.symmetry = Symmetry::full;
    BOOST_TEST(System(Model::build(full)).tied_stiffness_n_per_m() == bonded_k(20), tt::tolerance(1e-9));
}

BOOST_AUTO_TEST_CASE(pairs_exist_only_where_the_leaves_overlap) {
    const Model m = Model::build(two_leaves(InterfaceLaw::coulomb, 0.3, 20));
    // half model: nodes every 0.0125 m on [0, 0.25]; the short leaf covers [0.125, 0.25]: 11 nodes
    BOOST_TEST(m.candidate_pairs().size() == 11u);
    for (const auto& p : m.candidate_pairs()) BOOST_TEST(p.x_m >= 0.125 - 1e-12);
    BOOST_TEST(!m.leaf_has_node(1, 0));
}

BOOST_AUTO_TEST_CASE(friction_run_on_a_graduated_stack_closes_its_energy_balance) {
    // mu = 0.3 with a clamp at x = 0.15 m (preload 200 N) crossing the interface: the
    // run must keep kinetic + strain + dissipated = 10 J (m v0^2 / 2) to the O(dt^2)
    // error of the scheme: < 1e-4 of 10 J at dt = 0.5 ms; and dissipate some energy.
    ModelSpec s = two_leaves(InterfaceLaw::coulomb, 0.3, 20);
    s.clamps = {{0.15, 200.0}, {0.35, 200.0}};
    const System sys(Model::build(s));
    SimulationOptions so;
    so.dt_s = 5e-4;
    so.t_end_s = 0.3;
    so.solver.tolerance_m = 1e-11;
    const auto r = simulate(sys, so);
    BOOST_TEST(r.front().kinetic_energy_j == 10.0, tt::tolerance(1e-12));
    for (const auto& x : r) BOOST_CHECK_SMALL(x.energy_balance_error_j, 1e-3);
    BOOST_TEST(r.back().dissipated_energy_j > 0.1);
}
