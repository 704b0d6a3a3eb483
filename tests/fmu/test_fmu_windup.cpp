// The FMU carries windup (docs/fmu.md, "The seat's rotation"; docs/windup.md): the seat's rotation
// in, the moment out, through the FMI 2.0 calls only (fmu_importer.hpp); the reference runs are the
// library's own (stackbeam::simulate, make_stepper).
#define BOOST_TEST_MODULE test_fmu_windup
#include <boost/test/unit_test.hpp>

#include "fmu_importer.hpp"

using namespace stackbeam::fmu_importer;

namespace {

/// The text of `path` with each `from` replaced by its `to` (each must occur), written to a file of
/// its own named after `tag`; returns that file's path.
std::string variant(const std::string& path, const std::vector<std::pair<std::string, std::string>>& edits,
                    const std::string& tag) {
    std::string text = slurp(path);
    for (const auto& [from, to] : edits) {
        const auto at = text.find(from);
        if (at == std::string::npos) throw std::runtime_error("no '" + from + "' in " + path);
        text.replace(at, from.size(), to);
    }
    const fs::path out = fs::temp_directory_path() / ("stackbeam_test_fmu_" + tag + "_" + std::to_string(::getpid()) + ".toml");
    std::ofstream(out) << text;
    return out.string();
}

/// The windup outputs the tests compare, per communication point: the moment, u_R (0 where the seat
/// holds the stack axially: no output), the force and the dissipated energy.
using WindupRow = std::array<double, 4>;

/// Drives instance `c` from t = 0 with the scenario's own seat motion: w(t) (loading.displacement_m)
/// and theta_R(t) (loading.seat_rotation_rad) with their derivatives, at h = dt, `n` steps.
std::vector<WindupRow> drive_windup(const Fmu& f, fmi2Component c, long n) {
    const auto& L = f.scenario.simulation.loading;
    const fmi2ValueReference in[6] = {f.vr("seat.displacement_m"), f.vr("seat.velocity_m_per_s"),
                                      f.vr("seat.acceleration_m_per_s2"), f.vr("seat.rotation_rad"),
                                      f.vr("seat.angular_velocity_rad_per_s"), f.vr("seat.angular_acceleration_rad_per_s2")};
    // u_R where the seat slides (else its slot reads the moment again and is set to 0 below)
    const bool axial = f.has("seat.axial_displacement_m");
    const fmi2ValueReference out[4] = {f.vr("seat.moment_n_m"), f.vr(axial ? "seat.axial_displacement_m" : "seat.moment_n_m"),
                                       f.vr("seat.force_n"), f.vr("spring.dissipated_energy_j")};
    const double dt = f.scenario.simulation.dt_s;
    std::vector<WindupRow> rows;
    auto sample = [&](long i) {
        const double t = static_cast<double>(i) * dt;
        const auto& w = L.displacement_m;
        const auto& th = *L.seat_rotation_rad;
        const double u[6] = {w.value(t), w.derivative(t), w.second_derivative(t),
                             th.value(t), th.derivative(t), th.second_derivative(t)};
        BOOST_REQUIRE_EQUAL(f.api.fmi2SetReal(c, in, 6, u), fmi2OK);
        WindupRow y{};
        BOOST_REQUIRE_MESSAGE(f.api.fmi2GetReal(c, out, 4, y.data()) == fmi2OK, g_last_message);
        if (!axial) y[1] = 0.0;
        rows.push_back(y);
    };
    sample(0);
    for (long i = 0; i < n; ++i) {
        BOOST_REQUIRE_MESSAGE(f.api.fmi2DoStep(c, static_cast<double>(i) * dt, dt, fmi2True) == fmi2OK, g_last_message);
        sample(i + 1);
    }
    return rows;
}

/// The FMU of tests/fmu/windup_rig.toml, made once for the cases that drive it.
const Fmu& windup_fmu() {
    static const Fmu f(FMU_WINDUP_SCENARIO, "windup");
    return f;
}

/// Whether the library's own make_stepper takes scenario `f` as it is (the vertical and the windup
/// rig together): the importer's independent answer to "is the rotation an input?".
bool library_takes(const Fmu& f) {
    try {
        stackbeam::make_stepper(stackbeam::System(stackbeam::Model::build(f.scenario.model)), f.scenario.simulation);
    } catch (const stackbeam::InputError&) {
        return false;
    }
    return true;
}

}  // namespace

