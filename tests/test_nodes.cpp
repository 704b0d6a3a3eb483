// The nodes' displacements as an output (Stepper::nodes(), System::leaf_nodes, simulate's
// on_nodes): the static shape of a single leaf against the Euler-Bernoulli closed form at every
// node, the half model mirrored against the whole one, and on every stepper make_stepper builds
// the node at R's seat moving with the record's w at every record.
#define BOOST_TEST_MODULE nodes
#include <boost/test/unit_test.hpp>
#include <algorithm>
#include <cmath>

#include "single_leaf.hpp"
#include "test_support.hpp"
#include "stackbeam/errors.hpp"
#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/time/stepper.hpp"

using namespace stackbeam;

namespace {

constexpr double kLength = 0.5, kHeight = 0.005, kWidth = 0.05, kE = 2.0e11;
constexpr double kW0 = 0.01;  // R's initial displacement [m]

/// A pinned-pinned leaf with R at midspan, held at w(0) = kW0 at rest: the initial record of the
/// closed-form mode is the static shape of that deflection.
std::vector<LeafNodes> initial_nodes(Symmetry symmetry) {
    ModelSpec spec = testing::single_leaf(kLength, kHeight, kWidth, kE, SupportKind::pinned, SupportKind::pinned,
                                          0.5 * kLength, kLength / 20.0);
    spec.symmetry = symmetry;
    spec.rigid_body.initial_displacement_m = kW0;
    const System system(Model::build(spec));
    SimulationOptions o;
    o.t_end_s = 1e-3;
    const auto stepper = make_stepper(system, o);
    BOOST_TEST(stepper->current().w_m == kW0);
    return stepper->nodes();
}

}  // namespace

// A simply supported beam under a midspan load P deflects v(x) = P x (3 L^2 - 4 x^2) / (48 E I) for
// x <= L/2 (Timoshenko & Gere), w0 = P L^3 / (48 E I) at midspan, so with R held at w0:
//     v(x) = w0 x (3 L^2 - 4 x^2) / L^3,   theta(x) = w0 (3 L^2 - 12 x^2) / L^3,
// mirrored for x > L/2. The cubic Hermite element is exact at the nodes for loads at nodes (its
// shape functions hold the homogeneous solution), so the FE agrees to round-off: the stiffness
// solve's error, about cond(K) eps ~ 1e-16 * (L/h)^4 = 1.6e-11 of w0 (h = L/20 the element
// length): tolerance 1e-10 w0 (and 1e-10 w0 / L on theta; measured 1.2e-13 and 7.7e-13).
BOOST_AUTO_TEST_CASE(simply_supported_leaf_matches_euler_bernoulli_at_every_node) {
    for (const Symmetry sym : {Symmetry::full, Symmetry::half}) {
        const auto nodes = initial_nodes(sym);
        BOOST_TEST_REQUIRE(nodes.size() == 1u);
        const LeafNodes& leaf = nodes[0];
        BOOST_TEST(leaf.leaf == 0);
        BOOST_TEST_REQUIRE(leaf.x_m.size() == 21u);  // 20 elements on the whole leaf, also mirrored
        BOOST_TEST_REQUIRE(leaf.w_m.size() == leaf.x_m.size());
        BOOST_TEST_REQUIRE(leaf.theta_rad.size() == leaf.x_m.size());
        BOOST_TEST(leaf.x_m.front() == 0.0);
        BOOST_TEST(std::abs(leaf.x_m.back() - kLength) <= 1e-15);
        BOOST_TEST(std::is_sorted(leaf.x_m.begin(), leaf.x_m.end()));
        const double L3 = kLength * kLength * kLength;
        double worst_w = 0.0, worst_theta = 0.0;
        for (std::size_t j = 0; j < leaf.x_m.size(); ++j) {
            const double xi = std::min(leaf.x_m[j], kLength - leaf.x_m[j]);  // distance from the nearer support
            const double sign = leaf.x_m[j] <= 0.5 * kLength ? 1.0 : -1.0;   // theta is odd about midspan
            const double v = kW0 * xi * (3 * kLength * kLength - 4 * xi * xi) / L3;
            const double th = sign * kW0 * (3 * kLength * kLength - 12 * xi * xi) / L3;
            worst_w = std::max(worst_w, std::abs(leaf.w_m[j] - v));
            worst_theta = std::max(worst_theta, std::abs(leaf.theta_rad[j] - th));
        }
        BOOST_TEST_MESSAGE((sym == Symmetry::half ? "half" : "full") << " model: max |v - closed form| / w0 = "
                                                                      << worst_w / kW0 << ", theta: "
                                                                      << worst_theta * kLength / kW0);
        BOOST_TEST(worst_w <= 1e-10 * kW0);
        BOOST_TEST(worst_theta <= 1e-10 * kW0 / kLength);
    }
}

