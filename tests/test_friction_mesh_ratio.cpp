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
