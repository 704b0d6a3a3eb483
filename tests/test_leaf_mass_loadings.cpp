// Every loading with the leaves' own inertia, in mode newmark and in mode cvode with the whole
// massive stack (loading.hpp, newmark_stepper.hpp, lib/time/cvode/cvode_massive.cpp): free
// response, applied force, gravity with the leaves' weight, base excitation and the rig.
//
// The independent value: on a stack whose pairs all stay held (bonded, or compressed and
// frictionless) with elastic interfaces, the motion is linear, M z'' + K_t z = q(t) with
// K_t = K + G_S^T C_L^-1 G_S (every held row's layer spring), and its exact solution is the
// modal superposition of the generalized eigen-solve (K_t, M) with each mode's response to
// the loading written in closed form (constant and harmonic forcing from the initial state).
// The time histories are compared at every output: that the free response follows the
// eigen-solve's frequencies is the first case, the loadings are the others. The records also
// show that no pair ever slipped or opened (else the reference would not apply).
//
// Tolerances. Mode cvode (rtol 1e-6, atol 1e-10 m): the BDF's global error over the ~1e3-1e5
// steps of a run is bounded by 1e3 rtol of the response's amplitude (measured: 4e-6 of it at
// most, on the applied force). Mode newmark: 1e-4 of the amplitude at dt = 1e-5 s, and the error
// must fall at least 1.8x from dt = 2e-5 s: first order, because each closed layer's force enters
// a step as its implicit impulse (newmark_stepper.cpp); the leaves' elastic forces alone are
// second order (measured ratios 2.1-2.4). The rig's force is the exception (see that case).
#define BOOST_TEST_MODULE leaf_mass_loadings
#include <boost/test/unit_test.hpp>
#include <Eigen/Dense>
#include <cmath>
#include <functional>
#include <string>

#include "stackbeam/errors.hpp"
#include "stackbeam/time/stepper.hpp"
#include "test_support.hpp"
#include "tied_modal_reference.hpp"

namespace tt = boost::test_tools;
using namespace stackbeam;
using namespace stackbeam::testing;

namespace {

/// The paper's bonded (or frictionless) stack of 3 leaves at 10 elements per half leaf, steel
/// density, elastic interfaces (derived layer), 10 mm clamps (an elastic layer over them).
System stack(PaperCase c) { return System(Model::build(steel_elastic_stack(c))); }

SimulationOptions options(Mode mode, double t_end_s, double dt_s) {
    SimulationOptions so = run_options(mode, t_end_s, dt_s, 1e-12, 1e-6);
    so.cvode.atol_m = 1e-10;
    so.cvode.leaf_inertia = LeafInertia::massive;
    return so;
}

/// Every pair held over the run (none slipped or opened), and the balance closed to `tol_j`.
void require_held_and_balanced(const std::vector<StepRecord>& r, double tol_j) {
    double err = 0.0;
    for (const auto& rec : r) {
        BOOST_REQUIRE_EQUAL(rec.n_slip, 0);
        BOOST_REQUIRE_EQUAL(rec.n_open, 0);
        err = std::max(err, std::abs(rec.energy_balance_error_j));
    }
    BOOST_TEST_MESSAGE("  energy balance error " << err << " J");
    BOOST_TEST(err < tol_j);
}

/// Runs `system` under `loading` from R at w0 [m] in mode cvode and in mode newmark at dt and
/// dt/2, and compares the records' `got` with `ref(t)` (file comment): cvode within 1e-6 of the
/// reference's amplitude (1e3 x rtol: the global error over ~1e3-1e4 steps), newmark within 1e-4
/// of it at dt = 1e-5 s with the error falling at least 1.8x from dt = 2e-5 s unless it is already
/// below 1e-7 of the amplitude (round-off): first order, as the layer's force enters each step as
/// its implicit impulse (newmark_stepper.cpp; the leaves' elastic forces alone are second order). Every pair held, the balance
/// closed: cvode to 1e3 rtol, newmark to 1e-9 of the energy scale (exact by construction).
void check_case(const std::string& name, const System& system, const Loading& loading, double w0, double t_end_s,
                const std::function<double(const StepRecord&)>& got, const std::function<double(double)>& ref,
                double energy_scale_j, double cvode_bound = 1e-3, double newmark_bound = 1e-4, double min_ratio = 1.8,
                const StructuralDamping& damping = {}) {
    ModelSpec spec = system.model().spec();
    spec.rigid_body.initial_displacement_m = w0;
    const System sw(Model::build(spec));
    std::vector<StepRecord> probe_times;
    double amplitude = 0.0;
    double newmark_dev[2] = {0.0, 0.0};
    for (int run = 0; run < 3; ++run) {
        const Mode mode = run == 0 ? Mode::cvode : Mode::newmark;
        const double dt = run == 0 ? 1e-4 : run == 1 ? 2e-5 : 1e-5;
        SimulationOptions so = options(mode, t_end_s, dt);
        so.loading = loading;
        so.damping = damping;
        RunReport rep;
        const auto r = simulate(sw, so, {}, &rep);
        if (run == 0) amplitude = max_abs(r, ref);
        const double dev = max_deviation(r, got, ref);
        BOOST_TEST_MESSAGE(name << ", " << to_string(mode) << " dt " << dt << ": max deviation " << dev << " of "
                                << amplitude << " (" << rep.steps << " steps)");
        require_held_and_balanced(r, run == 0 ? 1e3 * so.cvode.rtol * energy_scale_j : 1e-9 * energy_scale_j);
        if (run == 0) BOOST_TEST(dev < cvode_bound * amplitude);
        else newmark_dev[run - 1] = dev;
    }
    BOOST_TEST(newmark_dev[1] < newmark_bound * amplitude);
    BOOST_TEST((newmark_dev[0] / newmark_dev[1] > min_ratio || newmark_dev[1] < 1e-7 * amplitude));
}

double w_of(const StepRecord& r) { return r.w_m; }

}  // namespace

