// The windup figures (run/loop_figures.hpp, windup_figures; docs/windup.md, "The windup figures"):
// the windup stiffness, loop area and loss factor of a windup loop and the seat's longitudinal
// compliance against closed forms and the friction work, and each front-end's copy of them (the JSON
// summary, the sweep's columns) equal to the run layer's.
//
// Tolerances. Prismatic leaves loaded at nodes (the seat is a node): the cubic Hermite element is
// exact there, so the static figures are to rounding (relative 1e-9, well above the 1e-12 of the
// factorisations of a few hundred DOFs). A friction loop's area equals its friction work to the
// contact solver's tolerance (1e-9 m on the gaps and slips, relative 1e-6 of the work here, as in
// test_windup's loop), and its loss factor is that area over 2 pi E_s (the same tolerance).
#define BOOST_TEST_MODULE windup_figures
#include <boost/test/unit_test.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "stackbeam/errors.hpp"
#include "stackbeam/io/scenario.hpp"
#include "stackbeam/run/run.hpp"
#include "stackbeam/run/summary_json.hpp"
#include "stackbeam/study/sweep.hpp"
#include "stackbeam/study/sweep_output.hpp"

using namespace stackbeam;
namespace tt = boost::test_tools;

namespace {

constexpr double kPi = 3.14159265358979323846;
// the flat leaf of tests/sweep/windup_small.toml: 1.2 m, 10 x 50 mm, E = 206 GPa, the seat at a = 0.5 m
constexpr double kL = 1.2, kT = 0.01, kB = 0.05, kE = 206e9, kA = 0.5;
const double kEI = kE * kB * kT * kT * kT / 12.0, kEA = kE * kB * kT;
const std::string kWindupFile = std::string(STACKBEAM_SOURCE_DIR) + "/tests/sweep/windup_small.toml";

RunSummary run(const Scenario& s) {
    const System system(Model::build(s.model));
    RunRequest request;
    request.options = s.simulation;
    return run_scenario(system, request);
}

/// A spring of `leaves` ([[leaves]] tables) 1.2 m long on pinned eyes, the seat at mid-length, with
/// `interface` (an [[interfaces]] table, "" none), `loading` ([loading] and its tables), mode newmark
/// with massless leaves, dt = 10 ms to `t_end_s`.
Scenario spring(const std::string& leaves, const std::string& interface, const std::string& loading,
                double t_end_s = 2.0) {
    return parse_scenario(leaves + interface + R"(
[rigid_body]
mass_kg = 1.0
x_m = 0.6
)" + loading + R"(
[mesh]
element_length_m = 0.05
symmetry = "full"
[integrator]
mode = "newmark"
dt_s = 0.01
t_end_s = )" + std::to_string(t_end_s) + "\n",
                          "test.toml");
}

/// The main leaf (1.2 m, pinned eyes) and a 0.8 m leaf below it, centred, free ends.
const std::string kTwoLeaves = R"(
[[leaves]]
length_m = 1.2
height_m = 0.01
width_m = 0.05
youngs_modulus_pa = 206e9
left_support = "pinned"
right_support = "pinned"
[[leaves]]
length_m = 0.8
x_start_m = 0.2
height_m = 0.01
width_m = 0.05
youngs_modulus_pa = 206e9
left_support = "free"
right_support = "free"
)";

/// A triangle of `amplitude` at 1 Hz as the table `name` ("loading.seat_rotation_rad").
std::string triangle(const std::string& name, double amplitude, double mean = 0.0) {
    return "[" + name + "]\nshape = \"triangle\"\namplitude = " + std::to_string(amplitude) +
           "\nmean = " + std::to_string(mean) + "\nfrequency_hz = 1.0\n";
}

}  // namespace

