// Spring ends (LeafEndSpec): eyes (a support point off the leaf's axis), shackles (small
// deflection: an inclined roller along the link) and bushings (springs at the support),
// against statics by hand and closed forms from the unit-load method. Prismatic leaves
// with point loads at nodes: the cubic Hermite element is exact there, so every check is to
// rounding (relative 1e-9, well above the 1e-12 of the factorisations).
#define BOOST_TEST_MODULE spring_ends
#include <boost/test/unit_test.hpp>

#include <cmath>

#include "single_leaf.hpp"
#include "stackbeam/errors.hpp"
#include "stackbeam/fe/system.hpp"
#include "stackbeam/io/scenario.hpp"

using namespace stackbeam;
namespace tt = boost::test_tools;

namespace {

constexpr double kL = 1.4, kT = 0.02, kB = 0.08, kE = 206e9;
const double kEI = kE * kB * kT * kT * kT / 12.0, kEA = kE * kB * kT;

/// One prismatic leaf from x = 0 to kL, the load (the rigid body) at the centre.
ModelSpec leaf_on(SupportKind left, SupportKind right, double seat_x = 0.5 * kL) {
    return testing::single_leaf(kL, kT, kB, kE, left, right, seat_x, kL / 20);
}

double stiffness(const ModelSpec& s) { return System(Model::build(s)).free_stiffness_n_per_m(); }

/// The nodal forces (N_x, N_y, M) [N, N, N m] that the end element needs at a leaf end, K_e d_e:
/// with no other force at an end node, the support's reaction on the leaf.
Eigen::Vector3d end_reaction(const System& sys, const Eigen::VectorXd& d, bool right) {
    const auto& xs = sys.model().nodes_x();
    const int n0 = right ? sys.model().last_node(0) - 1 : 0;
    const double L = xs[n0 + 1] - xs[n0], c = kEI / (L * L * L);
    Eigen::Matrix<double, 6, 6> k = Eigen::Matrix<double, 6, 6>::Zero();
    k(0, 0) = k(3, 3) = kEA / L;
    k(0, 3) = k(3, 0) = -kEA / L;
    const int bi[4] = {1, 2, 4, 5};
    const double kb[4][4] = {{12 * c, 6 * L * c, -12 * c, 6 * L * c},
                             {6 * L * c, 4 * L * L * c, -6 * L * c, 2 * L * L * c},
                             {-12 * c, -6 * L * c, 12 * c, -6 * L * c},
                             {6 * L * c, 2 * L * L * c, -6 * L * c, 4 * L * L * c}};
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) k(bi[i], bi[j]) = kb[i][j];
    Eigen::Matrix<double, 6, 1> de;
    de << d.segment<3>(3 * sys.node_dof(0, n0)), d.segment<3>(3 * sys.node_dof(0, n0 + 1));
    const Eigen::Matrix<double, 6, 1> f = k * de;
    return right ? Eigen::Vector3d(f.tail<3>()) : Eigen::Vector3d(f.head<3>());
}

/// Compliance 1 / k at the centre of the hinged-eye / shackle leaf (eyes at e, link angle a):
///   1/k = L^3/(48 EI) - tan(a) e L^2/(8 EI) + tan(a)^2 (e^2 L/(4 EI) + L/(4 EA))
/// (derived in shackle_angle_changes_the_rate_as_derived).
double shackle_compliance(double e, double a) {
    const double t = std::tan(a);
    return std::pow(kL, 3) / (48 * kEI) - t * e * kL * kL / (8 * kEI) + t * t * (e * e * kL / (4 * kEI) + kL / (4 * kEA));
}

ModelSpec hinged_and_shackle(double e, double a) {
    ModelSpec s = leaf_on(SupportKind::hinged, SupportKind::shackle);
    s.leaves[0].left_end.eye_offset_m = e;
    s.leaves[0].right_end.eye_offset_m = e;
    s.leaves[0].right_end.shackle_angle_rad = a;
    return s;
}

}  // namespace

