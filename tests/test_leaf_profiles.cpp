// Leaf profiles (LeafProfile): a tapered leaf's static deflection against closed forms
// derived by integrating M/EI (the unit-load method), the measured convergence rate of
// the FE, and the exactness of the per-element integration (leaf_sections.hpp).
#define BOOST_TEST_MODULE leaf_profiles
#include <boost/test/unit_test.hpp>

#include <cmath>
#include <vector>

#include "fe/leaf_sections.hpp"
#include "single_leaf.hpp"
#include "stackbeam/errors.hpp"
#include "stackbeam/fe/system.hpp"

using namespace stackbeam;
namespace tt = boost::test_tools;

namespace {

constexpr double kE = 206e9;    // spring steel [Pa]
constexpr double kB = 0.09;     // width [m] (a 90 mm truck leaf)
constexpr double kT0 = 0.030;   // thickness at the seat [m]
constexpr double kT1 = 0.012;   // minimum thickness at the end [m]

/// One leaf from x = 0 to L of width kB (its thickness from a profile), the load at seat_x.
ModelSpec one_leaf(double L, SupportKind left, SupportKind right, double seat_x, double element_m) {
    return testing::single_leaf(L, 0.0, kB, kE, left, right, seat_x, element_m);
}

double compliance_m_per_n(const ModelSpec& s) { return 1.0 / System(Model::build(s)).free_stiffness_n_per_m(); }

/// J(l) = int_0^l x^2 / EI(x) dx for the truncated taper measured from the thin end:
/// t = t1 on [0, x1], then linear to t0 at x = l (slope s = (t0 - t1)/(l - x1)); EI = E b t^3/12.
/// On the taper put tau = t(x) = s x + c, c = t1 - s x1, x = (tau - c)/s, dx = dtau/s:
///   int x^2/tau^3 dx = s^-3 int (tau - c)^2 / tau^3 dtau = s^-3 [ln tau + 2c/tau - c^2/(2 tau^2)]_t1^t0,
/// and on the flat part int x^2 / t1^3 dx = x1^3 / (3 t1^3).
double taper_integral(double l, double x1, double t1, double t0) {
    const double s = (t0 - t1) / (l - x1), c = t1 - s * x1;
    const double F = std::log(t0 / t1) + 2.0 * c * (1.0 / t0 - 1.0 / t1) - 0.5 * c * c * (1.0 / (t0 * t0) - 1.0 / (t1 * t1));
    return 12.0 / (kE * kB) * (x1 * x1 * x1 / (3.0 * t1 * t1 * t1) + F / (s * s * s));
}

/// Relative errors of the FE compliance against `exact` on meshes of element length h / k: every
/// segment between the profile's points a multiple of h, so each mesh halves every element.
std::vector<double> errors(ModelSpec s, double h, const std::vector<int>& ks, double exact) {
    std::vector<double> e;
    for (int k : ks) {
        s.mesh.element_length_m = h / k;
        e.push_back((exact - compliance_m_per_n(s)) / exact);
    }
    return e;
}

/// The convergence rates log2(e_h / e_h/2) and their checks (see the cases for the reasoning).
void check_rates(const std::vector<double>& e) {
    for (std::size_t i = 0; i < e.size(); ++i) {
        BOOST_TEST_MESSAGE("relative error " << e[i]);
        BOOST_TEST(e[i] > 0.0);  // the conforming FE is stiffer: its compliance is below the exact one
        if (i == 0) continue;
        const double rate = std::log2(e[i - 1] / e[i]);
        BOOST_TEST_MESSAGE("rate " << rate);
        BOOST_TEST(rate > 3.7);
        BOOST_TEST(rate < 4.3);
    }
}

}  // namespace