// A single flat leaf with the seat held vertically and wound +-0.02 rad (tests/sweep/windup_small.toml):
// each half a propped cantilever built in at the seat, so the rig's loop is the line M = k theta with
// k = 3 E I (1/a + 1/b); its secant is k and, traversed back and forth, it encloses no area (the
// trapezoidal sum of k theta dtheta telescopes to 0: round-off, relative to M_max theta_max).
BOOST_AUTO_TEST_CASE(bonded_flat_leaf_winds_up_at_3EI_over_a_plus_over_b_with_no_loop) {
    const RunSummary s = run(load_scenario(kWindupFile));
    BOOST_TEST_REQUIRE(s.windup.has_value());
    BOOST_TEST_REQUIRE(s.windup->windup.has_value(), s.windup->windup_note);
    const HysteresisMetrics& m = *s.windup->windup;
    const double k = 3.0 * kEI * (1.0 / kA + 1.0 / (kL - kA));
    BOOST_TEST_MESSAGE("windup stiffness " << m.secant_stiffness_n_per_m << " N m/rad, 3 E I (1/a + 1/b) " << k
                                           << ", loop area " << m.loop_area_j << " J");
    BOOST_TEST(m.secant_stiffness_n_per_m == k, tt::tolerance(1e-9));
    BOOST_TEST(m.w_max_m == 0.02, tt::tolerance(1e-12));  // theta_R over the cycle [rad]
    BOOST_TEST(m.w_min_m == -0.02, tt::tolerance(1e-12));
    BOOST_TEST(std::abs(m.loop_area_j) < 1e-12 * m.force_max_n * m.w_max_m);
    BOOST_TEST(std::abs(m.loss_factor) < 1e-9);
    BOOST_TEST(m.t_end_s - m.t_start_s == 1.0, tt::tolerance(1e-9));  // the rig's period
    // no vertical loop (the seat held at w = 0): no vertical rate; no longitudinal force
    BOOST_TEST(!s.loop.metrics.has_value());
    BOOST_TEST(std::isnan(s.windup->vertical_rate_n_per_m));
    BOOST_TEST(std::isnan(s.windup->longitudinal_compliance_m_per_n));
    BOOST_TEST(s.windup->longitudinal_note == "no longitudinal force");

    // the JSON summary's "windup" section: the same numbers
    const auto j = nlohmann::json::parse(summary_json(s, Model::build(load_scenario(kWindupFile).model)));
    const auto& w = j.at("windup");
    BOOST_TEST(w.at("stiffness_n_m_per_rad").get<double>() == m.secant_stiffness_n_per_m);
    BOOST_TEST(w.at("loop_area_j").get<double>() == m.loop_area_j);
    BOOST_TEST(w.at("loss_factor").get<double>() == m.loss_factor);
    BOOST_TEST(w.at("energy_loss_factor").get<double>() == m.energy_loss_factor);
    BOOST_TEST(w.at("loop").at("secant_stiffness_n_m_per_rad").get<double>() == m.secant_stiffness_n_per_m);
    BOOST_TEST(w.at("loop").at("seat_rotation_rad_max").get<double>() == m.w_max_m);
    BOOST_TEST(w.at("loop").at("seat_moment_n_m_max").get<double>() == m.force_max_n);
    BOOST_TEST(w.at("vertical_rate_n_per_m").is_null());
    BOOST_TEST(w.at("longitudinal_compliance_m_per_n").is_null());
    BOOST_TEST(w.at("longitudinal_loop").is_null());
    // a run that does not load the seat has none
    Scenario vertical = load_scenario(kWindupFile);
    vertical.simulation.loading.seat_rotation_rad.reset();
    vertical.simulation.mode = Mode::closed_form;  // the vertical rig alone: mode closed-form's
    const RunSummary v = run(vertical);
    BOOST_TEST(!v.windup.has_value());
    BOOST_TEST(nlohmann::json::parse(summary_json(v, Model::build(vertical.model))).at("windup").is_null());
}