// Statics by hand: a leaf of span L, the fixed eye (hinged) at x = 0 and the shackle's eye at
// x = L, both eye centres at e = 25 mm above the axis, the link at a = 0.3 rad from the vertical
// (leaning to +x), the load P down at the centre. The link is a two-force member: its force on
// the leaf is S (sin a, cos a). Moments about the fixed eye (both eyes at the same height, so
// the horizontal forces have no arm): S cos a L = P L/2; vertical: V_0 = P - S cos a = P/2;
// horizontal: H_0 = -S sin a = -(P/2) tan a. Each reaction acts at its eye, e above the node,
// so its moment about the node is -e H (M_z = x F_y - y F_x).
BOOST_AUTO_TEST_CASE(hinged_eye_and_shackle_reactions_are_statics) {
    const double e = 0.025, a = 0.3, P = 10e3;
    const System sys(Model::build(hinged_and_shackle(e, a)));
    const double w = -P / sys.free_stiffness_n_per_m();  // f = k w = -P: the body pushes the leaf down by P
    const Eigen::VectorXd d = sys.leaf_displacements(Eigen::VectorXd(0), w);
    const Eigen::Vector3d r0 = end_reaction(sys, d, false), rL = end_reaction(sys, d, true);
    const double tol = 1e-9 * P;
    BOOST_TEST(std::abs(r0[0] - (-0.5 * P * std::tan(a))) < tol);
    BOOST_TEST(std::abs(r0[1] - 0.5 * P) < tol);
    BOOST_TEST(std::abs(r0[2] - (-e * r0[0])) < tol * e);
    BOOST_TEST(std::abs(rL[0] - 0.5 * P * std::tan(a)) < tol);
    BOOST_TEST(std::abs(rL[1] - 0.5 * P) < tol);
    BOOST_TEST(std::abs(rL[2] - (-e * rL[0])) < tol * e);
    // the shackle's eye moves across the link only: sin a (u - e theta) + cos a v = 0
    const Eigen::Vector3d uL = d.segment<3>(3 * sys.node_dof(0, sys.model().last_node(0)));
    BOOST_TEST(std::abs(std::sin(a) * (uL[0] - e * uL[2]) + std::cos(a) * uL[1]) < 1e-12 * std::abs(w));
    // the fixed eye does not move: u - e theta = 0, v = 0
    const Eigen::Vector3d u0 = d.segment<3>(0);
    BOOST_TEST(std::abs(u0[0] - e * u0[2]) < 1e-12 * std::abs(w));
    BOOST_TEST(u0[1] == 0.0);
}

// The rate against the shackle angle, by the unit-load method on the same leaf. With the
// reactions above, the leaf carries the axial tension N = (P/2) tan a and the bending moment
// (sagging +) M(x) = P m0(x) - (P/2) tan a e, m0 the simply supported beam's triangle
// (x/2 up to L/2): the horizontal forces act e above the axis, a constant moment. The unit
// load gives m = m0 - tan a e / 2, n = tan a / 2, so (int m0 = L^2/8, int m0^2 = L^3/48)
//   delta/P = int m^2/EI + int n^2/EA
//           = L^3/(48 EI) - tan a e L^2/(8 EI) + tan^2 a (e^2 L/(4 EI) + L/(4 EA)).
// The eye above the axis (e > 0) with the link leaning out (a > 0) stiffens the spring; a = 0
// (a vertical link) is the roller, L^3/(48 EI), whatever e. Left out by small-deflection
// theory: the link's rotation as the eye moves (docs/model-and-scenarios.md).
BOOST_AUTO_TEST_CASE(shackle_angle_changes_the_rate_as_derived) {
    for (double e : {0.0, 0.025, -0.025})
        for (double a : {-0.4, 0.0, 0.2, 0.5}) {
            BOOST_TEST_CONTEXT("e " << e << " a " << a) {
                BOOST_TEST(stiffness(hinged_and_shackle(e, a)) == 1.0 / shackle_compliance(e, a), tt::tolerance(1e-9));
            }
        }
    // and the change it makes is not small: at e = 25 mm, a = 0.5 rad, about -6 % compliance
    BOOST_TEST(shackle_compliance(0.025, 0.5) / shackle_compliance(0.025, 0.0) < 0.95);
}

// Bushings in series with the beam: a simply supported leaf on translational bushings k_y at
// both ends (k_x holds it axially), load P at the centre: each end sinks (P/2)/k_y, the centre
// by their mean, so delta/P = L^3/(48 EI) + 1/(2 k_y).
BOOST_AUTO_TEST_CASE(translational_bushings_in_series) {
    const double ky = 2e6;
    ModelSpec s = leaf_on(SupportKind::bushing, SupportKind::bushing);
    for (LeafEndSpec* end : {&s.leaves[0].left_end, &s.leaves[0].right_end}) {
        end->bushing_x_n_per_m = 5e7;
        end->bushing_y_n_per_m = ky;
    }
    BOOST_TEST(stiffness(s) == 1.0 / (std::pow(kL, 3) / (48 * kEI) + 1.0 / (2 * ky)), tt::tolerance(1e-9));
}

