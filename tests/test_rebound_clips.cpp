// Rebound clips (model.hpp ClipSpec): a spring pulled apart opens up to the clip's clearance
// and then carries the load through the clip; its force against statics by hand.
#define BOOST_TEST_MODULE rebound_clips
#include <boost/test/unit_test.hpp>
#include <Eigen/Dense>
#include <cmath>

#include "stackbeam/errors.hpp"
#include "stackbeam/time/closed_form_stepper.hpp"
#include "test_support.hpp"

namespace tt = boost::test_tools;
using namespace stackbeam;
using namespace stackbeam::testing;

namespace {

constexpr double kL1 = kTwoLeafL1_m, kT1 = kTwoLeafT1_m, kT2 = kTwoLeafT2_m;
constexpr double kA = 0.2, kClearance = 0.001, kStrap = 2e6;

/// The flat two-leaf spring (test_support.hpp) with clips at L1 -+ a around both leaves
/// (clearance c, a soft strap of k = 2e6 N/m, so that its stretch T / k, 76 um at 151 N, is seen).
ModelSpec clipped_spring(Symmetry sym) {
    ModelSpec spec = two_leaf_spring(0.0, 0.0);
    spec.clips = {{kL1 - kA, 0, 1, kClearance, kStrap}, {kL1 + kA, 0, 1, kClearance, kStrap}};
    spec.symmetry = sym;
    return spec;
}

/// The rig pulls R down from 0 to w_end in `steps` quasi-static steps; the records and the
/// pairs at the end.
std::pair<std::vector<StepRecord>, std::vector<PairRecord>> pull(const System& sys, double w_end, int steps,
                                                                 ContactPath path) {
    SimulationOptions so;
    so.contact_path = path;
    so.mode = Mode::closed_form;
    so.dt_s = 1.0 / steps;
    so.t_end_s = 1.0;
    so.solver.tolerance_m = 1e-12;
    so.loading.kind = LoadingKind::prescribed_displacement;
    so.loading.displacement_m.shape = TimeFunction::Shape::table;
    so.loading.displacement_m.times_s = {0.0, 1.0};
    so.loading.displacement_m.values = {0.0, w_end};
    ClosedFormStepper st(sys, so);
    std::vector<StepRecord> records{st.current()};
    for (int i = 0; i < steps; ++i) records.push_back(st.advance());
    return {records, st.pairs()};
}

}  // namespace

BOOST_AUTO_TEST_CASE(clip_takes_the_rebound_load_beyond_its_clearance) {
    // Rebound: the rig pulls the seat down by W (w = -W) below the eyes' pins. Each half is two
    // cantilevers from the seat (x from it): the main leaf (L1, EI1) with its pin's force Q
    // at L1, the lower leaf (L2, EI2) free. Pulled apart, the leaves touch nowhere but at the
    // seat; the opening at the clip (x = a) is the main leaf's deflection there, W g(a, L1) /
    // g(L1, L1), with g(a, b) = a^2 (3b - a)/6 (a <= b), b^2 (3a - b)/6 (a >= b) the
    // cantilever's deflection at a per unit load at b and per unit EI. The clip engages when
    // it reaches the clearance c: at W_c = c g(L1, L1) / g(a, L1) (4.81 mm). Beyond, the clip's
    // tension T pulls the main leaf down and the lower leaf up at a, and the strap stretches by T/k:
    //     (Q g(a, L1) - T g(a, a)) / EI1 - T g(a, a) / EI2 = c + T / k   (opening = c + T/k)
    //     (Q g(L1, L1) - T g(L1, a)) / EI1 = W                          (the pin)
    // two equations for Q, T; the rig's force is -2 Q (whole spring, R pulled down).
    // Tolerance: beam elements are exact for point loads at nodes (the clip, the pins and the
    // seat are nodes), so 1e-8 relative (round-off, solver 1e-12 m).
    auto g = [](double a, double b) { return a <= b ? a * a * (3 * b - a) / 6 : b * b * (3 * a - b) / 6; };
    const double EI1 = steel_leaf_bending_stiffness(kT1), EI2 = steel_leaf_bending_stiffness(kT2);
    const double W_c = kClearance * g(kL1, kL1) / g(kA, kL1);
    const double W = 0.015;
    Eigen::Matrix2d M;
    M << g(kA, kL1) / EI1, -g(kA, kA) * (1.0 / EI1 + 1.0 / EI2) - 1.0 / kStrap, g(kL1, kL1) / EI1, -g(kL1, kA) / EI1;
    const Eigen::Vector2d QT = M.partialPivLu().solve(Eigen::Vector2d(kClearance, W));
    const double Q = QT[0], T = QT[1];
    BOOST_TEST_MESSAGE("rebound clip: engages at w = " << -W_c << " m; at w = " << -W << " m pin force " << Q
                                                      << " N, clip tension " << T << " N");
    BOOST_TEST(T > 0.0);
    for (const auto& [sym, path] : {std::pair{Symmetry::full, ContactPath::dense}, std::pair{Symmetry::half, ContactPath::dense},
                                    std::pair{Symmetry::full, ContactPath::sparse}}) {
        BOOST_TEST_CONTEXT((sym == Symmetry::full ? "full" : "half") << " model, "
                                                                      << (path == ContactPath::dense ? "dense" : "sparse") << " path") {
            const System sys(Model::build(clipped_spring(sym)));
            const auto [records, pairs] = pull(sys, -W, 30, path);
            BOOST_TEST(records.back().w_m == -W, tt::tolerance(1e-12));
            BOOST_TEST(records.back().spring_force_n == -2.0 * Q, tt::tolerance(1e-8));
            int clips = 0;
            for (const PairRecord& r : pairs) {
                if (std::abs(std::abs(r.x_m - kL1) - kA) > 1e-9 || r.p_t_n != 0.0) continue;
                // the clip's row and the interface's pair share the node: the clip's carries the tension
                if (r.p_n_n != 0.0) {
                    ++clips;
                    BOOST_TEST(-r.p_n_n == T, tt::tolerance(1e-8));
                }
            }
            BOOST_TEST(clips == (sym == Symmetry::full ? 2 : 1));
            // before the clip engages the spring is the main leaf alone: 2 * 3 EI1 / L1^3
            for (const StepRecord& r : records)
                if (-r.w_m < W_c * (1 - 1e-9))
                    BOOST_TEST(r.spring_force_n == 2.0 * 3.0 * EI1 / std::pow(kL1, 3) * r.w_m, tt::tolerance(1e-8));
        }
    }
}