BOOST_AUTO_TEST_CASE(free_response_follows_the_eigen_solve) {
    // R released from w0 = 1 mm with the leaves in the static shape held there (no velocity).
    // Bonded stack, 20 ms (about 1.4 periods of R's mode; the leaves' own modes at 1570 rad/s
    // and up are in the response too). Undamped, then with Rayleigh damping C = alpha M + beta K,
    // which is diagonal in the modes: mode i decays with zeta_i = alpha / (2 omega_i) +
    // beta omega_i / 2 (R's mode: 0.07; the layer's modes above 1e6 rad/s overdamped), and the
    // damping energy is in the balance.
    const System s = stack(PaperCase::bonded);
    const Linear L = linear(s);
    const double w0 = 1e-3;
    StructuralDamping damped;
    damped.rayleigh_alpha_per_s = 10.0;
    damped.rayleigh_beta_s = 2e-6;
    for (const StructuralDamping& c : {StructuralDamping{}, damped}) {
        const Modal ref(L.M, L.K, held_shape(L, w0), Eigen::VectorXd::Zero(L.w + 1), Forcing{}, c);
        BOOST_TEST_MESSAGE("lowest frequencies " << ref.omega.head(3).transpose() << " rad/s");
        check_case(c.active() ? "damped free response" : "free response", s, Loading{}, w0, 0.02, w_of,
                   w_reference(ref, L.w), 0.5 * s.tied_stiffness_n_per_m() * w0 * w0, 1e-3, 1e-4, 1.8, c);
    }
}

BOOST_AUTO_TEST_CASE(free_response_of_the_frictionless_stack_follows_the_eigen_solve) {
    // The frictionless stack (mu = 0, normal rows only, the leaves free to slide): the same check
    // with the normal layer springs alone tied. Its pairs carry no force (three identical leaves
    // tied by R's seat and the clamps bend alike), so the records count them open; the
    // comparison of w is what shows none separated.
    const System s = stack(PaperCase::frictionless);
    const Linear L = linear(s);
    const double w0 = 1e-3;
    const Modal ref(L.M, L.K, held_shape(L, w0), Eigen::VectorXd::Zero(L.w + 1), Forcing{});
    BOOST_TEST_MESSAGE("frictionless: lowest frequencies " << ref.omega.head(3).transpose() << " rad/s");
    ModelSpec spec = s.model().spec();
    spec.rigid_body.initial_displacement_m = w0;
    const System sw(Model::build(spec));
    for (Mode mode : {Mode::cvode, Mode::newmark}) {
        const auto r = simulate(sw, options(mode, 0.02, mode == Mode::cvode ? 1e-4 : 1e-5));
        const double dev = max_deviation(r, w_of, w_reference(ref, L.w));
        BOOST_TEST_MESSAGE("frictionless, " << to_string(mode) << ": max |w - w_modal| " << dev << " m of " << w0);
        BOOST_TEST(dev < (mode == Mode::cvode ? 1e-3 : 1e-4) * w0);
    }
}

