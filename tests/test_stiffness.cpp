// Static stiffness of the paper example at the rigid body, against
// docs/method.md and beam theory.
#define BOOST_TEST_MODULE stiffness
#include <boost/test/unit_test.hpp>
#include <cmath>

#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/fe/system.hpp"

namespace tt = boost::test_tools;
using namespace stackbeam;

namespace {
double bonded_stiffness(int elements, Symmetry sym = Symmetry::half) {
    PaperExampleOptions o;
    o.elements_per_half_leaf = elements;
    o.symmetry = sym;
    return System(Model::build(paper_example(PaperCase::bonded, o))).tied_stiffness_n_per_m();
}
}  // namespace

BOOST_AUTO_TEST_CASE(bonded_stiffness_matches_reference_table) {
    // The table in reference-example.md is rounded to 1 N/m: tolerance 0.6 N/m absolute
    // (6e-6 relative, far below the 0.03 %..8 % discretisation errors it documents).
    const int elements[] = {5, 10, 20, 40, 80};
    const double table[] = {99233, 105659, 107404, 107850, 107963};
    for (int i = 0; i < 5; ++i) {
        BOOST_TEST_CONTEXT("elements per half leaf " << elements[i]) {
            BOOST_CHECK_SMALL(bonded_stiffness(elements[i]) - table[i], 0.6);
        }
    }
}

BOOST_AUTO_TEST_CASE(bonded_stiffness_converges_as_h_squared_to_the_monolithic_beam) {
    // Tying the leaves only at the nodes softens the stack by O(h^2): each halving of
    // the element must cut the error to 108,000 N/m (48EI/L^3 of the 0.015 m beam) by 4.
    // The ratio approaches 4 from a few percent away on these meshes: tolerance 5 %.
    const double k_exact = paper_analytic(PaperCase::bonded).stiffness_n_per_m;
    BOOST_TEST(k_exact == 108000.0, tt::tolerance(1e-12));
    double prev = k_exact - bonded_stiffness(10);
    for (int n : {20, 40, 80}) {
        const double err = k_exact - bonded_stiffness(n);
        BOOST_TEST_CONTEXT("elements " << n) {
            BOOST_TEST(err > 0.0);                          // always softer than the monolithic beam
            BOOST_TEST(prev / err == 4.0, tt::tolerance(0.05));
        }
        prev = err;
    }
    // Richardson extrapolation of 40 and 80 elements removes the h^2 term: what is left
    // is O(h^4) ~ (0.14 %)^2 -> well within 0.01 %.
    const double k40 = bonded_stiffness(40), k80 = bonded_stiffness(80);
    BOOST_TEST((4.0 * k80 - k40) / 3.0 == k_exact, tt::tolerance(1e-4));
}

BOOST_AUTO_TEST_CASE(frictionless_stiffness_is_exact_on_any_mesh) {
    // Three leaves side by side: 48EI/L^3 of a 0.15 x 0.005 m beam = 12,000 N/m. Cubic
    // elements are exact for point loads, so only round-off remains; the condensation
    // k = K_ww - K_wr K_rr^-1 K_rw cancels terms ~ (elements)^3 times larger than k:
    // eps * 80^3 * 24 ~ 2.5e-9 on the finest mesh. Tolerance 1e-8.
    const double k_exact = paper_analytic(PaperCase::frictionless).stiffness_n_per_m;
    BOOST_TEST(k_exact == 12000.0, tt::tolerance(1e-12));
    for (int n : {1, 3, 5, 20, 80}) {
        PaperExampleOptions o;
        o.elements_per_half_leaf = n;
        const System s(Model::build(paper_example(PaperCase::frictionless, o)));
        BOOST_TEST_CONTEXT("elements " << n) { BOOST_TEST(s.free_stiffness_n_per_m() == k_exact, tt::tolerance(1e-8)); }
    }
}

BOOST_AUTO_TEST_CASE(full_model_equals_half_model) {
    // The full model with 2N elements per leaf is the half model mirrored: same
    // stiffness up to round-off of the condensation (cond(C') ~ 1e5): tolerance 1e-9.
    for (int n : {5, 20}) {
        BOOST_TEST(bonded_stiffness(n, Symmetry::full) == bonded_stiffness(n, Symmetry::half), tt::tolerance(1e-9));
    }
}

BOOST_AUTO_TEST_CASE(single_leaf_point_load_stiffness) {
    // One pinned-pinned leaf with the mass off centre at x = a: k = 3 E I L / (a^2 b^2)
    // (beam tables); a cantilever with the mass at its tip: k = 3 E I / L^3. Exact for
    // cubic elements: tolerance 1e-10.
    LeafSpec leaf{0.5, 0.0, 0.005, 0.05, 2e10, 0.0, SupportKind::pinned, SupportKind::pinned};
    const double I = 0.05 * std::pow(0.005, 3) / 12.0;
    ModelSpec s;
    s.leaves = {leaf};
    s.rigid_body.mass_kg = 1.0;
    s.rigid_body.x_m = 0.15;
    s.mesh.element_length_m = 0.05;
    const double a = 0.15, b = 0.35;
    BOOST_TEST(System(Model::build(s)).free_stiffness_n_per_m() == 3 * 2e10 * I * 0.5 / (a * a * b * b),
               tt::tolerance(1e-10));
    s.leaves[0].left_support = SupportKind::fixed;
    s.leaves[0].right_support = SupportKind::free;
    s.rigid_body.x_m = 0.5;
    BOOST_TEST(System(Model::build(s)).free_stiffness_n_per_m() == 3 * 2e10 * I / std::pow(0.5, 3), tt::tolerance(1e-10));
}
