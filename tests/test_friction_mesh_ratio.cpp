// The friction-mesh ratio kappa = mu (t_i + t_i+1) / (2 h) of a frictional stack
// (model.hpp): how strongly the friction forces move neighbouring pairs' normal forces,
// the gain of the exact solvers' fixed point on the friction limits. Checked against
// the hand-computed value from the spec (pure geometry: the node spacing is the
// mesh's element length, so the only error is the round-off of the grid's x), and the
// advice it adds to a failed step's error message.
#define BOOST_TEST_MODULE friction_mesh_ratio
#include <boost/test/unit_test.hpp>
#include <string>

#include "stackbeam/time/closed_form_stepper.hpp"
#include "stackbeam/errors.hpp"
#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/time/simulation.hpp"
#include "stackbeam/fe/system.hpp"

namespace tt = boost::test_tools;
using namespace stackbeam;

namespace {
// the grid's x come from sums of element lengths: a few ulps of 0.5 m
constexpr double kRoundOff = 1e-12;

ModelSpec paper(PaperCase c, int elements_per_half_leaf) {
    PaperExampleOptions o;
    o.elements_per_half_leaf = elements_per_half_leaf;
    return paper_example(c, o);
}
}  // namespace

BOOST_AUTO_TEST_CASE(paper_example_ratio_is_mu_thickness_over_element_length) {
    // 5 mm leaves, mu = 0.5, half leaf 0.25 m: h = 0.25 / n, kappa = 0.5 * 0.005 / h
    for (const int n : {20, 100, 400}) {
        const Model m = Model::build(paper(PaperCase::friction, n));
        const FrictionMeshRatio r = friction_mesh_ratio(m);
        const double h = 0.25 / n;
        BOOST_TEST_CONTEXT("elements per half leaf " << n) {
            BOOST_TEST(r.ratio == 0.5 * 0.005 / h, tt::tolerance(kRoundOff));
            BOOST_TEST(r.pair_spacing_m == h, tt::tolerance(kRoundOff));
            BOOST_TEST(r.spacing_for_one_m == 0.5 * 0.005, tt::tolerance(kRoundOff));
            BOOST_TEST(r.interface_index >= 0);
        }
    }
}

BOOST_AUTO_TEST_CASE(no_friction_no_ratio) {
    for (const PaperCase c : {PaperCase::bonded, PaperCase::frictionless}) {
        const Model m = Model::build(paper(c, 400));
        const FrictionMeshRatio r = friction_mesh_ratio(m);
        BOOST_TEST(r.ratio == 0.0);
        BOOST_TEST(r.interface_index == -1);
        BOOST_TEST(friction_mesh_advice(m).empty());
    }
}

BOOST_AUTO_TEST_CASE(largest_interface_with_unequal_thicknesses) {
    // leaves 5, 8, 5 mm; mu 0.3 above the middle leaf, 0.5 below it; h = 12.5 mm:
    //   interface 0: 0.3 * (0.005 + 0.008) / 2 / 0.0125 = 0.156
    //   interface 1: 0.5 * (0.008 + 0.005) / 2 / 0.0125 = 0.26   (the largest)
    ModelSpec s = paper(PaperCase::friction, 20);
    s.leaves[1].height_m = 0.008;
    s.interfaces[0].friction_coefficient = 0.3;
    s.interfaces[1].friction_coefficient = 0.5;
    const FrictionMeshRatio r = friction_mesh_ratio(Model::build(s));
    BOOST_TEST(r.interface_index == 1);
    BOOST_TEST(r.ratio == 0.26, tt::tolerance(kRoundOff));
    BOOST_TEST(r.spacing_for_one_m == 0.5 * 0.0065, tt::tolerance(kRoundOff));
}

BOOST_AUTO_TEST_CASE(advice_only_at_one_or_more) {
    BOOST_TEST(friction_mesh_advice(Model::build(paper(PaperCase::friction, 20))).empty());   // 0.2
    BOOST_TEST(friction_mesh_advice(Model::build(paper(PaperCase::friction, 80))).empty());   // 0.8
    const std::string a = friction_mesh_advice(Model::build(paper(PaperCase::friction, 200)));  // 2
    BOOST_TEST(a.find("friction-mesh ratio") != std::string::npos);
    BOOST_TEST(a.find(" is 2 on interface 0") != std::string::npos);
    BOOST_TEST(a.find("0.0025 m apart") != std::string::npos);  // mu t = 2.5 mm
    BOOST_TEST(a.find("mu below 0.25") != std::string::npos);   // 0.5 / 2
}