// A cantilever of length L = 0.7 m (half a 1.4 m parabolic leaf: the seat is its root), built
// in at x = L (the seat's thickness t0), free at x = 0 with the point load P there (the eye
// end): the thickness is t1 = 12 mm over x1 = 0.1 m (the eye's flat end), then rises linearly
// to t0 = 30 mm. M(x) = P x and the unit load's m(x) = x, so the tip deflection is
//   delta = int_0^L M m / EI dx = P J(L)     (taper_integral, derived there).
// The FE (cubic Hermite elements, the section integrated exactly over each element, a node at
// the profile's kink) is conforming, so its compliance is below the exact one and, the load's
// work being the energy, its error is the energy norm of the displacement error squared:
// O(h^2)^2 = O(h^4). Measured on 4 meshes (7, 14, 28, 56 elements): rates 3.76, 3.94, 3.99 (the first
// pre-asymptotic: one element over the flat end); asserted in [3.7, 4.3].
BOOST_AUTO_TEST_CASE(tapered_cantilever_tip_deflection_converges_at_h4) {
    const double L = 0.7, x1 = 0.1;
    ModelSpec s = one_leaf(L, SupportKind::free, SupportKind::fixed, 0.0, L / 5);
    s.leaves[0].profile = LeafProfile{{0.0, x1, L}, {kT1, kT1, kT0}, {}};
    const double exact = taper_integral(L, x1, kT1, kT0);
    const std::vector<double> e = errors(s, x1, {1, 2, 4, 8}, exact);
    check_rates(e);
    // the finest mesh, 56 elements: within 1e-7 (measured 4.3e-9)
    BOOST_TEST(e.back() < 1e-7);
}

// The same taper mirrored about the centre of a simply supported leaf of L = 1.4 m (thin ends
// over x1 = 0.1 m, 30 mm at the centre), the point load P at the centre (the seat). By symmetry
// each half carries P/2 at its end: M = P x / 2, m = x / 2 on the half from the support, so
//   delta = 2 int_0^(L/2) (P x/2)(x/2) / EI dx = (P/2) J(L/2).
// Same reasoning as the cantilever; 14, 28, 56, 112 elements: rates 3.76, 3.93, 4.21:
// the last where the error (3.7e-9) nears the rounding of the condensation at the seat,
// k = K_ww - K_wr K_rr^-1 K_rw (about 1e-10 relative on this mesh).
BOOST_AUTO_TEST_CASE(tapered_simply_supported_centre_deflection_converges_at_h4) {
    const double L = 1.4, x1 = 0.1;
    ModelSpec s = one_leaf(L, SupportKind::pinned, SupportKind::pinned, 0.5 * L, L / 10);
    s.leaves[0].profile = LeafProfile{{0.0, x1, 0.5 * L, L - x1, L}, {kT1, kT1, kT0, kT1, kT1}, {}};
    const double exact = 0.5 * taper_integral(0.5 * L, x1, kT1, kT0);
    const std::vector<double> e = errors(s, x1, {1, 2, 4, 8}, exact);
    check_rates(e);
    BOOST_TEST(e.back() < 1e-7);  // measured 3.7e-9
}

// A width taper, thickness constant: the cantilever of the first case with b = b1 + (b0 - b1) x/L
// (a trapezoidal plate spring). EI = E t^3 b(x) / 12, b linear: put tau = b(x) = a + beta x,
//   int_0^L x^2 / b dx = beta^-3 [tau^2/2 - 2 a tau + a^2 ln tau]_b1^b0,  delta = P 12/(E t^3) of it.
// Same O(h^4) convergence; at 40 elements within 1e-7 (measured 7.8e-9).
BOOST_AUTO_TEST_CASE(width_taper_cantilever) {
    const double L = 0.7, b1 = 0.03, b0 = 0.09, t = 0.02;
    ModelSpec s = one_leaf(L, SupportKind::free, SupportKind::fixed, 0.0, L / 40);
    s.leaves[0].width_m = 0.0;
    s.leaves[0].height_m = t;
    s.leaves[0].profile = LeafProfile{{0.0, L}, {}, {b1, b0}};
    const double a = b1, beta = (b0 - b1) / L;
    auto F = [&](double tau) { return tau * tau / 2.0 - 2.0 * a * tau + a * a * std::log(tau); };
    const double exact = 12.0 / (kE * t * t * t) * (F(b0) - F(b1)) / (beta * beta * beta);
    const double e = (exact - compliance_m_per_n(s)) / exact;
    BOOST_TEST_MESSAGE("width taper, 40 elements: relative error " << e);
    BOOST_TEST(e > 0.0);
    BOOST_TEST(e < 1e-7);
}