BOOST_AUTO_TEST_CASE(applied_force_with_leaf_mass) {
    // F(t) = 200 N sin(2 pi 5 Hz t) on R from rest: q = e_w F / f (whole-spring force on the
    // meshed part), 50 ms, below R's mode (11 Hz).
    const System s = stack(PaperCase::bonded);
    const Linear L = linear(s);
    const HarmonicForceCase force = harmonic_force_case(s, L, 200.0, 5.0);
    check_case("applied force", s, force.load, 0.0, 0.05, w_of, w_reference(force.ref, L.w), force.energy_scale_j);
}

// Release only (label slow: the longest case of this file under the sanitizers); the sanitizer
// build still runs the other loadings with leaf mass (applied force, the rig, free response) and base excitation on the modal stepper (test_cvode_modal_loadings).
BOOST_AUTO_TEST_CASE(base_excitation_with_leaf_mass, *boost::unit_test::label("slow")) {
    // The supports move by y_b = A cos(Omega t) (A = 1 mm, 3 Hz; y_b'(0) = 0, so the stack starts
    // at rest relative to them): in their frame every mass feels -y_b'' times itself,
    // q = A Omega^2 cos(Omega t) l. Well below R's mode, R moves with the base (w + y_b ~ y_b).
    const System s = stack(PaperCase::bonded);
    const Linear L = linear(s);
    const double A = 1e-3, Om = 2.0 * kPi * 3.0;
    const BaseExcitationCase base = base_excitation_case(L, A, 3.0);
    const Loading& load = base.load;
    const double amp = A * (Om * Om) / (70.0 * 70.0);
    check_case("base excitation", s, load, 0.0, 0.05, w_of, w_reference(base.ref, L.w),
               0.5 * s.tied_stiffness_n_per_m() * A * A);
    // R's absolute motion follows the base's to the quasi-static (Omega/omega_1)^2 ~ 0.07 of it
    SimulationOptions so = options(Mode::cvode, 0.05, 1e-4);
    so.loading = load;
    for (const auto& r : simulate(s, so)) BOOST_TEST(std::abs(r.w_m) < 2.0 * amp);
}

BOOST_AUTO_TEST_CASE(gravity_with_the_leaves_weight) {
    // Bonded stack under g from rest: the run starts from the static equilibrium of the whole
    // stack under its weight and R's (K_t z = -g l) and stays there.
    const double g = 9.81;
    {
        const System s = stack(PaperCase::bonded);
        const Linear L = linear(s);
        Loading load;
        load.gravity_m_per_s2 = g;
        const Eigen::VectorXd zg = L.K.ldlt().solve(Eigen::VectorXd(-g * L.l));
        BOOST_TEST_MESSAGE("bonded: static sag " << zg[L.w] << " m");
        check_case("gravity, bonded", s, load, 0.0, 0.02, w_of, [&](double) { return zg[L.w]; },
                   0.5 * s.tied_stiffness_n_per_m() * zg[L.w] * zg[L.w]);
    }
    // Frictionless stack of 3 identical pinned leaves, R at midspan tying them: each leaf carries
    // its own weight and a third of R's, the pairs no force, so the sag is the closed form of a
    // simply supported beam, 5 q L^4 / (384 E I) + (m g / 3) L^3 / (48 E I) per leaf (exact at the
    // nodes for cubic elements with consistent loads: the bound is the solver's tolerance).
    const System s = stack(PaperCase::frictionless);
    const auto& leaf = s.model().spec().leaves[0];
    const double L = leaf.length_m, EI = leaf.youngs_modulus_pa * leaf.width_m * std::pow(leaf.height_m, 3) / 12.0;
    const double q = kSteel * leaf.width_m * leaf.height_m * g, m = s.model().spec().rigid_body.mass_kg;
    const double sag = 5.0 * q * std::pow(L, 4) / (384.0 * EI) + m * g / 3.0 * std::pow(L, 3) / (48.0 * EI);
    for (Mode mode : {Mode::cvode, Mode::newmark}) {
        SimulationOptions so = options(mode, 0.01, mode == Mode::cvode ? 1e-4 : 1e-5);
        so.loading.gravity_m_per_s2 = g;
        const auto r = simulate(s, so);
        double dev = 0.0;
        for (const auto& rec : r) dev = std::max(dev, std::abs(rec.w_m + sag));
        BOOST_TEST_MESSAGE("frictionless, " << to_string(mode) << ": sag " << -r.front().w_m << " m, closed form " << sag
                                            << " m, max deviation over the run " << dev << " m");
        BOOST_TEST(dev < 1e-9 * sag + 1e-12);
    }
}