BOOST_AUTO_TEST_CASE(failed_step_names_the_ratio) {
    // The paper's E = I iteration held to one iteration cannot settle the first step:
    // the step's SolverError carries the advice on a mesh with kappa = 2 only.
    for (const int n : {20, 200}) {
        const System sys(Model::build(paper(PaperCase::friction, n)));
        SimulationOptions o;
        o.solver.kind = SolverKind::paper;
        o.solver.max_iterations = 1;
        ClosedFormStepper st(sys, o);
        std::string what;
        try {
            st.advance();
        } catch (const SolverError& e) {
            what = e.what();
        }
        BOOST_TEST_CONTEXT("elements per half leaf " << n << ": " << what) {
            BOOST_TEST(!what.empty());
            BOOST_TEST((what.find("friction-mesh ratio") != std::string::npos) == (n == 200));
        }
    }
}

// ---- the elastic interface (issue 18): kappa = mu (t_i + t_i+1) / (2 max(h, l)) ---------------

namespace {
ModelSpec elastic_paper(int elements_per_half_leaf, double mu) {
    ModelSpec s = paper(PaperCase::friction, elements_per_half_leaf);
    for (auto& f : s.interfaces) {
        f.contact = InterfaceContact::elastic;
        f.friction_coefficient = mu;
    }
    return s;
}
// The paper's leaves (5 mm, b = 50 mm, E = 2e10 Pa, nu = 0.3) by hand:
//   k_n = E / (1 - nu^2) / t = 2e10 / 0.91 / 0.005 = 4.3956044e12 Pa/m,
//   EI = 2e10 * 0.05 * 0.005^3 / 12 = 10.416667 N m^2, EI_eq = EI / 2 = 5.2083333 N m^2,
//   l = (4 EI_eq / (k_n b))^(1/4) = (20.833333 / 2.1978022e11)^(1/4) = 3.1202726e-3 m.
constexpr double kDecayLength = 3.1202726e-3;
constexpr double kDecayDigits = 1e-7;  // 8 digits written above
}  // namespace

BOOST_AUTO_TEST_CASE(elastic_ratio_uses_the_longer_of_spacing_and_decay_length) {
    // coarse: 20 elements, h = 12.5 mm > l: kappa = 0.5 * 0.005 / 0.0125 = 0.2, as rigid
    const FrictionMeshRatio coarse = friction_mesh_ratio(Model::build(elastic_paper(20, 0.5)));
    BOOST_TEST(coarse.elastic);
    BOOST_TEST(coarse.ratio == 0.2, tt::tolerance(kRoundOff));
    BOOST_TEST(coarse.decay_length_m == kDecayLength, tt::tolerance(kDecayDigits));
    // fine: 400 elements, h = 0.625 mm < l: kappa = 0.5 * 0.005 / l = 0.80121 (rigid: 4)
    const FrictionMeshRatio fine = friction_mesh_ratio(Model::build(elastic_paper(400, 0.5)));
    BOOST_TEST(fine.elastic);
    BOOST_TEST(fine.pair_spacing_m == 0.25 / 400, tt::tolerance(kRoundOff));
    BOOST_TEST(fine.ratio == 0.5 * 0.005 / kDecayLength, tt::tolerance(kDecayDigits));
    BOOST_TEST(fine.spacing_for_one_m == 0.5 * 0.005, tt::tolerance(kRoundOff));
    // rigid: no decay length
    const FrictionMeshRatio rigid = friction_mesh_ratio(Model::build(paper(PaperCase::friction, 400)));
    BOOST_TEST(!rigid.elastic);
    BOOST_TEST(rigid.decay_length_m == 0.0);
}

BOOST_AUTO_TEST_CASE(advice_names_the_elastic_law_and_warns_at_high_mu) {
    // rigid, kappa = 2: the advice offers the elastic law
    const std::string rigid = friction_mesh_advice(Model::build(paper(PaperCase::friction, 200)));
    BOOST_TEST(rigid.find("interfaces[0].contact = \"elastic\"") != std::string::npos);
    // elastic, mu = 0.8 (>= 0.7): the warning, on a coarse mesh too
    for (const int n : {20, 400}) {
        const std::string warn = friction_mesh_advice(Model::build(elastic_paper(n, 0.8)));
        BOOST_TEST_CONTEXT(n << " elements: " << warn) {
            BOOST_TEST(warn.find("elastic law with mu = 0.8") != std::string::npos);
            BOOST_TEST(warn.find("1.43 mu") != std::string::npos);
        }
    }
    // elastic, mu = 0.3 on the fine mesh (kappa = 0.3 * 0.005 / l = 0.48): nothing to say
    BOOST_TEST(friction_mesh_advice(Model::build(elastic_paper(400, 0.3))).empty());
}
