// One contact solve over both forms (issue 42, item 1; docs/decisions/064-one-contact-solve.md):
// StepContactSolver gives the same readouts (forces, displacements, relative positions, strain
// energy, SolveResult) whichever form the operator took, so no stepper asks which path runs.
#define BOOST_TEST_MODULE one_solve
#include <boost/test/unit_test.hpp>
#include <cmath>

#include "stackbeam/contact/step.hpp"
#include "stackbeam/errors.hpp"
#include "stackbeam/fe/system.hpp"
#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/time/closed_form_stepper.hpp"
#include "time/static_stages.hpp"

using namespace stackbeam;

namespace stackbeam {
std::ostream& operator<<(std::ostream& os, ContactPath p) { return os << to_string(p); }
}  // namespace stackbeam

namespace {

// Agreement between the forms: both solve the same linear system per set of modes (a dense LU
// of W_SS against a sparse LU of the saddle-point system) and reach the same modes, so they
// differ by round-off amplified by cond(W) ~ 1e5 on the paper example: ~1e-11 relative
// (test_sparse_path.cpp measures at most 6e-11 on the forces); 1e-9 keeps a margin and still
// catches a wrong formula or a different mode (>= 1e-6).
constexpr double kRel = 1e-9;

double rel_diff(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    return (a - b).lpNorm<Eigen::Infinity>() / std::max(1e-300, b.lpNorm<Eigen::Infinity>());
}

ClosedFormStepper stepper(const System& sys, ContactPath path) {
    SimulationOptions so;
    so.dt_s = 1e-3;
    so.t_end_s = 0.1;
    so.contact_path = path;
    return ClosedFormStepper(sys, so);
}

}  // namespace

// The closed-form stepper on both paths: the displacements (on the dense path made by the
// operator from p and w, System::reduced_displacements), the relative positions and the strain
// energy agree at every 10th step of 100.
BOOST_AUTO_TEST_CASE(closed_form_readouts_agree_on_both_paths) {
    for (PaperCase pc : {PaperCase::bonded, PaperCase::friction}) {
        const System sys(Model::build(paper_example(pc)));
        ClosedFormStepper dense = stepper(sys, ContactPath::dense), sparse = stepper(sys, ContactPath::sparse);
        BOOST_TEST(dense.contact_path() == ContactPath::dense);
        BOOST_TEST(sparse.contact_path() == ContactPath::sparse);
        BOOST_TEST(rel_diff(dense.reduced_displacements(), sparse.reduced_displacements()) < kRel);
        for (int i = 1; i <= 100; ++i) {
            dense.advance();
            sparse.advance();
            if (i % 10) continue;
            BOOST_TEST(rel_diff(dense.reduced_displacements(), sparse.reduced_displacements()) < kRel);
            // relative positions are differences of displacements (a bonded pair's is 0 up to
            // round-off): their agreement is measured on the displacements' scale
            BOOST_TEST((dense.relative_positions() - sparse.relative_positions()).lpNorm<Eigen::Infinity>() <
                       kRel * sparse.reduced_displacements().lpNorm<Eigen::Infinity>());
            BOOST_TEST(std::abs(dense.current().strain_energy_j - sparse.current().strain_energy_j) <
                       kRel * sparse.current().strain_energy_j);
            BOOST_TEST(dense.contact_solver().path() == ContactPath::dense);
            BOOST_TEST(sparse.contact_solver().path() == ContactPath::sparse);
        }
    }
}

// A balance that must close on the dense path: the strain energy its form gives in closed form,
// (p^T C' p + k w^2) / 2, equals z^T K z / 2 of the displacements the operator makes from p and w
// (rigid interfaces: no layer energy). Both are round-off of the same number: cond(K_rr) ~ 1e7
// at 20 elements per half leaf gives ~1e-9 relative at worst; 1e-8.
BOOST_AUTO_TEST_CASE(dense_displacements_close_the_strain_energy) {
    const System sys(Model::build(paper_example(PaperCase::friction)));
    ClosedFormStepper st = stepper(sys, ContactPath::dense);
    const double f = sys.model().whole_spring_factor();
    for (int i = 0; i < 50; ++i) st.advance();
    const Eigen::VectorXd z = st.reduced_displacements();
    BOOST_TEST(z.size() == sys.num_reduced_dofs());
    const double u_z = 0.5 * f * z.dot(sys.stiffness_reduced() * z);
    BOOST_TEST(std::abs(st.current().strain_energy_j - u_z) < 1e-8 * u_z);
}