BOOST_AUTO_TEST_CASE(clip_closes_an_initial_gap_wider_than_its_clearance) {
    // The flat two-leaf spring with a uniform initial gap of 3 mm and clips of 2.5 mm clearance:
    // the assembly (before t = 0, no force on R) pulls the leaves together at the clips until the
    // opening is the clearance plus the strap's stretch. Each half: the clip's tension T acts at
    // a on two cantilevers from the seat (the pins carry nothing: R is free and unloaded), so
    //     T g(a, a) (1/EI1 + 1/EI2) + T / k = gap - clearance = 0.5 mm       (T = 27.7 N)
    // and the main leaf's end falls by T g(L1, a) / EI1 below the seat: w = +that. (Leaf 1's tip,
    // 0.1 m beyond the clip, closes 0.9 mm of its 3 mm gap: it stays open.) Tolerance 1e-8.
    auto g = [](double a, double b) { return a <= b ? a * a * (3 * b - a) / 6 : b * b * (3 * a - b) / 6; };
    const double EI1 = steel_leaf_bending_stiffness(kT1), EI2 = steel_leaf_bending_stiffness(kT2);
    const double gap = 0.003, clearance = 0.0025;
    const double T = (gap - clearance) / (g(kA, kA) * (1.0 / EI1 + 1.0 / EI2) + 1.0 / kStrap);
    ModelSpec spec = clipped_spring(Symmetry::full);
    spec.interfaces[0].initial_gap_m = gap;
    for (auto& c : spec.clips) c.clearance_m = clearance;
    const System sys(Model::build(spec));
    SimulationOptions so;
    so.dt_s = 1e-4;
    so.t_end_s = 1e-4;
    so.solver.tolerance_m = 1e-12;
    const ClosedFormStepper st(sys, so);
    BOOST_TEST(st.current().w_m == T * g(kL1, kA) / EI1, tt::tolerance(1e-8));
    int engaged = 0;
    for (const PairRecord& r : st.pairs()) {
        if (r.p_n_n == 0.0) continue;
        ++engaged;
        BOOST_TEST(std::abs(std::abs(r.x_m - kL1) - kA) < 1e-9);
        BOOST_TEST(-r.p_n_n == T, tt::tolerance(1e-8));
    }
    BOOST_TEST(engaged == 2);
}

BOOST_AUTO_TEST_CASE(clip_input_is_checked) {
    auto expect = [](const ModelSpec& s, const std::string& field) {
        BOOST_TEST(input_error_field([&] { Model::build(s); }) == field);
    };
    ModelSpec bad = clipped_spring(Symmetry::full);
    bad.clips[1].clearance_m = 0.0;
    expect(bad, "clips[1].clearance_m");
    bad = clipped_spring(Symmetry::full);
    bad.clips[0].x_m = 0.1;  // off the lower leaf (0.2..0.8 m)
    expect(bad, "clips[0].x_m");
    bad = clipped_spring(Symmetry::full);
    bad.clips[0].last_leaf = 0;
    expect(bad, "clips[0].last_leaf");
    bad = clipped_spring(Symmetry::full);
    bad.clips[0].x_m = kL1;  // at the seat
    expect(bad, "clips[0].x_m");
    bad = clipped_spring(Symmetry::half);
    bad.clips.pop_back();  // the half model needs the mirrored twin
    expect(bad, "clips[0].x_m");
    const System sys(Model::build(clipped_spring(Symmetry::full)));
    SimulationOptions so;
    so.mode = Mode::cvode;
    so.dt_s = 1e-4;
    so.t_end_s = 1e-3;
    BOOST_TEST(input_error_field([&] { simulate(sys, so); }) == "clips[0]");
}