// A profile of constant section is the constant leaf: the integration is exact, so the
// stiffness and the mass agree to rounding (1e-12) with height_m / width_m (whose code path
// is unchanged). The profile's extra node at 0.3 m is on the constant leaf's grid too (0.05 m).
BOOST_AUTO_TEST_CASE(constant_profile_is_the_constant_leaf) {
    ModelSpec c = one_leaf(1.0, SupportKind::pinned, SupportKind::pinned, 0.5, 0.05);
    c.leaves[0].height_m = 0.01;
    ModelSpec p = c;
    p.leaves[0].height_m = 0.0;
    p.leaves[0].width_m = 0.0;
    p.leaves[0].profile = LeafProfile{{0.0, 0.3, 1.0}, {0.01, 0.01, 0.01}, {kB, kB, kB}};
    const double kc = 1.0 / compliance_m_per_n(c), kp = 1.0 / compliance_m_per_n(p);
    BOOST_TEST(std::abs(kp - kc) / kc < 1e-12);
    // and the consistent mass (density > 0) is the constant leaf's, entry by entry
    c.leaves[0].density_kg_per_m3 = p.leaves[0].density_kg_per_m3 = 7850.0;
    const Eigen::SparseMatrix<double> mc = System(Model::build(c)).mass_reduced(), mp = System(Model::build(p)).mass_reduced();
    BOOST_TEST((mc.rows() == mp.rows() && mc.cols() == mp.cols()));
    BOOST_TEST(Eigen::MatrixXd(mp - mc).cwiseAbs().maxCoeff() < 1e-12 * Eigen::MatrixXd(mc).cwiseAbs().maxCoeff());
}

// The element matrices of leaf_sections.hpp against hand integrals over one element with t and
// b linear (t1 -> t2, b1 -> b2, length h): the total mass int rho b t dx is the rigid vertical
// translation's (v1 = v2 = 1) and the axial one's, h (2 b1 t1 + b1 t2 + b2 t1 + 2 b2 t2) / 6 (exact:
// Simpson on a quadratic); the axial stiffness is int E b t dx / h^2. Both to 1e-13.
BOOST_AUTO_TEST_CASE(element_integrals_are_exact) {
    LeafSpec l;
    l.length_m = 0.5;
    l.youngs_modulus_pa = kE;
    l.density_kg_per_m3 = 7850.0;
    l.profile = LeafProfile{{0.0, 0.5}, {0.03, 0.01}, {0.1, 0.06}};
    const double x1 = 0.1, x2 = 0.35, h = x2 - x1;
    const double t1 = leaf_thickness_m(l, x1), t2 = leaf_thickness_m(l, x2), b1 = leaf_width_m(l, x1), b2 = leaf_width_m(l, x2);
    const double area_integral = h * (2 * b1 * t1 + b1 * t2 + b2 * t1 + 2 * b2 * t2) / 6.0;  // int b t dx
    const detail::ElementMatrix m = detail::profiled_mass(l, x1, x2);
    const double vertical = m[1][1] + m[1][4] + m[4][1] + m[4][4];
    const double axial = m[0][0] + m[0][3] + m[3][0] + m[3][3];
    BOOST_TEST(std::abs(vertical - l.density_kg_per_m3 * area_integral) < 1e-13 * vertical);
    BOOST_TEST(std::abs(axial - l.density_kg_per_m3 * area_integral) < 1e-13 * axial);
    const detail::ElementMatrix k = detail::profiled_stiffness(l, x1, x2);
    const double EA_over_h = kE * area_integral / (h * h);
    BOOST_TEST(std::abs(k[0][0] - EA_over_h) < 1e-13 * EA_over_h);
    BOOST_TEST(std::abs(k[0][3] + EA_over_h) < 1e-13 * EA_over_h);
}