// The windup rig through the FMU (tests/fmu/windup_rig.toml: an asymmetric three-leaf spring with
// friction, the seat lifted to 20 mm and wound +-0.01 rad at 2 Hz, mode newmark, massless leaves)
// equals simulate() of the same scenario record for record, bit for bit: the moment (the FMU's is the
// spring's on the seat, minus the record's seat_moment), u_R, the force and the friction work. Why
// bitwise: the stepper reads theta_R and w (and their rates) only at its record times, where the
// FMU's samples are the values set, the scenario's own TimeFunctions at the same times.
BOOST_AUTO_TEST_CASE(the_windup_rig_through_the_fmu_is_simulate_record_for_record) {
    const Fmu& f = windup_fmu();
    BOOST_REQUIRE(library_takes(f));
    for (const char* name : {"seat.rotation_rad", "seat.angular_velocity_rad_per_s", "seat.angular_acceleration_rad_per_s2"})
        BOOST_CHECK_EQUAL(f.desc.by_name(name).causality, "input");
    BOOST_CHECK_EQUAL(f.desc.by_name("seat.rotation_rad").unit, "rad");
    BOOST_CHECK_EQUAL(f.desc.by_name("seat.moment_n_m").unit, "N.m");
    BOOST_CHECK_EQUAL(f.desc.by_name("seat.axial_displacement_m").causality, "output");  // the hinged eye: the seat slides
    BOOST_CHECK_EQUAL(f.desc.output_indices.size(), 7u);
    const stackbeam::SimulationOptions& so = f.scenario.simulation;
    const auto ref = stackbeam::simulate(stackbeam::System(stackbeam::Model::build(f.scenario.model)), so);
    fmi2Component c = started(f, "windup");
    const auto o = drive_windup(f, c, static_cast<long>(ref.size()) - 1);
    BOOST_REQUIRE_EQUAL(o.size(), ref.size());
    double peak = 0.0;
    for (std::size_t i = 0; i < ref.size(); ++i) {
        BOOST_REQUIRE_MESSAGE(o[i][0] == -ref[i].seat_moment_n_m,
                              "record " << i << ": moment " << o[i][0] << " vs " << -ref[i].seat_moment_n_m);
        BOOST_REQUIRE_EQUAL(o[i][1], ref[i].seat_axial_m);
        BOOST_REQUIRE_EQUAL(o[i][2], -ref[i].spring_force_n);
        BOOST_REQUIRE_EQUAL(o[i][3], ref[i].dissipated_energy_j);
        peak = std::max(peak, std::abs(ref[i].seat_moment_n_m));
    }
    // not a comparison of zeros: the rig winds the spring (hundreds of N m), friction works, u_R moves
    BOOST_CHECK_GT(peak, 100.0);
    BOOST_CHECK_GT(ref.back().dissipated_energy_j, 0.1);
    BOOST_CHECK_GT(std::abs(ref[125].seat_axial_m), 1e-5);
    f.api.fmi2FreeInstance(c);
}

