// Beam inertia, first part: consistent mass matrices and the natural frequencies
// of the paper's stack with leaf mass, against independent figures.
#define BOOST_TEST_MODULE modal
#include <boost/test/unit_test.hpp>
#include <cmath>

#include "stackbeam/errors.hpp"
#include "stackbeam/fe/modal.hpp"
#include "stackbeam/model/paper_example.hpp"

namespace tt = boost::test_tools;
using namespace stackbeam;

namespace {
constexpr double kSteel = 7850.0;  // [kg/m^3]
constexpr double kMass = 20.0;     // the body [kg]
// The three leaves 0.5 x 0.05 x 0.005 m: 2.944 kg in all.
constexpr double kLeavesMass = 3 * kSteel * 0.5 * 0.05 * 0.005;

System massive(PaperCase c, double density, int elements = 20) {
    PaperExampleOptions o;
    o.elements_per_half_leaf = elements;
    ModelSpec spec = paper_example(c, o);
    for (auto& leaf : spec.leaves) leaf.density_kg_per_m3 = density;
    return System(Model::build(spec));
}
}  // namespace

BOOST_AUTO_TEST_CASE(mass_matrix_carries_the_body_and_is_symmetric) {
    // At density 0 the only mass is the body's, on w: half of it on the half model.
    const System s0 = massive(PaperCase::bonded, 0.0);
    const Eigen::MatrixXd M0 = Eigen::MatrixXd(s0.mass_reduced());
    BOOST_TEST(M0(M0.rows() - 1, M0.cols() - 1) == kMass / 2.0, tt::tolerance(1e-14));
    BOOST_TEST(M0.sum() == kMass / 2.0, tt::tolerance(1e-14));
    // With steel leaves: symmetric, positive definite (every reduced DOF carries mass).
    const Eigen::MatrixXd M = Eigen::MatrixXd(massive(PaperCase::bonded, kSteel).mass_reduced());
    BOOST_CHECK_SMALL((M - M.transpose()).norm(), 1e-15 * M.norm());
    BOOST_TEST((Eigen::LLT<Eigen::MatrixXd>(M).info() == Eigen::Success));
}

BOOST_AUTO_TEST_CASE(first_frequency_of_the_body_on_the_massive_stack) {
    // Independent figure: Rayleigh's quotient with the static deflection shape of a
    // pinned beam under a midspan load, whose modal mass is (17/35) m_beam:
    //     omega = sqrt(k / (m + 17/35 m_beam)),
    // with k the mesh's own stiffness (107,404 N/m bonded on 20 elements; 12,000
    // frictionless). The quotient is accurate to O((m_beam/m)^2 x the shape's error):
    // for m_beam/m = 0.147, 1e-5 measured: tolerance 1e-4. Against the figures
    // (70.99 and 23.66 rad/s, with the exact k = 108,000 and 12,000 N/m), the bonded
    // mesh converges as h^2 (70.230, 70.795, 70.939, 70.975 rad/s at 10..80 elements):
    // Richardson's extrapolation from 40 and 80 elements must give 70.99 to 1e-4 (the
    // figure's rounding is 7e-5).
    for (PaperCase c : {PaperCase::bonded, PaperCase::frictionless}) {
        BOOST_TEST_CONTEXT("case " << to_string(c)) {
            const System s = massive(c, kSteel);
            const ModalTie tie = c == PaperCase::bonded ? ModalTie::all : ModalTie::normal;
            const ModalResult r = modal_analysis(s, tie, 6);
            const double k = c == PaperCase::bonded ? s.tied_stiffness_n_per_m() : s.free_stiffness_n_per_m();
            const double rayleigh = std::sqrt(k / (kMass + 17.0 / 35.0 * kLeavesMass));
            BOOST_TEST_MESSAGE(to_string(c) << ": omega_1 = " << r.omega_rad_per_s[0] << " rad/s, Rayleigh "
                                            << rayleigh << ", next " << r.omega_rad_per_s[1] << ", "
                                            << r.omega_rad_per_s[2]);
            BOOST_TEST(r.omega_rad_per_s[0] == rayleigh, tt::tolerance(1e-4));
            // the figure is given to 4 digits: half a unit of the last, 2.2e-4 relative
            if (c == PaperCase::frictionless) BOOST_TEST(r.omega_rad_per_s[0] == 23.66, tt::tolerance(2.2e-4));
        }
    }
    const double w40 = modal_analysis(massive(PaperCase::bonded, kSteel, 40), ModalTie::all, 1).omega_rad_per_s[0];
    const double w80 = modal_analysis(massive(PaperCase::bonded, kSteel, 80), ModalTie::all, 1).omega_rad_per_s[0];
    BOOST_TEST(w80 + (w80 - w40) / 3.0 == 70.99, tt::tolerance(1e-4));
}

BOOST_AUTO_TEST_CASE(next_symmetric_mode_of_the_bonded_stack) {
    // The half model holds the symmetric modes; the second is a leaf bending mode with
    // the heavy body nearly still, which the issue gives as "near 1736 rad/s". It
    // converges as h^2 on the mesh (1584, 1692, 1723, 1731 rad/s at 10..80 elements per
    // half leaf, differences shrinking 3.5x, 3.9x): the observed order from 20/40/80
    // must be 2 +- 0.3, and Richardson's extrapolation from 40 and 80 elements within
    // 0.3 % of 1736 (measured 1733.6, 0.14 %).
    double w[3];
    int i = 0;
    for (int e : {20, 40, 80}) w[i++] = modal_analysis(massive(PaperCase::bonded, kSteel, e), ModalTie::all, 2).omega_rad_per_s[1];
    const double order = std::log2((w[1] - w[0]) / (w[2] - w[1]));
    const double extrapolated = w[2] + (w[2] - w[1]) / 3.0;
    BOOST_TEST_MESSAGE("bonded omega_2: " << w[0] << ", " << w[1] << ", " << w[2] << " rad/s at 20, 40, 80 elements; order "
                                          << order << ", extrapolated " << extrapolated);
    BOOST_TEST(order == 2.0, tt::tolerance(0.15));
    BOOST_TEST(extrapolated == 1736.0, tt::tolerance(3e-3));
}

BOOST_AUTO_TEST_CASE(massless_leaves_are_refused_by_name) {
    const System s = massive(PaperCase::bonded, 0.0);
    try {
        modal_analysis(s, ModalTie::all);
        BOOST_ERROR("no error");
    } catch (const InputError& e) {
        BOOST_TEST(e.field() == "leaves[].density_kg_per_m3");
    }
}