// The half model's nodes mirrored about the seat are the whole model's: the same nodes (the
// full mesh has the half's nodes and their mirror images), the same displacements to round-off
// of the two solves (1e-10 w0 as above), theta of opposite sign on the mirrored side.
BOOST_AUTO_TEST_CASE(mirrored_half_equals_the_whole_model) {
    const auto half = initial_nodes(Symmetry::half), full = initial_nodes(Symmetry::full);
    BOOST_TEST_REQUIRE(half[0].x_m.size() == full[0].x_m.size());
    for (std::size_t j = 0; j < full[0].x_m.size(); ++j) {
        BOOST_TEST(std::abs(half[0].x_m[j] - full[0].x_m[j]) <= 1e-15);
        BOOST_TEST(std::abs(half[0].w_m[j] - full[0].w_m[j]) <= 1e-10 * kW0);
        BOOST_TEST(std::abs(half[0].theta_rad[j] - full[0].theta_rad[j]) <= 1e-10 * kW0 / kLength);
    }
}

BOOST_AUTO_TEST_CASE(leaf_nodes_refuses_a_vector_of_the_wrong_size) {
    const ModelSpec spec = testing::single_leaf(kLength, kHeight, kWidth, kE, SupportKind::pinned,
                                                SupportKind::pinned, 0.5 * kLength, kLength / 4.0);
    const System system(Model::build(spec));
    try {
        system.leaf_nodes(Eigen::VectorXd::Zero(system.num_reduced_dofs() + 1));
        BOOST_FAIL("no InputError");
    } catch (const InputError& e) {
        BOOST_TEST(e.field() == "z");
    }
}