// Leaf mass (newmark-massive, elastic interfaces): tests/fmu/rig_leaf_mass.toml on the full model,
// the seat also turned from rest (a harmonic from rest, 0.008 rad peak at 8 Hz), through
// the FMU against simulate(): the stepper now reads theta_R' and theta_R'' too (the leaves' inertial
// load). Equal to simulate() but for one input: the FMU takes the importer's rate at the start,
// cos(-pi/2) 2 pi f A = 1.2e-17 rad/s, as the rest it must be (0), where simulate() keeps the
// shape's rounding. Measured: bit for bit all the same (0 of 6.6 N m and of 109 N; the run starts at
// rest from the start stage's state). The bound, 1e-9 of the peak moment and force, is that rounding
// carried through the linear steps, should a stepper read the start's rate.
BOOST_AUTO_TEST_CASE(leaf_mass_windup_through_the_fmu_is_simulate_to_rounding) {
    const std::string path = variant(FMU_LEAF_MASS_SCENARIO,
                                     {{"symmetry = \"half\"", "symmetry = \"full\""},
                                      {"\n[mesh]", "[loading.seat_rotation_rad]\nshape = \"harmonic\"\nmean = 0.004\n"
                                                    "amplitude = 0.004\nfrequency_hz = 8.0\nphase_rad = -1.5707963267948966\n\n[mesh]"}},
                                     "windup_leaf_mass");
    const Fmu f(path, "windup_leaf_mass");
    fs::remove(path);
    BOOST_REQUIRE(f.has("seat.rotation_rad"));
    BOOST_CHECK(!f.has("seat.axial_displacement_m"));  // pinned ends: the seat holds the stack axially
    const stackbeam::SimulationOptions& so = f.scenario.simulation;
    const auto ref = stackbeam::simulate(stackbeam::System(stackbeam::Model::build(f.scenario.model)), so);
    fmi2Component c = started(f, "windup_leaf_mass");
    const auto o = drive_windup(f, c, static_cast<long>(ref.size()) - 1);
    BOOST_REQUIRE_EQUAL(o.size(), ref.size());
    double dm = 0.0, df = 0.0, pm = 0.0, pf = 0.0;
    for (std::size_t i = 0; i < ref.size(); ++i) {
        dm = std::max(dm, std::abs(o[i][0] + ref[i].seat_moment_n_m));
        df = std::max(df, std::abs(o[i][2] + ref[i].spring_force_n));
        pm = std::max(pm, std::abs(ref[i].seat_moment_n_m));
        pf = std::max(pf, std::abs(ref[i].spring_force_n));
    }
    BOOST_TEST_MESSAGE("leaf mass windup through the FMU: max |moment - simulate| = " << dm << " of " << pm
                                                                                     << " N m, force " << df << " of " << pf << " N");
    BOOST_CHECK_GT(pm, 1.0);  // the rig winds the spring (measured 6 N m), not zeros
    BOOST_CHECK_LE(dm, 1e-9 * pm);
    BOOST_CHECK_LE(df, 1e-9 * pf);
    f.api.fmi2FreeInstance(c);
}

// The windup stiffness read through the FMU: a single prismatic leaf, pinned ends at 0 and 1.2 m,
// the seat at a = 0.5 m (b = 0.7 m) held vertically at w = 0 and turned by a small step theta = 1e-4
// rad in one communication step: each half is a propped cantilever turned at its built-in end, so
// the seat's moment is 3 E I (1/a + 1/b) theta (statics of the Bernoulli-Euler beam). The cubic
// Hermite element is exact for nodal loads on a prismatic leaf (the seat is a node), so the figure is
// the closed form to rounding: relative 1e-9 (test_windup's bound for the same check).
BOOST_AUTO_TEST_CASE(a_small_rotation_step_gives_the_single_leafs_windup_stiffness) {
    const double L = 1.2, t = 0.01, b_w = 0.05, E = 206e9, a = 0.5, b = L - a, theta = 1e-4;
    const double EI = E * b_w * t * t * t / 12.0;
    std::ostringstream text;
    text << "[[leaves]]\nlength_m = " << L << "\nheight_m = " << t << "\nwidth_m = " << b_w
         << "\nyoungs_modulus_pa = " << E << "\nleft_support = \"pinned\"\nright_support = \"pinned\"\n\n"
         << "[rigid_body]\nmass_kg = 1.0\nx_m = " << a << "\n\n[loading]\nkind = \"prescribed-displacement\"\n"
         << "[loading.displacement_m]\nshape = \"constant\"\nmean = 0.0\n[loading.seat_rotation_rad]\nshape = \"table\"\n"
         << "times_s = [0.0, 1.0]\nvalues = [0.0, 0.0]\n\n[mesh]\nelement_length_m = 0.05\nsymmetry = \"full\"\n\n"
         << "[integrator]\nmode = \"newmark\"\ndt_s = 0.1\nt_end_s = 1.0\n";
    const fs::path path = fs::temp_directory_path() / ("stackbeam_test_fmu_leaf_" + std::to_string(::getpid()) + ".toml");
    std::ofstream(path) << text.str();
    const Fmu f(path.string(), "leaf");
    fs::remove(path);
    BOOST_REQUIRE(f.has("seat.rotation_rad"));
    BOOST_CHECK(!f.has("seat.axial_displacement_m"));  // pinned ends: the seat holds the stack axially
    fmi2Component c = started(f, "leaf");
    const fmi2ValueReference rot = f.vr("seat.rotation_rad"), moment = f.vr("seat.moment_n_m");
    BOOST_REQUIRE_EQUAL(f.api.fmi2DoStep(c, 0.0, 0.1, fmi2True), fmi2OK);
    BOOST_REQUIRE_EQUAL(f.api.fmi2SetReal(c, &rot, 1, &theta), fmi2OK);
    double M = 0.0;
    BOOST_REQUIRE_MESSAGE(f.api.fmi2GetReal(c, &moment, 1, &M) == fmi2OK, g_last_message);
    const double k = 3.0 * EI * (1.0 / a + 1.0 / b);
    BOOST_TEST_MESSAGE("windup stiffness through the FMU " << -M / theta << " N m/rad, 3 E I (1/a + 1/b) = " << k);
    // the spring's moment on the seat turns it back: -k theta
    BOOST_CHECK_CLOSE(-M / theta, k, 1e-7);  // percent: 1e-9 relative
    f.api.fmi2FreeInstance(c);
}