// The contact pairs' moment arms follow the local thickness. Two bonded leaves of complementary
// linear tapers, t_A = t1 -> t2 and t_B = t2 -> t1 along the span: on straight axes at the
// distance D = (t1 + t2)/2 (stacked at the centre) they touch everywhere (t_A + t_B = 2D), and
// the bonded pair is one composite section. With t_A = D + a, t_B = D - a its EI about the
// composite axis is E b [(t_A^3 + t_B^3)/12 + t_A t_B D/2] (the two leaves and their parallel-axis
// term, EA_A EA_B D^2/(EA_A + EA_B)) = E b [(2D^3 + 6 D a^2)/12 + (D^2 - a^2) D/2] = E b (2D)^3/12:
// constant, so the pair on two rollers with the load at the centre has k = 48 E b (2D)^3/(12 L^3).
// The bonded FE ties the leaves at the nodes only, so it converges as h^2 to that (as the
// constant stack, test_stiffness.cpp): the error ratio between 20, 40 and 80 elements is 4
// (measured 3.97, 3.99; asserted +- 2.5 %) and the Richardson value (4 k_h/2 - k_h)/3 is within 1e-4
// (the h^4 remainder). An arm from any fixed thickness misses it by percents.
BOOST_AUTO_TEST_CASE(complementary_bonded_tapers_bend_as_one_prismatic_section) {
    const double L = 1.4, t1 = 0.012, t2 = 0.028, D = 0.5 * (t1 + t2);
    ModelSpec s = one_leaf(L, SupportKind::pinned, SupportKind::pinned, 0.5 * L, L / 20);
    s.leaves[0].profile = LeafProfile{{0.0, L}, {t1, t2}, {}};
    s.leaves.push_back(s.leaves[0]);
    s.leaves[1].profile.thickness_m = {t2, t1};
    InterfaceSpec f;
    f.law = InterfaceLaw::bonded;
    s.interfaces = {f};
    const double k_exact = 48.0 * kE * kB * std::pow(2.0 * D, 3) / (12.0 * std::pow(L, 3));
    std::vector<double> k;
    for (int n : {20, 40, 80}) {
        s.mesh.element_length_m = L / n;
        const Model m = Model::build(s);
        for (const PairSpec& p : m.candidate_pairs()) BOOST_TEST(p.initial_gap_m == 0.0, tt::tolerance(1e-15));
        k.push_back(System(m).tied_stiffness_n_per_m());
        BOOST_TEST_MESSAGE("complementary bonded tapers, " << n << " elements: k / k_exact - 1 = " << k.back() / k_exact - 1.0);
        BOOST_TEST(k.back() < k_exact);  // tied at the nodes only: softer than the composite
    }
    BOOST_TEST_MESSAGE("error ratios " << (k_exact - k[0]) / (k_exact - k[1]) << " " << (k_exact - k[1]) / (k_exact - k[2]));
    BOOST_TEST((k_exact - k[0]) / (k_exact - k[1]) == 4.0, tt::tolerance(0.025));
    BOOST_TEST((k_exact - k[1]) / (k_exact - k[2]) == 4.0, tt::tolerance(0.025));
    BOOST_TEST((4.0 * k[2] - k[1]) / 3.0 == k_exact, tt::tolerance(1e-4));
}

// Straight axes: two identical tapered leaves stacked at the centre (thickest) open a gap
// towards the ends of (t_centre - t(x)) (each surface recedes by half the thinning).
BOOST_AUTO_TEST_CASE(taper_opens_the_gap_away_from_the_seat) {
    const double L = 1.4;
    ModelSpec s = one_leaf(L, SupportKind::pinned, SupportKind::pinned, 0.5 * L, L / 14);
    s.leaves[0].profile = LeafProfile{{0.0, 0.5 * L, L}, {kT1, kT0, kT1}, {}};
    s.leaves.push_back(s.leaves[0]);
    s.leaves[1].left_support = s.leaves[1].right_support = SupportKind::free;
    s.interfaces = {InterfaceSpec{}};
    s.interfaces[0].initial_gap_m = 0.001;
    const Model m = Model::build(s);
    for (const PairSpec& p : m.candidate_pairs()) {
        const double t = leaf_thickness_m(s.leaves[0], p.x_m);
        BOOST_TEST(p.initial_gap_m == 0.001 + (kT0 - t), tt::tolerance(1e-12));
    }
    // thicker away from the seat than at it: the leaves would overlap (an InputError)
    s.leaves[1].profile.thickness_m = {0.04, kT1, 0.04};  // at the ends 4 mm more than at the seat
    BOOST_CHECK_THROW(Model::build(s), InputError);
}