// The one solve call on a problem built by hand (R held at w: detail::held_body_system): the same
// StepProblem on a dense and on a sparse operator gives the same forces, displacements, relative
// positions and a SolveResult whose sparse-only routes count 0 on the dense form.
BOOST_AUTO_TEST_CASE(one_call_over_a_dense_and_a_sparse_operator) {
    const System sys(Model::build(paper_example(PaperCase::bonded)));
    const StepSystem held = detail::held_body_system(sys);
    SolverOptions o;
    Eigen::VectorXd p[2], z[2], rel[2];
    const ContactPath paths[2] = {ContactPath::dense, ContactPath::sparse};
    for (int k = 0; k < 2; ++k) {
        StepProblem pr;
        pr.op = std::make_shared<const ContactOperator>(held, paths[k], o.kind);
        pr.pairs = sys.pairs();
        pr.u = Eigen::VectorXd::Constant(1, -0.02);  // R held 20 mm down [m]
        pr.d = sys.initial_offsets_m();
        StepContactSolver solver(o);
        p[k] = Eigen::VectorXd::Zero(sys.num_components());
        const SolveResult r = solver.solve(pr, p[k], z[k]);
        BOOST_TEST(r.converged);
        BOOST_TEST(solver.path() == paths[k]);
        rel[k] = solver.relative_positions(p[k]);
        if (k == 0) BOOST_TEST(r.updates + r.newton_iterations + r.smoothing_iterations == 0);
        BOOST_TEST(z[k].size() == sys.num_reduced_dofs() - 1);  // z_r: R's w is given
    }
    BOOST_TEST(rel_diff(p[0], p[1]) < kRel);
    BOOST_TEST(rel_diff(z[0], z[1]) < kRel);
    BOOST_TEST((rel[0] - rel[1]).lpNorm<Eigen::Infinity>() < kRel * z[1].lpNorm<Eigen::Infinity>());  // bonded: ~0
}

// The operator's forms: a dense form alone (the event driver's W) is taken whatever the request;
// neither form is an InputError naming the system; options out of range are refused by the solver.
BOOST_AUTO_TEST_CASE(operator_forms_and_bad_input) {
    StepSystem only_dense;
    only_dense.rows = 2;
    only_dense.dense = [] {
        DenseStepForm f;
        f.W = Eigen::Matrix2d{{2e-6, 0.0}, {0.0, 1e-6}};  // [m/N]; Q empty: q = u - d
        return f;
    };
    const auto op = std::make_shared<const ContactOperator>(only_dense, ContactPath::sparse, SolverKind::exact);
    BOOST_TEST(op->path() == ContactPath::dense);
    StepProblem pr;
    pr.op = op;
    ContactPair bonded;
    bonded.kind = PairKind::bonded;
    bonded.row_n = 0;
    bonded.row_t = 1;
    pr.pairs = {bonded};
    pr.u = Eigen::Vector2d(1e-3, -2e-3);  // s = W p + u - d [m]
    pr.d = Eigen::Vector2d::Zero();
    StepContactSolver solver{SolverOptions{}};
    Eigen::VectorXd p = Eigen::VectorXd::Zero(2);
    BOOST_TEST(solver.solve(pr, p).converged);
    // bonded: s = 0, so p = -W^-1 u exactly (to round-off)
    BOOST_TEST(std::abs(p[0] + 1e-3 / 2e-6) < 1e-9 * 500.0);
    BOOST_TEST(std::abs(p[1] - 2e-3 / 1e-6) < 1e-9 * 2000.0);
    BOOST_TEST(solver.displacements().size() == 0);  // no degrees of freedom beyond the rows
    BOOST_CHECK_THROW(solver.strain_energy_j(p, solver.relative_positions(p)), std::logic_error);
    StepSystem none;
    none.rows = 2;
    try {
        ContactOperator bad(none, ContactPath::automatic, SolverKind::exact);
        BOOST_FAIL("no form accepted");
    } catch (const InputError& e) {
        BOOST_TEST(std::string(e.what()).find("system") != std::string::npos);
    }
    SolverOptions o;
    o.tresca_anderson_depth = 51;
    try {
        StepContactSolver s(o);
        BOOST_FAIL("tresca_anderson_depth 51 accepted");
    } catch (const InputError& e) {
        BOOST_TEST(std::string(e.what()).find("solver.tresca_anderson_depth") != std::string::npos);
        BOOST_TEST(std::string(e.what()).find("51") != std::string::npos);
    }
}
