// Mode cvode with leaf inertia, first part (lib/time/cvode/cvode_held.hpp, docs/time-integration.md): the
// bonded and frictionless stacks with steel leaves, a stiff linear ODE integrated by BDF
// (order <= 2) in the held stack's modal coordinates. Checked against the eigen-solve, the Newmark
// reference as its dt -> 0, and the energy balance against rtol.
#define BOOST_TEST_MODULE cvode_inertia
#include <boost/test/unit_test.hpp>
#include <algorithm>
#include <cmath>

#include "stackbeam/time/cvode_stepper.hpp"
#include "stackbeam/errors.hpp"
#include "stackbeam/fe/modal.hpp"
#include "test_support.hpp"

namespace tt = boost::test_tools;
using namespace stackbeam;
using namespace stackbeam::testing;

namespace {

System massive(PaperCase c, double density = kSteel) { return System(Model::build(paper_with_mass(c, density, false))); }

std::vector<StepRecord> run(const System& s, Mode mode, double t_end_s, double dt_s, double rtol = 1e-8,
                            RunReport* report = nullptr) {
    return simulate(s, run_options(mode, t_end_s, dt_s, 1e-9, rtol), {}, report);
}
}  // namespace

BOOST_AUTO_TEST_CASE(free_response_frequency_matches_the_eigen_solve) {
    // 20 elements per half leaf: omega from the mean period of w against modal_analysis
    // (bonded 70.795 rad/s, all components tied, over 1 s; frictionless 23.663 rad/s,
    // the normal components tied, over 2 s). BDF2's phase error is O((omega h)^2) per
    // radian with h set by rtol = 1e-8 (measured 33k steps/s, omega h ~ 2e-3); the leaf
    // modes shift the zero crossings by ~1e-7 (test_inertia.cpp): tolerance 2e-6.
    for (PaperCase c : {PaperCase::bonded, PaperCase::frictionless}) {
        BOOST_TEST_CONTEXT("case " << to_string(c)) {
            const System s = massive(c);
            const double omega =
                modal_analysis(s, c == PaperCase::bonded ? ModalTie::all : ModalTie::normal, 1).omega_rad_per_s[0];
            RunReport rep;
            const auto r = run(s, Mode::cvode, c == PaperCase::bonded ? 1.0 : 2.0, 2.5e-4, 1e-8, &rep);
            const double measured = 2.0 * kPi / mean_period(r);
            BOOST_TEST_MESSAGE(to_string(c) << ": omega from the response " << measured << " rad/s, eigen-solve "
                                            << omega << " (relative " << measured / omega - 1.0 << "); "
                                            << rep.cvode.steps << " steps, " << rep.cvode.jacobian_evaluations
                                            << " Jacobians, " << rep.cvode.linear_setups << " Newton matrices");
            BOOST_TEST(measured == omega, tt::tolerance(2e-6));
        }
    }
}

BOOST_AUTO_TEST_CASE(converges_to_the_newmark_reference) {
    // w(t) on 0.3 s, cvode at rtol 1e-9 against mode newmark at dt = 0.2, 0.1, 0.05 ms:
    // Newmark's error is O(dt^2) on the bonded stack (no contact transitions), so the
    // deviation must fall at least 3.5x per halving (measured 4.05x, 4.7x: the floor of
    // cvode's own error at this rtol is not reached) and end below 1e-6 m (of 28 mm;
    // measured 4.6e-7 m).
    const System s = massive(PaperCase::bonded);
    const auto ref = run(s, Mode::cvode, 0.3, 1e-4, 1e-9);
    double prev = 0.0;
    for (double dt : {2e-4, 1e-4, 5e-5}) {
        const auto nm = run(s, Mode::newmark, 0.3, dt);
        // common output times: those of the coarser grid (ref every 0.1 ms)
        double dev = 0.0;
        for (std::size_t j = 0; j < ref.size(); ++j) {
            const double k = static_cast<double>(j) * 1e-4 / dt;
            const auto ki = static_cast<std::size_t>(std::lround(k));
            if (std::abs(k - static_cast<double>(ki)) > 1e-9 || ki >= nm.size()) continue;
            dev = std::max(dev, std::abs(ref[j].w_m - nm[ki].w_m));
        }
        BOOST_TEST_MESSAGE("newmark dt " << dt << ": max |w_cvode - w_newmark| " << dev << " m");
        if (prev > 0.0) BOOST_TEST(prev / dev > 3.5);
        prev = dev;
    }
    BOOST_TEST(prev < 1e-6);
}

BOOST_AUTO_TEST_CASE(energy_balance_closes_as_rtol_falls) {
    // The bonded stack conserves kinetic + strain energy; BDF2 damps a little, which the
    // error control bounds: over 1 s the balance error must be below 1000 rtol of the
    // 42.9 J (measured 270 rtol at 1e-6, 40 rtol at 1e-8) and fall at least 100x from
    // rtol 1e-6 to 1e-8 (measured 660x).
    const System s = massive(PaperCase::bonded);
    double prev = 0.0;
    for (double rtol : {1e-6, 1e-8}) {
        RunReport rep;
        const auto r = run(s, Mode::cvode, 1.0, 1e-3, rtol, &rep);
        const double e0 = r.front().kinetic_energy_j + r.front().strain_energy_j;
        double worst = 0.0;
        for (const auto& x : r) worst = std::max(worst, std::abs(x.energy_balance_error_j));
        BOOST_TEST_MESSAGE("rtol " << rtol << ": max |balance error| " << worst << " J of " << e0 << " J ("
                                   << worst / e0 / rtol << " rtol); " << rep.cvode.steps << " steps");
        BOOST_TEST(worst < 1000.0 * rtol * e0);
        if (prev > 0.0) BOOST_TEST(prev / worst > 100.0);
        prev = worst;
    }
}

BOOST_AUTO_TEST_CASE(response_converges_to_the_massless_mode_as_density_falls) {
    // Bonded stack, 0.3 s: w(t) of cvode with leaf inertia against the closed-form
    // (massless) mode at dt = 0.1 ms (its own error ~1e-6 m: test_inertia.cpp). The
    // deviation is proportional to the density (the leaves' mass lowers omega): 10x less
    // density, 10x less deviation (+-30 %; newmark measured 8.9x and 9.9x), while the
    // leaf modes grow stiffer as 1/sqrt(density) (BDF is A-stable: no step limit).
    const auto ref = run(massive(PaperCase::bonded, 0.0), Mode::closed_form, 0.3, 1e-4);
    double prev = 0.0;
    for (double rho : {kSteel / 10, kSteel / 100}) {
        RunReport rep;
        const auto r = run(massive(PaperCase::bonded, rho), Mode::cvode, 0.3, 1e-4, 1e-8, &rep);
        double dev = 0.0;
        for (std::size_t i = 0; i < std::min(r.size(), ref.size()); ++i) dev = std::max(dev, std::abs(r[i].w_m - ref[i].w_m));
        BOOST_TEST_MESSAGE("density " << rho << ": max |w - w_massless| " << dev << " m, " << rep.cvode.steps << " steps");
        if (prev > 0.0) BOOST_TEST(prev / dev == 10.0, tt::tolerance(0.3));
        prev = dev;
    }
}