BOOST_AUTO_TEST_CASE(rig_force_includes_the_leaves_inertia) {
    // The rig moves R by w_p = A (1 - cos Omega t) (A = 2 mm, 8 Hz; at rest at t = 0). With w
    // given, the leaves obey M_rr z_r'' + K_rr z_r = -M_rw w_p'' - K_rw w_p, solved exactly by the
    // constrained system's modes; the load cell between R and the spring reads
    // f ((M z'' + K_t z)_w - m w_p''): the spring's static force plus the leaves' inertia.
    const System s = stack(PaperCase::bonded);
    const Linear L = linear(s);
    const int w = L.w;
    const double A = 2e-3, Om = 2.0 * kPi * 8.0;
    Loading load;
    load.kind = LoadingKind::prescribed_displacement;
    load.displacement_m.shape = TimeFunction::Shape::harmonic;
    load.displacement_m.mean = A;
    load.displacement_m.amplitude = A;
    load.displacement_m.frequency_hz = 8.0;
    load.displacement_m.phase_rad = -kPi / 2.0;
    const Eigen::MatrixXd Mrr = L.M.topLeftCorner(w, w), Krr = L.K.topLeftCorner(w, w);
    const Eigen::VectorXd Mrw = L.M.block(0, w, w, 1), Krw = L.K.block(0, w, w, 1);
    Forcing q;
    q.omega = Om;
    q.a = -A * Krw;
    q.b = A * (Krw - Om * Om * Mrw);
    const Modal ref(Mrr, Krr, Eigen::VectorXd::Zero(w), Eigen::VectorXd::Zero(w), q);
    auto force_ref = [&](double t) {
        Eigen::VectorXd zr, ar;
        ref.at(t, zr, ar);
        const double wp = A * (1.0 - std::cos(Om * t)), wpdd = A * Om * Om * std::cos(Om * t);
        const double lambda = L.M.row(w).head(w).dot(ar) + L.M(w, w) * wpdd + L.K.row(w).head(w).dot(zr) + L.K(w, w) * wp;
        return L.f * (lambda - L.m_half * wpdd);
    };
    // The force is M z'' + K_t z: the accelerations of every mode, the mesh-scale and layer modes
    // included, which w_p'' jumping from 0 to A Omega^2 at t = 0 sets ringing (undamped). CVODE
    // controls their displacements to ~atol, and k_layer x atol is ~0.1 N of the 375 N (measured
    // 0.12 N: bound 1e-3 of the amplitude); newmark's phase error (omega dt)^2 omega t / 12 on
    // them is ~0.04 rad at 4435 rad/s, dt = 1e-5 s and 50 ms (measured 0.71 N: bound 5e-3 of the
    // amplitude, the error falling at least 1.5x when dt halves; measured 1.6x).
    const double F = s.tied_stiffness_n_per_m() * 2.0 * A;
    check_case("rig", s, load, 0.0, 0.05, [](const StepRecord& r) { return r.spring_force_n; }, force_ref,
               0.5 * F * 2.0 * A, 1e-3, 5e-3, 1.5);
}

