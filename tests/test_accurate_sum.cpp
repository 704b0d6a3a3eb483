// Sums, sparse products and quadratic forms in twice the working precision (lib/time/accurate_sum.hpp)
// and what they are for: newmark's energy balance on a fine mesh closing to round-off
// (docs/decisions/065-soak-round-off-and-tolerances.md).
#define BOOST_TEST_MODULE accurate_sum
#include <boost/test/unit_test.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "stackbeam/io/scenario.hpp"
#include "stackbeam/time/stepper.hpp"
#include "time/accurate_sum.hpp"

using namespace stackbeam;

// The error-free transformations are exact: a + b = s + e and a b = p + e, checked where the
// exact value is known (powers of two and numbers whose products fit 106 bits).
BOOST_AUTO_TEST_CASE(two_sum_and_two_product_are_exact) {
    double s, e;
    detail::two_sum(1.0, std::ldexp(1.0, -60), s, e);
    BOOST_TEST(s == 1.0);
    BOOST_TEST(e == std::ldexp(1.0, -60));
    // (1 + 2^-30)^2 = 1 + 2^-29 + 2^-60: the product rounds to 1 + 2^-29, the error is 2^-60
    const double a = 1.0 + std::ldexp(1.0, -30);
    double p;
    detail::two_product(a, a, p, e);
    BOOST_TEST(p == 1.0 + std::ldexp(1.0, -29));
    BOOST_TEST(e == std::ldexp(1.0, -60));
}

// A fine mesh's quadratic form: a chain of n springs k between nodes displaced by a large common
// offset plus small differences. The value is k sum (z_i - z_i+1)^2 with the differences and
// their squares' sum exact (multiples of 2^-30 on an offset of 0.7: every z_i and difference is
// representable), one rounding in the product by k = 7e10 N/m (graduated_elastic's 12 EI / l^3 is
// 1e11), n = 1000. Evaluated as
// z^T (K z) in double the terms k z_i^2 ~ 7e10 cancel down to ~1e-4: the error is ~eps k n z^2,
// orders above the value's own round-off; in twice the precision it is eps |value|.
BOOST_AUTO_TEST_CASE(quadratic_form_of_a_stiff_chain_keeps_its_digits) {
    const int n = 1000;
    const double k = 7e10;
    std::vector<Eigen::Triplet<double>> t;
    for (int i = 0; i + 1 < n; ++i) {
        t.emplace_back(i, i, k);
        t.emplace_back(i + 1, i + 1, k);
        t.emplace_back(i, i + 1, -k);
        t.emplace_back(i + 1, i, -k);
    }
    Eigen::SparseMatrix<double> K(n, n);
    K.setFromTriplets(t.begin(), t.end());
    Eigen::VectorXd z(n);
    double squares = 0.0;  // sum d_i^2 with d_i = j 2^-30, j in -3..3: each term and the sum exact
    for (int i = 0; i < n; ++i) z[i] = 0.7 + std::ldexp(static_cast<double>((i * 7) % 4), -30);
    for (int i = 0; i + 1 < n; ++i) {
        const double d = z[i] - z[i + 1];
        squares += d * d;
    }
    const double exact = k * squares;  // to one rounding
    const double naive = z.dot(K * z);
    const double accurate = detail::accurate_quadratic_form(K, z);
    BOOST_TEST_MESSAGE("relative error: double " << (naive - exact) / exact << ", accurate " << (accurate - exact) / exact);
    BOOST_TEST(std::abs(accurate - exact) <= 1e-15 * exact);  // a few roundings of the result's size
    BOOST_TEST(std::abs(naive - exact) > 1e3 * std::abs(accurate - exact));  // the cancellation this is for
}

// graduated_elastic.toml (4 leaves, 160 elements per half leaf, elastic interfaces, clamps) under
// newmark with massless leaves, its own 0.5 s: the step's energy identity is exact
// (newmark_stepper.hpp), so the balance must close to round-off, bound 1e-13 S per step as in
// test_soak (S the run's energy scale, here the initial kinetic energy plus the dissipated energy).
// In double the strain energy z^T K z (terms of 2e11 J for 72 J) and the step's residual left
// 1.38e-8 S (measured before the change); with the quadratic forms and the step's residual in
// twice the precision it closes to ~1e-13 S.
BOOST_AUTO_TEST_CASE(newmark_balance_on_a_fine_mesh_closes_to_round_off) {
    const Scenario sc = load_scenario(std::string(STACKBEAM_SOURCE_DIR) + "/scenarios/graduated_elastic.toml");
    const System system(Model::build(sc.model));
    SimulationOptions o = sc.simulation;
    o.mode = Mode::newmark;
    auto stepper = make_stepper(system, o);
    const double e0 = stepper->current().kinetic_energy_j + stepper->current().strain_energy_j;
    double balance = 0.0, dissipated = 0.0;
    const long n = static_cast<long>(std::ceil(o.t_end_s / o.dt_s - 1e-9));
    for (long i = 0; i < n; ++i) {
        const StepRecord& r = stepper->advance();
        balance = std::max(balance, std::abs(r.energy_balance_error_j));
        dissipated = r.dissipated_energy_j;
    }
    const double scale = e0 + dissipated, bound = 1e-13 * static_cast<double>(n) * scale;
    BOOST_TEST_MESSAGE("balance " << balance / scale << " S over " << n << " steps (bound " << bound / scale << " S)");
    BOOST_TEST(dissipated > 0.05 * e0);  // the pairs slip: the friction work is in the balance
    BOOST_TEST(balance <= bound);
}