// A cantilever on a bushing at its root (x = L: k_y and rotation k_r), the load P at the free
// tip x = 0: the root sinks P/k_y and turns P L / k_r, so delta/P = L^3/(3 EI) + 1/k_y + L^2/k_r.
// The bushing's axial spring acts at the eye (e = 20 mm): it takes no load here (N = 0), so e
// changes nothing.
BOOST_AUTO_TEST_CASE(rotational_and_translational_bushing_cantilever) {
    const double ky = 3e6, kr = 4e5;
    ModelSpec s = leaf_on(SupportKind::free, SupportKind::bushing, 0.0);
    auto& end = s.leaves[0].right_end;
    end.eye_offset_m = 0.02;
    end.bushing_x_n_per_m = 5e7;
    end.bushing_y_n_per_m = ky;
    end.bushing_rotation_n_m_per_rad = kr;
    BOOST_TEST(stiffness(s) == 1.0 / (std::pow(kL, 3) / (3 * kEI) + 1.0 / ky + kL * kL / kr), tt::tolerance(1e-9));
}

// Bad ends are InputErrors naming the field; a stack held by nothing axially is one too.
BOOST_AUTO_TEST_CASE(bad_ends_name_the_field) {
    auto field_of = [](const ModelSpec& s) {
        try {
            System sys(Model::build(s));
        } catch (const InputError& e) {
            return e.field();
        }
        return std::string("(none)");
    };
    ModelSpec s = hinged_and_shackle(0.0, 1.7);
    BOOST_TEST(field_of(s) == "leaves[0].right_end.shackle_angle_rad");
    s = hinged_and_shackle(0.0, 0.2);
    s.leaves[0].left_end.shackle_angle_rad = 0.1;  // the hinged end
    BOOST_TEST(field_of(s) == "leaves[0].left_end.shackle_angle_rad");
    s = leaf_on(SupportKind::pinned, SupportKind::bushing);
    BOOST_TEST(field_of(s) == "leaves[0].right_end.bushing_y_n_per_m");  // a bushing of no stiffness
    s.leaves[0].left_end.bushing_y_n_per_m = 1e6;
    BOOST_TEST(field_of(s) == "leaves[0].left_end.bushing_y_n_per_m");  // a bushing stiffness on a pinned end
    s = leaf_on(SupportKind::shackle, SupportKind::shackle);  // two vertical links: rollers; the seat holds it along x
    BOOST_TEST(field_of(s) == "(none)");
    BOOST_TEST(stiffness(s) == 48 * kEI / std::pow(kL, 3), tt::tolerance(1e-9));
    s = leaf_on(SupportKind::hinged, SupportKind::hinged);
    s.symmetry = Symmetry::half;
    BOOST_TEST(field_of(s) == "leaves[0].left_support");
}

// The example scenarios/parabolic_two_leaf.toml: its liner pads close the gap that the tapers
// leave at the second leaf's tips (straight axes, stacked at the seat: the gap is half the
// thinning of the two leaves against the seat's 24 + 24 mm), and the gap opens between.
BOOST_AUTO_TEST_CASE(parabolic_example_liners_close_the_taper_gap) {
    const Scenario sc = load_scenario(std::string(STACKBEAM_SOURCE_DIR) + "/scenarios/parabolic_two_leaf.toml");
    const LeafSpec& main_leaf = sc.model.leaves[0];  // the keys as read
    BOOST_TEST((main_leaf.left_support == SupportKind::hinged && main_leaf.right_support == SupportKind::shackle));
    BOOST_TEST(main_leaf.left_end.eye_offset_m == 0.0285);
    BOOST_TEST(main_leaf.right_end.shackle_angle_rad == 0.15);
    BOOST_TEST(main_leaf.profile.thickness_m.size() == 14u);
    BOOST_TEST(main_leaf.height_m == 0.0);
    const Model m = Model::build(sc.model);
    int pads = 0;
    for (const PairSpec& p : m.candidate_pairs()) {
        const double t = leaf_thickness_m(sc.model.leaves[0], p.x_m) + leaf_thickness_m(sc.model.leaves[1], p.x_m);
        BOOST_TEST(p.initial_gap_m == 0.5 * (0.048 - t), tt::tolerance(1e-12));
        const bool pad = p.x_m < 0.13 + 1e-9 || p.x_m > 1.07 - 1e-9;
        if (pad) ++pads;
        if (pad) BOOST_TEST(std::abs(p.initial_gap_m) < 1e-12);
        if (std::abs(p.x_m - 0.3) < 1e-9) BOOST_TEST(p.initial_gap_m > 0.004);
    }
    BOOST_TEST(pads == 6);  // x = 0.1, 0.115, 0.13 (the pad to the ramp's start) and their mirror images
}