// Get/set state with the rotation: step on, restore, step again with the same inputs: the same
// moments bit for bit (the state is the inputs' history, the rotation's included, replayed from t = 0);
// also through the serialised state.
BOOST_AUTO_TEST_CASE(restoring_a_state_repeats_the_windup_outputs_bit_for_bit) {
    const Fmu& f = windup_fmu();
    const auto& th = *f.scenario.simulation.loading.seat_rotation_rad;
    const auto& w = f.scenario.simulation.loading.displacement_m;
    fmi2Component c = started(f, "state");
    drive_windup(f, c, 100);  // to t = 0.1 s
    fmi2FMUstate saved = nullptr, copy = nullptr;
    BOOST_REQUIRE_EQUAL(f.api.fmi2GetFMUstate(c, &saved), fmi2OK);
    std::size_t size = 0;
    BOOST_REQUIRE_EQUAL(f.api.fmi2SerializedFMUstateSize(c, saved, &size), fmi2OK);
    std::vector<fmi2Byte> bytes(size);
    BOOST_REQUIRE_EQUAL(f.api.fmi2SerializeFMUstate(c, saved, bytes.data(), size), fmi2OK);
    BOOST_REQUIRE_EQUAL(f.api.fmi2DeSerializeFMUstate(c, bytes.data(), size, &copy), fmi2OK);
    const fmi2ValueReference in[2] = {f.vr("seat.displacement_m"), f.vr("seat.rotation_rad")};
    const fmi2ValueReference out[2] = {f.vr("seat.moment_n_m"), f.vr("spring.dissipated_energy_j")};
    auto go = [&](double scale, long from) {  // the rotation scaled by `scale` from t = from dt on
        std::vector<double> y;
        for (long i = from; i < from + 150; ++i) {
            BOOST_REQUIRE_MESSAGE(f.api.fmi2DoStep(c, i * 1e-3, 1e-3, fmi2False) == fmi2OK, g_last_message);
            const double t = (i + 1) * 1e-3, u[2] = {w.value(t), scale * th.value(t)};
            f.api.fmi2SetReal(c, in, 2, u);
            double v[2];
            BOOST_REQUIRE_EQUAL(f.api.fmi2GetReal(c, out, 2, v), fmi2OK);
            y.insert(y.end(), v, v + 2);
        }
        return y;
    };
    const std::vector<double> first = go(1.0, 100);
    const std::vector<double> other = go(-1.0, 250);  // on elsewhere, wound the other way
    BOOST_CHECK(other != std::vector<double>(first.begin(), first.end()));
    BOOST_REQUIRE_EQUAL(f.api.fmi2SetFMUstate(c, saved), fmi2OK);
    BOOST_CHECK(go(1.0, 100) == first);
    BOOST_REQUIRE_EQUAL(f.api.fmi2SetFMUstate(c, copy), fmi2OK);
    BOOST_CHECK(go(1.0, 100) == first);
    // a different rotation history from the restored state gives different moments: the rotation is read
    BOOST_REQUIRE_EQUAL(f.api.fmi2SetFMUstate(c, saved), fmi2OK);
    BOOST_CHECK(go(0.5, 100) != first);
    f.api.fmi2FreeFMUstate(c, &saved);
    f.api.fmi2FreeFMUstate(c, &copy);
    f.api.fmi2FreeInstance(c);
}