// The sweep's windup columns (a map over the rig's amplitude) are the run layer's figures: the same
// function (run/loop_figures.hpp) on the same records, so equal to the bit; the linear leaf's k_theta
// is the same at every amplitude (3 E I (1/a + 1/b) to rounding).
BOOST_AUTO_TEST_CASE(sweep_columns_are_the_windup_figures) {
    const SweepSpec spec = parse_sweep_spec("scenario = \"windup_small.toml\"\n[[axes]]\nkey = "
                                            "\"loading.seat_rotation_rad.amplitude\"\nvalues = [0.01, 0.02]\n",
                                            std::string(STACKBEAM_SOURCE_DIR) + "/tests/sweep/in_code.toml");
    const auto& columns = point_figure_columns();
    auto column = [&](const std::string& name) {
        const auto at = std::find(columns.begin(), columns.end(), name);
        BOOST_TEST_REQUIRE((at != columns.end()), name);
        return static_cast<std::size_t>(at - columns.begin());
    };
    const double k = 3.0 * kEI * (1.0 / kA + 1.0 / (kL - kA));
    for (const SweepPoint& p : expand_points(spec)) {
        const PointResult r = run_point(p);
        BOOST_TEST_REQUIRE((r.status == PointStatus::ok), r.message);
        const RunSummary s = run(p.scenario);
        const HysteresisMetrics& m = *s.windup->windup;
        BOOST_TEST(r.figures[column("windup_stiffness_n_m_per_rad")] == m.secant_stiffness_n_per_m);
        BOOST_TEST(r.figures[column("windup_loop_area_j")] == m.loop_area_j);
        BOOST_TEST(r.figures[column("windup_loss_factor")] == m.loss_factor);
        BOOST_TEST(std::isnan(r.figures[column("longitudinal_compliance_m_per_n")]));
        BOOST_TEST(r.figures[column("tangent_vertical_rate_n_per_m")] == s.windup->tangent->vertical_rate_n_per_m);
        BOOST_TEST(r.figures[column("windup_stiffness_n_m_per_rad")] == k, tt::tolerance(1e-9));
        // the message says why the empty figures are empty: the seat is held at w = 0, so the vertical
        // loading has no period and w no loop (not the loop code's "w does not move"); every windup
        // figure that applies is there (decision 076)
        BOOST_TEST(r.message == "no vertical loop: the vertical loading is not periodic");
        // point_figures, the sweep's figures from the records alone, gives the same; the tangent needs
        // the System and the last contact state, so its cell is empty there and the note says why
        std::string note;
        const auto f = point_figures(s.records, p.scenario.simulation, note);
        BOOST_TEST(f[column("windup_stiffness_n_m_per_rad")] == m.secant_stiffness_n_per_m);
        BOOST_TEST(std::isnan(f[column("tangent_vertical_rate_n_per_m")]));
        BOOST_TEST(note.rfind("no tangent vertical rate: from the records alone (point_figures)", 0) == 0, note);
        BOOST_TEST(note.find("; no vertical loop: the vertical loading is not periodic") != std::string::npos, note);
    }
}