// The friction-mesh ratio takes the largest local arm of the interface: two tapered leaves
// (12 -> 30 -> 12 mm), mu = 0.5, pairs 50 mm apart: kappa = mu (t + t)/(2 h) at the seat,
// 0.5 x 0.030 / 0.05 = 0.3 (to rounding).
BOOST_AUTO_TEST_CASE(friction_mesh_ratio_takes_the_local_thickness) {
    const double L = 1.4;
    ModelSpec s = one_leaf(L, SupportKind::pinned, SupportKind::pinned, 0.5 * L, 0.05);
    s.leaves[0].profile = LeafProfile{{0.0, 0.5 * L, L}, {kT1, kT0, kT1}, {}};
    s.leaves.push_back(s.leaves[0]);
    s.leaves[1].left_support = s.leaves[1].right_support = SupportKind::free;
    s.interfaces = {InterfaceSpec{}};
    s.interfaces[0].friction_coefficient = 0.5;
    const FrictionMeshRatio r = friction_mesh_ratio(Model::build(s));
    BOOST_TEST(r.ratio == 0.5 * kT0 / 0.05, tt::tolerance(1e-12));
}

// The half model of a mirrored profile is the full one (the symmetric taper of the simply
// supported case; to 1e-9: the same elements, the same equations); an unmirrored one is refused.
BOOST_AUTO_TEST_CASE(half_model_of_a_mirrored_profile) {
    const double L = 1.4;
    ModelSpec s = one_leaf(L, SupportKind::pinned, SupportKind::pinned, 0.5 * L, L / 28);
    s.leaves[0].profile = LeafProfile{{0.0, 0.1, 0.5 * L, L - 0.1, L}, {kT1, kT1, kT0, kT1, kT1}, {}};
    ModelSpec half = s;
    half.symmetry = Symmetry::half;
    BOOST_TEST(1.0 / compliance_m_per_n(half) == 1.0 / compliance_m_per_n(s), tt::tolerance(1e-9));
    half.leaves[0].profile.thickness_m[1] = 0.013;
    BOOST_CHECK_THROW(Model::build(half), InputError);
}

// Bad profiles are InputErrors naming the field.
BOOST_AUTO_TEST_CASE(bad_profiles_name_the_field) {
    auto field_of = [](ModelSpec s) {
        try {
            Model::build(s);
        } catch (const InputError& e) {
            return e.field();
        }
        return std::string("(none)");
    };
    ModelSpec s = one_leaf(1.0, SupportKind::pinned, SupportKind::pinned, 0.5, 0.1);
    s.leaves[0].profile = LeafProfile{{0.0, 0.5, 1.0}, {0.01, -0.01, 0.01}, {}};
    BOOST_TEST(field_of(s) == "leaves[0].profile.thickness_m[1]");
    s.leaves[0].profile = LeafProfile{{0.0, 0.5, 0.4, 1.0}, {0.01, 0.01, 0.01, 0.01}, {}};
    BOOST_TEST(field_of(s) == "leaves[0].profile.x_m[2]");
    s.leaves[0].profile = LeafProfile{{0.0, 0.5, 0.9}, {0.01, 0.01, 0.01}, {}};
    BOOST_TEST(field_of(s) == "leaves[0].profile.x_m[2]");
    s.leaves[0].profile = LeafProfile{{0.0, 1.0}, {0.01, 0.01, 0.01}, {}};
    BOOST_TEST(field_of(s) == "leaves[0].profile.thickness_m");
    s.leaves[0].profile = LeafProfile{{0.0, 1.0}, {0.01, 0.01}, {}};
    s.leaves[0].height_m = 0.01;
    BOOST_TEST(field_of(s) == "leaves[0].height_m");
}