// The rotation is an input exactly where the library's own stepper of the scenario takes the windup
// rig with the vertical rig (decided by make_stepper, i.e. the stepper registry's windup_rig row, not
// by mode name): the windup scenario under each mode, and the half model. Where it is not, the XML
// has no rotation, moment or u_R, the model description says why (the library's message, naming
// loading.seat_rotation_rad), and setting the rotation's value reference is refused with that reason.
BOOST_AUTO_TEST_CASE(the_rotation_is_an_input_exactly_where_the_scenarios_stepper_takes_the_windup_rig) {
    for (const char* mode : {"closed-form", "newmark", "cvode"}) {
        std::unique_ptr<Fmu> other;  // the scenario's own mode is newmark: its FMU is windup_fmu()
        if (std::string(mode) != "newmark") {
            const std::string path = variant(FMU_WINDUP_SCENARIO, {{"mode = \"newmark\"", std::string("mode = \"") + mode + "\""}},
                                             std::string("windup_") + mode);
            other = std::make_unique<Fmu>(path, std::string("windup_mode_") + mode);
            fs::remove(path);
        }
        const Fmu& f = other ? *other : windup_fmu();
        const bool takes = library_takes(f);
        BOOST_TEST_MESSAGE("mode " << mode << ": the windup rig with the vertical rig " << (takes ? "taken" : "refused"));
        BOOST_CHECK_EQUAL(f.has("seat.rotation_rad"), takes);
        BOOST_CHECK_EQUAL(f.has("seat.angular_velocity_rad_per_s"), takes);
        BOOST_CHECK_EQUAL(f.has("seat.moment_n_m"), takes);
        BOOST_CHECK_EQUAL(f.has("seat.axial_displacement_m"), takes);
        BOOST_CHECK_EQUAL(f.desc.description.find("loading.seat_rotation_rad") != std::string::npos, !takes);
    }
    // the half model (rig_leaf_mass.toml, mode newmark, whose stepper takes the windup rig): refused
    // by the library by name (loading.seat_rotation_rad on mesh.symmetry = 'half'), so no rotation
    const Fmu half(FMU_LEAF_MASS_SCENARIO, "windup_half");
    BOOST_CHECK(!half.has("seat.rotation_rad"));
    BOOST_CHECK(!half.has("seat.moment_n_m"));
    BOOST_CHECK(half.desc.description.find("not an input of this FMU") != std::string::npos);
    BOOST_CHECK_MESSAGE(half.desc.description.find("half model") != std::string::npos, half.desc.description);
    fmi2Component c = started(half, "half");
    const fmi2ValueReference rot = 4;  // the rotation's value reference in an FMU that has it
    const double theta = 0.01;
    BOOST_CHECK_EQUAL(half.api.fmi2SetReal(c, &rot, 1, &theta), fmi2Error);
    BOOST_CHECK_MESSAGE(g_last_message.find("not an input of this FMU") != std::string::npos, g_last_message);
    BOOST_CHECK_MESSAGE(g_last_message.find("half model") != std::string::npos, g_last_message);
    half.api.fmi2FreeInstance(c);
}

// Bad rotation input: a start away from the unwound seat is refused when the run starts (the spring
// starts unwound: theta_R(0) = 0), naming the input; a rotation that is not finite at once.
BOOST_AUTO_TEST_CASE(bad_rotation_inputs_are_refused_by_name) {
    const Fmu& f = windup_fmu();
    fmi2Component c = f.instantiate("bad");
    BOOST_REQUIRE(c != nullptr);
    BOOST_REQUIRE_EQUAL(f.api.fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK);
    BOOST_REQUIRE_EQUAL(f.api.fmi2EnterInitializationMode(c), fmi2OK);
    const fmi2ValueReference rot = f.vr("seat.rotation_rad");
    const double start = 0.002, nan = NAN;
    BOOST_REQUIRE_EQUAL(f.api.fmi2SetReal(c, &rot, 1, &start), fmi2OK);
    BOOST_CHECK_EQUAL(f.api.fmi2ExitInitializationMode(c), fmi2Error);
    BOOST_CHECK_MESSAGE(g_last_message.find("seat.rotation_rad = 0.002") != std::string::npos, g_last_message);
    BOOST_CHECK_MESSAGE(g_last_message.find("unwound") != std::string::npos, g_last_message);
    BOOST_CHECK_EQUAL(f.api.fmi2SetReal(c, &rot, 1, &nan), fmi2Error);
    BOOST_CHECK_MESSAGE(g_last_message.find("finite") != std::string::npos, g_last_message);
    const double zero = 0.0;  // from 0 the run starts
    BOOST_REQUIRE_EQUAL(f.api.fmi2SetReal(c, &rot, 1, &zero), fmi2OK);
    BOOST_CHECK_MESSAGE(f.api.fmi2ExitInitializationMode(c) == fmi2OK, g_last_message);
    f.api.fmi2FreeInstance(c);
}