// A windup sweep point's files and message (sweep_output.hpp, write_point_files; decision 076): the
// seat held at w = 0 writes its windup loop (t, theta_R, M over the rig's last period: 1 s at dt 10 ms,
// 101 records) and no vertical loop file (w constant: no loop); the seat stroked +-5 mm by the vertical
// rig at the windup rig's 1 Hz writes both, and its message has nothing to explain (both loops, the
// Fancher fit and the tangent there). A ramped seat moment
// (not periodic) has no windup loop: the message names that first, then the vertical loop's absence.
BOOST_AUTO_TEST_CASE(sweep_point_files_and_messages_of_windup_runs) {
    namespace fs = std::filesystem;
    const std::string dir =
        (fs::temp_directory_path() / ("stackbeam_test_windup_point_files_" + std::to_string(::getpid()))).string();
    fs::remove_all(dir);
    for (const char* kind : {"scenarios", "loops"}) fs::create_directories(fs::path(dir) / kind);  // as SweepDirectory does
    auto run_and_write = [&](const Scenario& scenario, int index) {
        SweepPoint point;
        point.index = index;
        point.scenario = scenario;
        point.scenario_text = "# test point\n";
        return run_point(point, nullptr, [&](const PointResult& r) { write_point_files(dir, point, r, false); });
    };
    auto lines = [](const std::string& path) {
        std::ifstream in(path);
        int n = 0;
        for (std::string line; std::getline(in, line);) ++n;
        return n;
    };
    const Scenario held = load_scenario(kWindupFile);
    const PointResult a = run_and_write(held, 0);
    BOOST_TEST_REQUIRE((a.status == PointStatus::ok), a.message);
    BOOST_TEST(a.message == "no vertical loop: the vertical loading is not periodic");
    BOOST_TEST(lines(point_file(dir, "loops", 0, "csv", "-windup")) == 102);  // the header and 101 records
    BOOST_TEST(!fs::exists(point_file(dir, "loops", 0, "csv")));

    Scenario stroked = held;
    TimeFunction& w = stroked.simulation.loading.displacement_m;
    w.shape = TimeFunction::Shape::triangle;
    w.amplitude = 0.005;
    w.frequency_hz = 1.0;
    const PointResult b = run_and_write(stroked, 1);
    BOOST_TEST_REQUIRE((b.status == PointStatus::ok), b.message);
    BOOST_TEST(lines(point_file(dir, "loops", 1, "csv", "-windup")) == 102);
    BOOST_TEST(lines(point_file(dir, "loops", 1, "csv")) == 102);
    BOOST_TEST(b.message == "");

    Scenario ramp = held;  // the seat free vertically, a seat moment ramped to 100 N m over the run
    ramp.simulation.loading = Loading{};
    TimeFunction M;
    M.shape = TimeFunction::Shape::table;
    M.times_s = {0.0, 2.0};
    M.values = {0.0, 100.0};
    ramp.simulation.loading.seat_moment_n_m = M;
    const PointResult c = run_and_write(ramp, 2);
    BOOST_TEST_REQUIRE((c.status == PointStatus::ok), c.message);
    BOOST_TEST(c.message == "no windup loop: no periodic windup rig or seat moment: no steady cycle; "
                            "no vertical loop: the vertical loading is not periodic");
    BOOST_TEST(!fs::exists(point_file(dir, "loops", 2, "csv", "-windup")));
    fs::remove_all(dir);
}

// A windup rig's loop with friction: the two-leaf spring held at w0 = 50 mm by the vertical rig (the
// leaves press on each other; mu = 0.3) and wound +-0.01 rad, 3 cycles. Over a closed steady cycle
// the strain energy returns, so the loop's area (the rig's work) is the cycle's friction work (the
// records' dissipated energy: the balance); the energy loss factor is that area over 2 pi E_s with
// E_s = k_theta theta_a^2 / 2, theta_a the rig's amplitude (reached on the record grid: 25 steps to
// a quarter period). Bounded by the frictionless (no loop) and the bonded spring's k_theta.
BOOST_AUTO_TEST_CASE(friction_windup_loop_area_is_the_friction_work) {
    const double theta_a = 0.01;
    auto loop = [&](const std::string& law, double mu) {
        const std::string interface = "[[interfaces]]\nlaw = \"" + law + "\"\n" +
                                      (law == "coulomb" ? "friction_coefficient = " + std::to_string(mu) + "\n" : "");
        const std::string loading = "[loading]\nkind = \"prescribed-displacement\"\n[loading.displacement_m]\n"
                                    "shape = \"constant\"\nmean = 0.05\n" +
                                    triangle("loading.seat_rotation_rad", theta_a);
        const RunSummary s = run(spring(kTwoLeaves, interface, loading, 3.0));
        BOOST_TEST_REQUIRE(s.windup->windup.has_value(), s.windup->windup_note);
        return *s.windup->windup;
    };
    const HysteresisMetrics m = loop("coulomb", 0.3);
    const double E_s = 0.5 * m.secant_stiffness_n_per_m * theta_a * theta_a;
    BOOST_TEST_MESSAGE("friction windup loop: k_theta " << m.secant_stiffness_n_per_m << " N m/rad, area " << m.loop_area_j
                                                       << " J, friction work " << m.dissipated_j << " J, loss factor "
                                                       << m.loss_factor << ", energy loss factor " << m.energy_loss_factor);
    BOOST_TEST(m.t_start_s == 2.0, tt::tolerance(1e-9));  // the last period
    BOOST_TEST(m.loop_area_j > 1e-3 * m.force_max_n * theta_a);  // a loop, not a line
    BOOST_TEST(m.loop_area_j == m.dissipated_j, tt::tolerance(1e-6));
    BOOST_TEST(m.energy_loss_factor == m.dissipated_j / (2.0 * kPi * E_s), tt::tolerance(1e-6));
    BOOST_TEST(m.loss_factor > 0.0);  // the moment leads the rotation
    const HysteresisMetrics frictionless = loop("coulomb", 0.0), bonded = loop("bonded", 0.0);
    BOOST_TEST(std::abs(frictionless.loop_area_j) < 1e-9 * frictionless.force_max_n * theta_a);
    BOOST_TEST(std::abs(bonded.loop_area_j) < 1e-9 * bonded.force_max_n * theta_a);
    BOOST_TEST(frictionless.secant_stiffness_n_per_m < m.secant_stiffness_n_per_m);
    BOOST_TEST(m.secant_stiffness_n_per_m < bonded.secant_stiffness_n_per_m);
}