BOOST_AUTO_TEST_CASE(the_assembled_stack_starts_at_the_nip_and_stays_there) {
    // The leaf-mass integrators start from the assembled stack too (free camber, clips: the
    // static assembly step with friction before t = 0, detail::static_stages). The classic nip
    // (test_assembly): two steel leaves bolted at the seat, the lower one (half length L2 = 0.3 m,
    // 6 mm, free radius 3 m) more curved than the upper (L1 = 0.5 m, 8 mm, 5 m), frictionless;
    // each half a pair of cantilevers from the seat touching only at the lower leaf's tip, where
    // the bolt closes the interference delta = (1/R2 - 1/R1) L2^2 / 2 by a force
    //     P = delta / (L2^3 / 3 (1/EI1 + 1/EI2) + c_tip),
    // c_tip the tip pair's layer compliance (0 on a rigid interface: P = 101.3 N), and the seat
    // sits P L2^2 (3 L1 - L2) / (6 EI1) below the upper leaf's pins. Mode newmark on the rigid
    // interface and both integrators on the elastic one, and mode cvode's modal stepper on both
    // (its static state is the whole stack's): the initial tip force and w to 1e-8
    // (cubic elements are exact for tip loads; the solver's tolerance is 1e-12 m), and with no
    // loading the stack stays there (it starts in equilibrium): w within 1e-9 of it for 2 ms.
    const double L1 = kTwoLeafL1_m, L2 = kTwoLeafL2_m, R1 = 5.0, R2 = 3.0;
    const double EI1 = steel_leaf_bending_stiffness(kTwoLeafT1_m), EI2 = steel_leaf_bending_stiffness(kTwoLeafT2_m);
    const double delta = (1.0 / R2 - 1.0 / R1) * L2 * L2 / 2.0;
    for (const bool elastic : {false, true}) {
        ModelSpec spec = two_leaf_spring(R1, R2);
        for (auto& leaf : spec.leaves) leaf.density_kg_per_m3 = kSteel;
        if (elastic) spec = with_elastic_interfaces(spec);
        const System sys(Model::build(spec));
        double c_tip = 0.0;
        int tip = -1;
        for (int k = 0; k < static_cast<int>(sys.pairs().size()); ++k)
            if (std::abs(std::abs(sys.pair_spec(k).x_m - L1) - L2) < 1e-9) {
                tip = k;
                c_tip = sys.layer_compliance_m_per_n().size() ? sys.layer_compliance_m_per_n()[sys.pairs()[k].row_n] : 0.0;
            }
        BOOST_REQUIRE(tip >= 0);
        const double P = delta / (L2 * L2 * L2 / 3.0 * (1.0 / EI1 + 1.0 / EI2) + c_tip);
        const double w = -P * L2 * L2 * (3.0 * L1 - L2) / (6.0 * EI1);
        for (int variant = 0; variant < 3; ++variant) {  // newmark, cvode massive, cvode modal
            const Mode mode = variant == 0 ? Mode::newmark : Mode::cvode;
            if (variant == 1 && !elastic) continue;  // the massive stack needs the elastic layer
            SimulationOptions so = options(mode, 2e-3, mode == Mode::cvode ? 1e-4 : 1e-5);
            if (variant == 2) so.cvode.leaf_inertia = LeafInertia::modal;
            const auto st = make_stepper(sys, so);
            const double p_tip = -st->pairs()[static_cast<std::size_t>(tip)].p_n_n;
            const double w0 = st->current().w_m;
            BOOST_TEST_MESSAGE((elastic ? "elastic, " : "rigid, ") << to_string(mode) << (variant == 2 ? " (modal)" : "")
                                                                  << ": tip force " << p_tip
                                                                  << " N (closed form " << P << "), w(0) " << w0 << " m (" << w << ")");
            BOOST_TEST(p_tip == P, tt::tolerance(1e-8));
            BOOST_TEST(w0 == w, tt::tolerance(1e-8));
            double drift = 0.0;
            while (st->current().t_s < so.t_end_s - 1e-12) drift = std::max(drift, std::abs(st->advance().w_m - w0));
            BOOST_TEST(drift < 1e-9 * std::abs(w));
        }
    }
}