namespace {

struct Case {
    const char* name;
    PaperCase paper_case;
    double density;
    Mode mode;
    double dt_s, t_end_s;
    ContactPath path = ContactPath::automatic;
    bool massive_stack = false;
    /// |node at the seat - w| allowed, relative to max |w| over the run: 0 where the stepper's w
    /// is the seat's DOF of the same z (the dense massless modes: z is solved with w given;
    /// newmark, the held and the massive stack: w is z's last entry). The sparse closed-form
    /// path's w is eq. 16's w_free + (gamma/k) c^T p, its z the solve of the augmented system
    /// (closed_form_stepper.hpp), equal in exact arithmetic; the modal stepper sums w =
    /// phi_w q + r_w p in another order than its z = Phi (q - Omega^-2 Phi^T G^T p) + K^-1 G^T p.
    /// Both: round-off of sums of a few terms of the size of w, ~1e-15 (measured 1.8e-16 and
    /// 9.7e-16); 1e-12.
    double tolerance = 0.0;
};

/// Every stepper make_stepper builds (as test_stepper_contract): simulate with on_nodes, then
/// at every record every leaf whole (the paper example is the half model: 2 x 20 elements) and
/// the node at R's seat (every leaf is tied there) at the record's w.
void check_seat_follows_w(const Case& c) {
    const ModelSpec spec = testing::paper_with_mass(c.paper_case, c.density, c.massive_stack);
    const int elements_per_half_leaf = c.massive_stack ? 10 : PaperExampleOptions{}.elements_per_half_leaf;
    const System system(Model::build(spec));
    SimulationOptions o;
    o.mode = c.mode;
    o.dt_s = c.dt_s;
    o.t_end_s = c.t_end_s;
    o.contact_path = c.path;
    if (c.massive_stack) {
        o.cvode.leaf_inertia = LeafInertia::massive;
        o.solver.tolerance_m = 1e-9;
    }
    const double x_r = spec.rigid_body.x_m;
    std::vector<std::vector<LeafNodes>> seen;
    std::vector<double> seen_t;
    const auto records = simulate(system, o, {}, nullptr, {}, [&](double t, const std::vector<LeafNodes>& nodes) {
        seen_t.push_back(t);
        seen.push_back(nodes);
    });
    BOOST_TEST_REQUIRE(seen.size() == records.size());
    double w_max = 0.0;
    for (const auto& r : records) w_max = std::max(w_max, std::abs(r.w_m));
    BOOST_TEST_REQUIRE(w_max > 0.0);
    double worst = 0.0;
    for (std::size_t i = 0; i < records.size(); ++i) {
        BOOST_TEST(seen_t[i] == records[i].t_s);
        BOOST_TEST_REQUIRE(seen[i].size() == spec.leaves.size());
        for (std::size_t l = 0; l < spec.leaves.size(); ++l) {
            const LeafNodes& leaf = seen[i][l];
            BOOST_TEST(leaf.leaf == static_cast<int>(l));
            BOOST_TEST_REQUIRE(leaf.x_m.size() == static_cast<std::size_t>(2 * elements_per_half_leaf + 1));
            const std::size_t seat = leaf.x_m.size() / 2;
            BOOST_TEST(std::abs(leaf.x_m[seat] - x_r) <= 1e-12);
            BOOST_TEST(leaf.theta_rad[seat] == 0.0);  // the symmetry plane
            worst = std::max(worst, std::abs(leaf.w_m[seat] - records[i].w_m));
            for (std::size_t j = 0; j < seat; ++j) {  // the mirror image
                BOOST_TEST(leaf.w_m[leaf.x_m.size() - 1 - j] == leaf.w_m[j]);
                BOOST_TEST(leaf.theta_rad[leaf.x_m.size() - 1 - j] == -leaf.theta_rad[j]);
            }
        }
    }
    BOOST_TEST_MESSAGE(c.name << ": max |v at the seat - w| / max |w| = " << worst / w_max);
    BOOST_TEST(worst <= c.tolerance * w_max);
    // the stepper itself: nodes() at its current record is what simulate observed
    const auto stepper = make_stepper(system, o);
    stepper->advance();
    const auto nodes = stepper->nodes();
    BOOST_TEST(nodes[0].w_m == seen[1][0].w_m);
}

}  // namespace

BOOST_AUTO_TEST_CASE(closed_form_dense) {
    check_seat_follows_w({"closed-form dense", PaperCase::friction, 0.0, Mode::closed_form, 1e-3, 0.02, ContactPath::dense});
}
BOOST_AUTO_TEST_CASE(closed_form_sparse) {
    Case c{"closed-form sparse", PaperCase::friction, 0.0, Mode::closed_form, 1e-3, 0.02, ContactPath::sparse};
    c.tolerance = 1e-12;
    check_seat_follows_w(c);
}
BOOST_AUTO_TEST_CASE(cvode_massless) { check_seat_follows_w({"cvode", PaperCase::friction, 0.0, Mode::cvode, 1e-3, 0.02}); }
BOOST_AUTO_TEST_CASE(newmark_steel) { check_seat_follows_w({"newmark", PaperCase::friction, 7850.0, Mode::newmark, 1e-4, 0.005}); }
BOOST_AUTO_TEST_CASE(cvode_held) { check_seat_follows_w({"cvode held", PaperCase::bonded, 7850.0, Mode::cvode, 1e-3, 0.01}); }
BOOST_AUTO_TEST_CASE(cvode_modal) {
    Case c{"cvode modal", PaperCase::friction, 7850.0, Mode::cvode, 1e-3, 0.01};
    c.tolerance = 1e-12;
    check_seat_follows_w(c);
}
BOOST_AUTO_TEST_CASE(cvode_massive) {
    Case c{"cvode massive", PaperCase::friction, 7850.0, Mode::cvode, 1e-4, 1e-3};
    c.massive_stack = true;
    check_seat_follows_w(c);
}