// The symmetric spring with pinned eyes (statics, test_windup): k_theta = k_v (L/2)^2 with the seat
// free vertically, k_v the vertical rate. Bonded, so every state is the same state: k_v is the
// vertical rig's secant (its summary's loop; mode closed-form), k_theta the windup rig's (newmark);
// both static and linear on the same mesh, so to rounding.
// A run with both rigs at once gives k_theta and the vertical rate at that same state: with the
// spring symmetric the two do not couple (K_w,theta = 0 to rounding), so they are the same numbers.
BOOST_AUTO_TEST_CASE(symmetric_spring_windup_stiffness_is_the_vertical_rate_times_half_length_squared) {
    const std::string bonded = "[[interfaces]]\nlaw = \"bonded\"\n";
    const std::string vertical = "[loading]\nkind = \"prescribed-displacement\"\n" + triangle("loading.displacement_m", 0.01);
    Scenario rig = spring(kTwoLeaves, bonded, vertical);
    rig.simulation.mode = Mode::closed_form;  // the vertical rig alone: mode closed-form's (massless newmark takes it with the windup rig)
    const RunSummary v = run(rig);
    BOOST_TEST_REQUIRE(v.loop.metrics.has_value(), v.loop.note);
    const double k_v = v.loop.metrics->secant_stiffness_n_per_m;
    const RunSummary w = run(spring(kTwoLeaves, bonded, "[loading]\nkind = \"initial-conditions\"\n" + triangle("loading.seat_rotation_rad", 0.01)));
    BOOST_TEST_REQUIRE(w.windup->windup.has_value(), w.windup->windup_note);
    const double k_theta = w.windup->windup->secant_stiffness_n_per_m, half = 0.5 * kL;
    BOOST_TEST_MESSAGE("k_v " << k_v << " N/m, k_theta " << k_theta << " N m/rad, k_v (L/2)^2 " << k_v * half * half);
    BOOST_TEST(k_theta == k_v * half * half, tt::tolerance(1e-9));
    BOOST_TEST(std::isnan(w.windup->vertical_rate_n_per_m));  // w free: no vertical loop in that run
    const RunSummary both = run(spring(kTwoLeaves, bonded, vertical + triangle("loading.seat_rotation_rad", 0.01)));
    BOOST_TEST_REQUIRE(both.windup->windup.has_value(), both.windup->windup_note);
    BOOST_TEST(both.windup->vertical_rate_n_per_m == k_v, tt::tolerance(1e-9));
    BOOST_TEST(both.windup->windup->secant_stiffness_n_per_m == k_theta, tt::tolerance(1e-9));
}

// The seat's longitudinal compliance: a flat leaf with a hinged left eye (it locates the stack, so the
// seat slides) and a roller at the right, H = 2 kN harmonic at the seat's reference (h = 0): the left
// half carries H axially, u_R = H a / (E A), so the compliance is a / (E A) (static: 'auto' leaves R's
// axial inertia out), to rounding. H at h = 0 does not turn the seat: no windup loop, a note says why.
BOOST_AUTO_TEST_CASE(longitudinal_compliance_is_a_over_EA) {
    Scenario s = load_scenario(kWindupFile);
    s.model.leaves[0].left_support = SupportKind::hinged;
    Loading L;  // the seat free vertically, no rig
    TimeFunction H;
    H.shape = TimeFunction::Shape::harmonic;
    H.amplitude = 2000.0;
    H.frequency_hz = 1.0;
    L.longitudinal_force_n = H;
    s.simulation.loading = L;
    const RunSummary r = run(s);
    BOOST_TEST_REQUIRE(r.windup.has_value());
    BOOST_TEST_REQUIRE(r.windup->longitudinal.has_value(), r.windup->longitudinal_note);
    BOOST_TEST_MESSAGE("compliance " << r.windup->longitudinal_compliance_m_per_n << " m/N, a / EA " << kA / kEA);
    BOOST_TEST(r.windup->longitudinal_compliance_m_per_n == kA / kEA, tt::tolerance(1e-9));
    BOOST_TEST(std::abs(r.windup->longitudinal->loop_area_j) < 1e-9 * 2000.0 * 2000.0 * kA / kEA);
    BOOST_TEST(!r.windup->windup.has_value());
    BOOST_TEST(r.windup->windup_note == "no periodic windup rig or seat moment: no steady cycle");
    const auto j = nlohmann::json::parse(summary_json(r, Model::build(s.model)));
    BOOST_TEST(j.at("windup").at("longitudinal_compliance_m_per_n").get<double>() == r.windup->longitudinal_compliance_m_per_n);
    BOOST_TEST(j.at("windup").at("longitudinal_loop").at("secant_stiffness_n_per_m").get<double>() ==
               r.windup->longitudinal->secant_stiffness_n_per_m);
    BOOST_TEST(j.at("windup").at("stiffness_n_m_per_rad").is_null());
}

// The seat's tangent stiffness at the last record's state (loop_figures.hpp, SeatStiffness). A single
// flat leaf (no pair): each half a beam built in at the seat and pinned at its eye, so with the other
// motion held k_ww = 3 E I (1/a^3 + 1/b^3) (a propped cantilever's end stiffness), k_theta = 3 E I
// (1/a + 1/b), k_w,theta = 3 E I (1/b^2 - 1/a^2) (the moment a unit lift makes at the built-in end,
// opposite on the two halves); condensed with the seat free to turn, the simply supported beam's
// 3 E I L / (a^2 b^2). The seat locates the stack (pinned eyes): no u_R, NaN. Exact elements: 1e-9.
BOOST_AUTO_TEST_CASE(seat_tangent_stiffness_of_a_flat_leaf_is_the_beams) {
    const RunSummary s = run(load_scenario(kWindupFile));
    BOOST_TEST_REQUIRE(s.windup->tangent.has_value(), s.windup->tangent_note);
    const SeatStiffness& t = *s.windup->tangent;
    const double b = kL - kA;
    BOOST_TEST(t.t_s == 2.0, tt::tolerance(1e-12));
    BOOST_TEST(t.stick + t.slip + t.open == 0);
    BOOST_TEST(t.matrix[0][0] == 3.0 * kEI * (1.0 / (kA * kA * kA) + 1.0 / (b * b * b)), tt::tolerance(1e-9));
    BOOST_TEST(t.matrix[1][1] == 3.0 * kEI * (1.0 / kA + 1.0 / b), tt::tolerance(1e-9));
    BOOST_TEST(std::abs(t.matrix[0][1]) == 3.0 * kEI * std::abs(1.0 / (b * b) - 1.0 / (kA * kA)), tt::tolerance(1e-9));
    BOOST_TEST(t.matrix[0][1] == t.matrix[1][0], tt::tolerance(1e-9));
    BOOST_TEST(t.vertical_rate_n_per_m == 3.0 * kEI * kL / (kA * kA * b * b), tt::tolerance(1e-9));
    BOOST_TEST(std::isnan(t.matrix[2][2]));
    BOOST_TEST(std::isnan(t.matrix[0][2]));
    const auto j = nlohmann::json::parse(summary_json(s, Model::build(load_scenario(kWindupFile).model)));
    const auto& js = j.at("windup").at("seat_tangent_stiffness");
    BOOST_TEST(js.at("matrix").at(1).at(1).get<double>() == t.matrix[1][1]);
    BOOST_TEST(js.at("matrix").at(2).at(2).is_null());
    BOOST_TEST(js.at("vertical_rate_n_per_m").get<double>() == t.vertical_rate_n_per_m);
}

// The tangent of a stack: (1) bonded, every pair tied, so with the seat free to turn the vertical rate
// is System::tied_stiffness_n_per_m() (C' condensed, another computation), and k_theta the windup
// rig's secant (linear); both to 1e-9. (2) Frictionless, held at 50 mm and wound: every closed pair
// held normally and free tangentially, the response linear while no pair opens or closes, so
// k_theta is the last step's slope of the moment against the rotation (the records: 1e-6, the
// contact solver's 1e-9 m tolerance on gaps the step moves by ~1e-4 m).
BOOST_AUTO_TEST_CASE(seat_tangent_stiffness_of_a_stack_at_its_state) {
    const std::string tri = triangle("loading.seat_rotation_rad", 0.01);
    const RunSummary bonded = run(spring(kTwoLeaves, "[[interfaces]]\nlaw = \"bonded\"\n",
                                         "[loading]\nkind = \"initial-conditions\"\n" + tri));
    BOOST_TEST_REQUIRE(bonded.windup->tangent.has_value(), bonded.windup->tangent_note);
    const Scenario sb = spring(kTwoLeaves, "[[interfaces]]\nlaw = \"bonded\"\n", "[loading]\nkind = \"initial-conditions\"\n" + tri);
    const double tied = System(Model::build(sb.model)).tied_stiffness_n_per_m();
    BOOST_TEST_MESSAGE("bonded: tangent vertical rate " << bonded.windup->tangent->vertical_rate_n_per_m << " N/m, tied "
                                                        << tied << ", k_theta " << bonded.windup->tangent->matrix[1][1]);
    BOOST_TEST(bonded.windup->tangent->vertical_rate_n_per_m == tied, tt::tolerance(1e-9));
    BOOST_TEST(bonded.windup->tangent->matrix[1][1] == bonded.windup->windup->secant_stiffness_n_per_m, tt::tolerance(1e-9));

    const std::string held = "[loading]\nkind = \"prescribed-displacement\"\n[loading.displacement_m]\nshape = \"constant\"\nmean = 0.05\n";
    const RunSummary free = run(spring(kTwoLeaves, "[[interfaces]]\nlaw = \"coulomb\"\nfriction_coefficient = 0.0\n", held + tri));
    BOOST_TEST_REQUIRE(free.windup->tangent.has_value(), free.windup->tangent_note);
    const auto& r = free.records;
    const std::size_t n = r.size() - 1;
    const double slope = (r[n].seat_moment_n_m - r[n - 1].seat_moment_n_m) / (r[n].seat_rotation_rad - r[n - 1].seat_rotation_rad);
    const SeatStiffness& t = *free.windup->tangent;
    BOOST_TEST_MESSAGE("frictionless: " << t.stick << " stick, " << t.slip << " slip, " << t.open << " open; k_theta "
                                        << t.matrix[1][1] << " N m/rad, last step's slope " << slope << ", states then "
                                        << r[n - 1].n_slip << "/" << r[n].n_slip << " slipping");
    BOOST_TEST(t.slip > 0);
    BOOST_TEST(r[n - 1].n_open == r[n].n_open);  // no pair opened or closed in the last step
    BOOST_TEST(t.matrix[1][1] == slope, tt::tolerance(1e-6));
}
