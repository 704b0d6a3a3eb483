// The FMU as an importer sees it (issue 45; docs/fmu.md): a C++ harness that makes an FMU with
// `stackbeam fmu`, opens the archive with libzip into a fresh directory (the "clean system": only
// the FMU's files, no stackbeam installed), reads modelDescription.xml with expat, dlopen()s the
// binary and drives it through the FMI 2.0 calls only. It shares no code with the exporter or the
// FMU (only the standard's declarations, fmu/include/fmi2*.h); the reference runs are the library's
// own (stackbeam::simulate, make_stepper), linked here as any user of the library would.
#define BOOST_TEST_MODULE test_fmu
#include <boost/test/unit_test.hpp>

#include "fmu_importer.hpp"

using namespace stackbeam::fmu_importer;

BOOST_AUTO_TEST_CASE(every_required_function_is_exported_and_the_versions_match) {
    const Fmu& f = fmu();
    for (const auto& name : kRequired) BOOST_CHECK_MESSAGE(dlsym(f.api.handle, name.c_str()) != nullptr, name);
    BOOST_CHECK_EQUAL(std::string(f.api.fmi2GetVersion()), "2.0");
    BOOST_CHECK_EQUAL(std::string(f.api.fmi2GetTypesPlatform()), "default");
    BOOST_CHECK_EQUAL(f.desc.fmi_version, "2.0");
    BOOST_CHECK_EQUAL(f.desc.cosim.at("canGetAndSetFMUstate"), "true");
    BOOST_CHECK_EQUAL(f.desc.cosim.at("canHandleVariableCommunicationStepSize"), "true");
    // the scenario's resources are in the archive, as the binary reads them
    BOOST_CHECK(fs::exists(f.dir / "unpacked" / "resources" / "scenario.toml"));
}

BOOST_AUTO_TEST_CASE(the_xml_variables_answer_the_calls_with_their_start_values_and_units) {
    const Fmu& f = fmu();
    // the scenario's spring: 2 interfaces, 4 clamps -> 2 + 4 parameters beside the step
    BOOST_CHECK_EQUAL(f.desc.variables.size(), 3u + 5u + 2u + 2u + 4u);
    fmi2Component c = f.instantiate();
    BOOST_REQUIRE(c != nullptr);
    BOOST_REQUIRE_EQUAL(f.api.fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK);
    BOOST_REQUIRE_EQUAL(f.api.fmi2EnterInitializationMode(c), fmi2OK);
    std::set<unsigned> vrs;
    for (const auto& v : f.desc.variables) {
        BOOST_CHECK_MESSAGE(vrs.insert(v.vr).second, "value reference " << v.vr << " given twice");
        BOOST_CHECK_MESSAGE(!v.unit.empty(), v.name << " has no unit");
        double x = NAN;
        BOOST_CHECK_MESSAGE(f.api.fmi2GetReal(c, &v.vr, 1, &x) == fmi2OK, v.name << ": " << g_last_message);
        if (v.has_start) BOOST_CHECK_MESSAGE(x == v.start, v.name << " = " << x << ", start " << v.start);
        if (v.causality == "output") BOOST_CHECK_MESSAGE(std::isfinite(x), v.name);
    }
    BOOST_CHECK_EQUAL(f.desc.by_name("interfaces[0].friction_coefficient").start, 0.5);
    BOOST_CHECK_EQUAL(f.desc.by_name("clamps[3].preload_n").start, 1000.0);
    BOOST_CHECK_EQUAL(f.desc.by_name("integrator.dt_s").start, f.scenario.simulation.dt_s);
    BOOST_CHECK_EQUAL(f.desc.by_name("seat.max_stroke_m").start, 0.02);  // the rig's +-20 mm stroke
    BOOST_CHECK_EQUAL(f.desc.by_name("seat.max_stroke_m").unit, "m");
    BOOST_CHECK_EQUAL(f.desc.output_indices.size(), 5u);
    // no Integer variables: a request for one is refused
    const fmi2ValueReference one = 1;
    fmi2Integer i = 0;
    BOOST_CHECK_EQUAL(f.api.fmi2GetInteger(c, &one, 1, &i), fmi2Error);
    f.api.fmi2FreeInstance(c);
}

BOOST_AUTO_TEST_CASE(calls_out_of_order_and_bad_values_are_refused_with_a_message) {
    const Fmu& f = fmu();
    // a wrong GUID: no instance, the cause logged
    BOOST_CHECK(f.api.fmi2Instantiate("x", fmi2CoSimulation, "{wrong}", f.resources_uri.c_str(), &kCallbacks, 0, 0) == nullptr);
    BOOST_CHECK(g_last_message.find("fmuGUID") != std::string::npos);
    BOOST_CHECK(f.api.fmi2Instantiate("x", fmi2ModelExchange, f.desc.guid.c_str(), f.resources_uri.c_str(), &kCallbacks, 0, 0) == nullptr);
    BOOST_CHECK(f.api.fmi2Instantiate("x", fmi2CoSimulation, f.desc.guid.c_str(), "file:///nonexistent", &kCallbacks, 0, 0) == nullptr);

    fmi2Component c = f.instantiate();
    BOOST_REQUIRE(c != nullptr);
    const fmi2ValueReference force = f.vr("seat.force_n"), mu = f.vr("interfaces[0].friction_coefficient");
    double x = 0.0;
    BOOST_CHECK_EQUAL(f.api.fmi2DoStep(c, 0.0, 1e-3, fmi2True), fmi2Error);  // not initialised
    BOOST_CHECK(g_last_message.find("not allowed in state 'instantiated'") != std::string::npos);
    BOOST_CHECK_EQUAL(f.api.fmi2ExitInitializationMode(c), fmi2Error);
    BOOST_CHECK_EQUAL(f.api.fmi2GetReal(c, &force, 1, &x), fmi2Error);
    // a bad parameter value: refused, named as the scenario names it
    const double bad = -0.5;
    BOOST_CHECK_EQUAL(f.api.fmi2SetReal(c, &mu, 1, &bad), fmi2Error);
    BOOST_CHECK_MESSAGE(g_last_message.find("friction_coefficient") != std::string::npos &&
                            g_last_message.find("-0.5") != std::string::npos, g_last_message);
    const fmi2ValueReference dt = f.vr("integrator.dt_s");
    const double zero = 0.0;
    BOOST_CHECK_EQUAL(f.api.fmi2SetReal(c, &dt, 1, &zero), fmi2Error);
    BOOST_CHECK_MESSAGE(g_last_message.find("integrator.dt_s") != std::string::npos, g_last_message);
    const fmi2ValueReference stroke = f.vr("seat.max_stroke_m");
    BOOST_CHECK_EQUAL(f.api.fmi2SetReal(c, &stroke, 1, &zero), fmi2Error);
    BOOST_CHECK_MESSAGE(g_last_message.find("seat.max_stroke_m = 0") != std::string::npos &&
                            g_last_message.find("> 0 m") != std::string::npos, g_last_message);
    const double nan = NAN;
    const fmi2ValueReference w = f.vr("seat.displacement_m");
    BOOST_CHECK_EQUAL(f.api.fmi2SetReal(c, &w, 1, &nan), fmi2Error);

    BOOST_REQUIRE_EQUAL(f.api.fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK);
    BOOST_CHECK_EQUAL(f.api.fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK);  // again, still instantiated
    BOOST_REQUIRE_EQUAL(f.api.fmi2EnterInitializationMode(c), fmi2OK);
    BOOST_CHECK_EQUAL(f.api.fmi2EnterInitializationMode(c), fmi2Error);
    BOOST_CHECK_EQUAL(f.api.fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2Error);
    BOOST_REQUIRE_EQUAL(f.api.fmi2ExitInitializationMode(c), fmi2OK);
    const double half = 0.3;
    BOOST_CHECK_EQUAL(f.api.fmi2SetReal(c, &mu, 1, &half), fmi2Error);  // fixed parameter after initialisation
    // the communication point and step: the FMU's time, a whole number of its dt
    BOOST_CHECK_EQUAL(f.api.fmi2DoStep(c, 0.5, 1e-3, fmi2True), fmi2Error);
    BOOST_CHECK(g_last_message.find("currentCommunicationPoint") != std::string::npos);
    BOOST_CHECK_EQUAL(f.api.fmi2DoStep(c, 0.0, 1.5e-3, fmi2True), fmi2Error);
    BOOST_CHECK(g_last_message.find("communicationStepSize") != std::string::npos);
    BOOST_CHECK_EQUAL(f.api.fmi2DoStep(c, 0.0, -1e-3, fmi2True), fmi2Error);
    BOOST_CHECK_EQUAL(f.api.fmi2DoStep(c, 0.0, 2e-3, fmi2True), fmi2OK);  // variable step: 2 dt, then 1 dt
    BOOST_CHECK_EQUAL(f.api.fmi2DoStep(c, 2e-3, 1e-3, fmi2True), fmi2OK);
    double t = 0.0;
    BOOST_CHECK_EQUAL(f.api.fmi2GetRealStatus(c, fmi2LastSuccessfulTime, &t), fmi2OK);
    BOOST_CHECK_CLOSE(t, 3e-3, 1e-9);
    BOOST_CHECK_EQUAL(f.api.fmi2CancelStep(c), fmi2Error);
    BOOST_CHECK_EQUAL(f.api.fmi2Terminate(c), fmi2OK);
    BOOST_CHECK_EQUAL(f.api.fmi2DoStep(c, 3e-3, 1e-3, fmi2True), fmi2Error);
    BOOST_CHECK_EQUAL(f.api.fmi2Terminate(c), fmi2Error);
    BOOST_CHECK_EQUAL(f.api.fmi2GetReal(c, &force, 1, &x), fmi2OK);  // outputs readable after terminate
    // reset: back to instantiated, the parameters at their start values, and it runs again
    BOOST_CHECK_EQUAL(f.api.fmi2Reset(c), fmi2OK);
    BOOST_CHECK_EQUAL(f.api.fmi2GetReal(c, &mu, 1, &x), fmi2Error);  // instantiated: no getters
    BOOST_REQUIRE_EQUAL(f.api.fmi2EnterInitializationMode(c), fmi2OK);
    BOOST_CHECK_EQUAL(f.api.fmi2GetReal(c, &mu, 1, &x), fmi2OK);
    BOOST_CHECK_EQUAL(x, 0.5);
    f.api.fmi2FreeInstance(c);
    f.api.fmi2FreeInstance(nullptr);  // allowed, does nothing
}

// The rig stroke through the FMU at the scenario's step is `stackbeam simulate` of the rig
// scenario: the FMU's stepper is the scenario's (closed-form) stepper and its seat displacement
// at each record time is the value the importer set, which is the triangle's value at that time
// computed by the same TimeFunction: the same operations on the same doubles, so the records are
// equal bit for bit (not within a tolerance).
BOOST_AUTO_TEST_CASE(a_rig_stroke_through_the_fmu_is_simulate_record_for_record) {
    const Fmu& f = fmu();
    stackbeam::SimulationOptions so = f.scenario.simulation;
    so.t_end_s = 0.6;  // past the first turning point (0.25 s) and the second (0.75 s: not needed)
    const stackbeam::System system(stackbeam::Model::build(f.scenario.model));
    const std::vector<stackbeam::StepRecord> ref = stackbeam::simulate(system, so);
    fmi2Component c = started(f);
    const Outputs o = drive(f, c, so.dt_s, static_cast<long>(ref.size()) - 1);
    require_records_equal(o, ref);
    BOOST_CHECK_GT(ref.back().dissipated_energy_j, 0.0);  // friction worked: the comparison is not of zeros
    // the largest leaf stress: the library's Stepper::stresses() of the same run, at a few records
    auto stepper = stackbeam::make_stepper(system, so);
    fmi2Component c2 = started(f, "stress");
    // 0.05 s = 50 dt: records 0, 50, ..., 200, on the stroke's first rise (to 0.25 s), where the
    // FMU's linear interpolation of the seat between communication points is the triangle itself
    const Outputs s = drive(f, c2, 0.05, 4, 1.0, true);
    for (long k = 0; k <= 4; ++k) {
        while (stepper->record_index() < 50 * k) stepper->advance();
        double m = 0.0;
        for (const auto& leaf : stepper->stresses().leaves) {
            for (double x : leaf.top_stress_pa) m = std::max(m, std::abs(x));
            for (double x : leaf.bottom_stress_pa) m = std::max(m, std::abs(x));
        }
        // the same stress recovery of the same state: equal but for the rounding of the interpolated
        // seat displacement at the records between communication points (1e-12 relative, far below)
        BOOST_CHECK_CLOSE(s.rows[k][4], m, 1e-10);
        if (k > 0) BOOST_CHECK_GT(m, 1e6);   // a 20 mm stroke stresses the leaves (MPa)
    }
    f.api.fmi2FreeInstance(c);
    f.api.fmi2FreeInstance(c2);
}

// Get/set state: step on, restore an earlier state, step again: the same outputs bit for bit
// (the FMU replays the inputs' history from t = 0: the same operations on the same doubles).
BOOST_AUTO_TEST_CASE(restoring_an_earlier_state_repeats_the_outputs_bit_for_bit) {
    const Fmu& f = fmu();
    fmi2Component c = started(f);
    drive(f, c, 1e-3, 100);  // to t = 0.1 s
    fmi2FMUstate saved = nullptr;
    BOOST_REQUIRE_EQUAL(f.api.fmi2GetFMUstate(c, &saved), fmi2OK);
    // serialise and read back: a second copy of the same state
    std::size_t size = 0;
    BOOST_REQUIRE_EQUAL(f.api.fmi2SerializedFMUstateSize(c, saved, &size), fmi2OK);
    std::vector<fmi2Byte> bytes(size);
    BOOST_REQUIRE_EQUAL(f.api.fmi2SerializeFMUstate(c, saved, bytes.data(), size), fmi2OK);
    fmi2FMUstate copy = nullptr;
    BOOST_REQUIRE_EQUAL(f.api.fmi2DeSerializeFMUstate(c, bytes.data(), size, &copy), fmi2OK);
    BOOST_CHECK_EQUAL(f.api.fmi2DeSerializeFMUstate(c, bytes.data(), size / 2, &copy), fmi2Error);  // truncated

    // on from t = 0.1 s with a different stroke (scale 0.5) ...
    const auto& w = f.scenario.simulation.loading.displacement_m;
    const fmi2ValueReference in = f.vr("seat.displacement_m"), out[2] = {f.vr("seat.force_n"), f.vr("spring.dissipated_energy_j")};
    auto go = [&](double scale, long from) {
        std::vector<double> y;
        for (long i = from; i < from + 150; ++i) {
            BOOST_REQUIRE_MESSAGE(f.api.fmi2DoStep(c, i * 1e-3, 1e-3, fmi2False) == fmi2OK, g_last_message);
            const double u = scale * w.value((i + 1) * 1e-3);
            f.api.fmi2SetReal(c, &in, 1, &u);
            double v[2];
            BOOST_REQUIRE_EQUAL(f.api.fmi2GetReal(c, out, 2, v), fmi2OK);
            y.insert(y.end(), v, v + 2);
        }
        return y;
    };
    const std::vector<double> first = go(1.0, 100);
    go(0.5, 250);  // ... and on elsewhere to t = 0.4 s
    BOOST_REQUIRE_EQUAL(f.api.fmi2SetFMUstate(c, saved), fmi2OK);
    BOOST_CHECK(go(1.0, 100) == first);
    BOOST_REQUIRE_EQUAL(f.api.fmi2SetFMUstate(c, copy), fmi2OK);
    BOOST_CHECK(go(1.0, 100) == first);
    BOOST_CHECK_EQUAL(f.api.fmi2FreeFMUstate(c, &saved), fmi2OK);
    BOOST_CHECK(saved == nullptr);
    BOOST_CHECK_EQUAL(f.api.fmi2FreeFMUstate(c, &copy), fmi2OK);
    f.api.fmi2FreeInstance(c);
}

// Several instances in one process, each on its own thread: the same outputs as one after the other.
BOOST_AUTO_TEST_CASE(two_instances_on_two_threads_give_the_outputs_of_one_after_the_other) {
    const Fmu& f = fmu();
    auto run = [&](const char* name, double scale) {
        fmi2Component c = started(f, name);
        Outputs o = drive(f, c, 2e-3, 150, scale);
        f.api.fmi2FreeInstance(c);
        return o.rows;
    };
    const auto a = run("a", 1.0), b = run("b", 0.5);
    std::vector<std::array<double, 5>> ta, tb;
    std::thread t1([&] { ta = run("ta", 1.0); }), t2([&] { tb = run("tb", 0.5); });
    t1.join();
    t2.join();
    BOOST_CHECK(ta == a);
    BOOST_CHECK(tb == b);
    BOOST_CHECK(a != b);
}

// The binary runs where stackbeam is not installed: it was loaded above from a fresh directory
// holding only the FMU's files; its dynamic dependencies (ldd) are the system libraries
// docs/fmu.md lists ("What the FMU needs on the importer's machine"), none of stackbeam's.
BOOST_AUTO_TEST_CASE(the_binary_needs_only_the_system_libraries_the_docs_list) {
    const Fmu& f = fmu();
    const fs::path so = f.dir / "unpacked" / "binaries" / "linux64" / (f.desc.model_identifier + ".so");
    const std::string cmd = "ldd " + so.string();
    FILE* p = popen(cmd.c_str(), "r");
    BOOST_REQUIRE(p != nullptr);
    std::string text;
    char buf[512];
    while (std::fgets(buf, sizeof buf, p)) text += buf;
    pclose(p);
    BOOST_TEST_MESSAGE(text);
    // the allowed list, as docs/fmu.md gives it (prefixes of the sonames)
    const std::vector<std::string> allowed = {
        "linux-vdso", "/lib64/ld-linux-x86-64", "libc.so", "libm.so", "libsundials_", "libcholmod", "libklu",
        "libamd", "libcamd", "libcolamd", "libccolamd", "libbtf", "libsuitesparseconfig", "libmetis", "liblapack",
        "libblas", "libopenblas", "libatlas", "libgfortran", "libquadmath", "libgomp", "libgcc_s", "libstdc++", "libz"};
    std::istringstream lines(text);
    std::string line;
    int n = 0;
    while (std::getline(lines, line)) {
        std::istringstream ls(line);
        std::string name;
        ls >> name;
        if (name.empty()) continue;
        ++n;
        BOOST_CHECK_MESSAGE(line.find("not found") == std::string::npos, line);
        BOOST_CHECK_MESSAGE(line.find("stackbeam") == std::string::npos || line.find(so.string()) != std::string::npos, line);
        bool ok = false;
        for (const auto& a : allowed) ok = ok || name.rfind(a, 0) == 0;
        BOOST_CHECK_MESSAGE(ok, "not in docs/fmu.md's list: " << line);
    }
    BOOST_CHECK_GT(n, 3);
}

namespace {

/// The seat's mass m on the FMU's spring, the supports moving by y_b(t) (base excitation), integrated
/// here in the supports' frame with the velocity Verlet scheme at the communication step h (= the
/// FMU's dt): m w'' = F(w) - m y_b''(t), F the FMU's force on the seat, evaluated at the new w
/// (the FMU's outputs depend directly on its inputs). Returns w at every communication point.
std::vector<double> coupled_mass(const Fmu& f, const stackbeam::TimeFunction& yb, double mass_kg, double h, double t_end) {
    fmi2Component c = f.instantiate("mass");
    BOOST_REQUIRE(c != nullptr);
    BOOST_REQUIRE_EQUAL(f.api.fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2True, t_end), fmi2OK);
    BOOST_REQUIRE_EQUAL(f.api.fmi2EnterInitializationMode(c), fmi2OK);
    const fmi2ValueReference dt = f.vr("integrator.dt_s"), in[2] = {f.vr("seat.displacement_m"), f.vr("seat.velocity_m_per_s")},
                             force = f.vr("seat.force_n");
    BOOST_REQUIRE_EQUAL(f.api.fmi2SetReal(c, &dt, 1, &h), fmi2OK);
    BOOST_REQUIRE_EQUAL(f.api.fmi2ExitInitializationMode(c), fmi2OK);
    const long n = std::lround(t_end / h);
    // R at rest in absolute terms at t = 0, as stackbeam's base excitation starts (initial_state.cpp):
    // its velocity relative to the supports is -y_b'(0)
    double w = 0.0, v = -yb.derivative(0.0), F = 0.0;
    const double u0[2] = {w, v};
    f.api.fmi2SetReal(c, in, 2, u0);
    f.api.fmi2GetReal(c, &force, 1, &F);
    double a = F / mass_kg - yb.second_derivative(0.0);
    std::vector<double> ws{w};
    for (long i = 0; i < n; ++i) {
        BOOST_REQUIRE_MESSAGE(f.api.fmi2DoStep(c, i * h, h, fmi2True) == fmi2OK, g_last_message);
        const double t1 = (i + 1) * h;
        w += h * v + 0.5 * h * h * a;
        const double u[2] = {w, v + h * a};
        f.api.fmi2SetReal(c, in, 2, u);
        BOOST_REQUIRE_MESSAGE(f.api.fmi2GetReal(c, &force, 1, &F) == fmi2OK, g_last_message);
        const double a1 = F / mass_kg - yb.second_derivative(t1);
        v += 0.5 * h * (a + a1);
        a = a1;
        ws.push_back(w);
    }
    f.api.fmi2FreeInstance(c);
    return ws;
}

}  // namespace

// A mass on the spring under base excitation: the harness's velocity Verlet coupled to the FMU at
// communication step h converges to stackbeam's own run of the same system (LoadingKind::base_excitation,
// mode closed-form, at a step 1/8 of the finest h) at the scheme's order 2: the spring force is
// continuous in w and piecewise smooth (its slope jumps where pairs stick or slip), which keeps the
// global order of the scheme (a slope jump costs O(h^3) in the one step that holds it).
BOOST_AUTO_TEST_CASE(a_mass_on_the_fmu_converges_to_stackbeams_own_run_at_order_two) {
    const Fmu& f = fmu();
    const double t_end = 0.2, mass = f.scenario.model.rigid_body.mass_kg;
    stackbeam::SimulationOptions so = f.scenario.simulation;
    so.loading = stackbeam::Loading{};
    so.loading.kind = stackbeam::LoadingKind::base_excitation;
    so.loading.displacement_m.shape = stackbeam::TimeFunction::Shape::harmonic;
    so.loading.displacement_m.amplitude = 0.005;  // +-5 mm at 8 Hz (scenarios/base_friction.toml)
    so.loading.displacement_m.frequency_hz = 8.0;
    so.t_end_s = t_end;
    const double h_ref = 5e-5 / 8.0;
    so.dt_s = h_ref;
    stackbeam::ModelSpec spec = f.scenario.model;
    spec.rigid_body.initial_velocity_m_per_s = 0.0;
    spec.rigid_body.initial_displacement_m = 0.0;
    const stackbeam::System system(stackbeam::Model::build(spec));
    const auto ref = stackbeam::simulate(system, so);
    stackbeam::TimeFunction yb = so.loading.displacement_m;
    std::vector<double> err;
    for (double h : {4e-4, 2e-4, 1e-4, 5e-5}) {
        const auto ws = coupled_mass(f, yb, mass, h, t_end);
        const long stride = std::lround(h / h_ref);
        double e = 0.0;
        for (std::size_t i = 0; i < ws.size(); ++i) e = std::max(e, std::abs(ws[i] - ref[i * stride].w_m));
        err.push_back(e);
        BOOST_TEST_MESSAGE("h = " << h << " s: max |w - w_ref| = " << e << " m");
    }
    double peak = 0.0;
    for (const auto& r : ref) peak = std::max(peak, std::abs(r.w_m));
    BOOST_TEST_MESSAGE("peak |w_ref| = " << peak << " m");
    for (std::size_t k = 1; k < err.size(); ++k) {
        const double order = std::log2(err[k - 1] / err[k]);
        BOOST_TEST_MESSAGE("observed order " << order);
        BOOST_CHECK_GT(order, 1.7);  // measured 1.95, 1.80, 2.08 (the kinks make it uneven, not lower)
    }
    // measured 1.2e-8 m at h = 5e-5 s; the reference's own error at h/8 is ~64x smaller (closed-form,
    // second order), so the figure is the coupling's
    BOOST_CHECK_LT(err.back(), 1e-5 * peak);
}

// Parameters set before the run (FMI 2.0 variability fixed: between fmi2Instantiate and
// fmi2ExitInitializationMode) are the run's: the friction coefficients and a clamp's preload set
// through the FMU give simulate() of the scenario with those values, bit for bit (the FMU
// rebuilds the model from the same spec: the same stepper on the same doubles, as above).
BOOST_AUTO_TEST_CASE(parameters_set_before_initialisation_are_the_runs) {
    const Fmu& f = fmu();
    stackbeam::ModelSpec spec = f.scenario.model;
    spec.interfaces[0].friction_coefficient = 0.3;
    spec.interfaces[1].friction_coefficient = 0.2;
    spec.clamps[0].preload_n = spec.clamps[3].preload_n = 800.0;  // the half model: mirrored clamps alike
    stackbeam::SimulationOptions so = f.scenario.simulation;
    so.t_end_s = 0.3;  // past the first turning point (0.25 s): stick and slip both
    const auto ref = stackbeam::simulate(stackbeam::System(stackbeam::Model::build(spec)), so);
    const auto plain = stackbeam::simulate(stackbeam::System(stackbeam::Model::build(f.scenario.model)), so);

    // set one by one: the model is checked as a whole when the run starts (a lone clamps[0] would
    // break the half model's mirror symmetry; fmi2ExitInitializationMode would say so)
    const fmi2ValueReference vr[4] = {f.vr("interfaces[0].friction_coefficient"), f.vr("interfaces[1].friction_coefficient"),
                                      f.vr("clamps[0].preload_n"), f.vr("clamps[3].preload_n")};
    const double v[4] = {0.3, 0.2, 800.0, 800.0};
    // one instance set in state instantiated, one in initialization mode: both are allowed
    for (const bool in_init : {false, true}) {
        fmi2Component c = f.instantiate(in_init ? "init" : "instantiated");
        BOOST_REQUIRE(c != nullptr);
        if (!in_init)
            for (int k = 0; k < 4; ++k) BOOST_REQUIRE_MESSAGE(f.api.fmi2SetReal(c, vr + k, 1, v + k) == fmi2OK, g_last_message);
        BOOST_REQUIRE_EQUAL(f.api.fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK);
        BOOST_REQUIRE_EQUAL(f.api.fmi2EnterInitializationMode(c), fmi2OK);
        if (in_init)
            for (int k = 0; k < 4; ++k) BOOST_REQUIRE_MESSAGE(f.api.fmi2SetReal(c, vr + k, 1, v + k) == fmi2OK, g_last_message);
        double back[4] = {0.0, 0.0, 0.0, 0.0};
        BOOST_REQUIRE_EQUAL(f.api.fmi2GetReal(c, vr, 4, back), fmi2OK);
        for (int k = 0; k < 4; ++k) BOOST_CHECK_EQUAL(back[k], v[k]);
        BOOST_REQUIRE_EQUAL(f.api.fmi2ExitInitializationMode(c), fmi2OK);
        BOOST_CHECK_EQUAL(f.api.fmi2SetReal(c, vr, 1, v), fmi2Error);  // fixed: not during the run
        BOOST_CHECK(g_last_message.find("variability fixed") != std::string::npos);
        const Outputs o = drive(f, c, so.dt_s, static_cast<long>(ref.size()) - 1);
        BOOST_REQUIRE_EQUAL(o.rows.size(), ref.size());
        for (std::size_t i = 0; i < ref.size(); ++i) {
            BOOST_REQUIRE_MESSAGE(o.rows[i][0] == -ref[i].spring_force_n, "record " << i);
            BOOST_REQUIRE_EQUAL(o.rows[i][1], ref[i].dissipated_energy_j);
        }
        f.api.fmi2FreeInstance(c);
    }
    // a lone clamps[0]: accepted alone, refused as a whole when the run starts, naming the key
    fmi2Component lone = f.instantiate("lone");
    BOOST_REQUIRE(lone != nullptr);
    BOOST_REQUIRE_EQUAL(f.api.fmi2SetReal(lone, vr + 2, 1, v + 2), fmi2OK);
    BOOST_REQUIRE_EQUAL(f.api.fmi2SetupExperiment(lone, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK);
    BOOST_REQUIRE_EQUAL(f.api.fmi2EnterInitializationMode(lone), fmi2OK);
    BOOST_CHECK_EQUAL(f.api.fmi2ExitInitializationMode(lone), fmi2Error);
    BOOST_CHECK_MESSAGE(g_last_message.find("clamps[0]") != std::string::npos, g_last_message);
    f.api.fmi2FreeInstance(lone);
    // the parameters mattered: less friction dissipates less over the same stroke
    BOOST_CHECK_LT(ref.back().dissipated_energy_j, 0.9 * plain.back().dissipated_energy_j);
}

namespace {

/// The leaf-mass scenario (tests/fmu/rig_leaf_mass.toml, mode newmark) with `mode` written in.
std::string leaf_mass_scenario(const std::string& mode) {
    std::string text;
    {
        std::ifstream is(FMU_LEAF_MASS_SCENARIO);
        std::stringstream s;
        s << is.rdbuf();
        text = s.str();
    }
    const std::string key = "mode = \"newmark\"";
    const auto at = text.find(key);
    if (at == std::string::npos) throw std::runtime_error("no " + key + " in " + FMU_LEAF_MASS_SCENARIO);
    text.replace(at, key.size(), "mode = \"" + mode + "\"");
    // mode cvode integrates the elastic layer's vibrations (short steps, docs/performance.md "Leaf
    // mass"): 10 ms of the stroke, not 50 (a quarter of the 8 Hz period is 31 ms)
    const std::string end = "t_end_s = 0.05";
    if (mode == "cvode" && text.find(end) != std::string::npos) text.replace(text.find(end), end.size(), "t_end_s = 0.01");
    const fs::path out = fs::temp_directory_path() / ("stackbeam_test_fmu_" + mode + "_" + std::to_string(::getpid()) + ".toml");
    std::ofstream(out) << text;
    return out.string();
}

/// The largest |a - b| over the force column and the largest |b| (b: simulate()).
std::pair<double, double> force_deviation(const Outputs& o, const std::vector<stackbeam::StepRecord>& ref) {
    double dev = 0.0, peak = 0.0;
    for (std::size_t i = 0; i < ref.size(); ++i) {
        dev = std::max(dev, std::abs(o.rows[i][0] + ref[i].spring_force_n));
        peak = std::max(peak, std::abs(ref[i].spring_force_n));
    }
    return {dev, peak};
}

}  // namespace

// Leaf mass, mode newmark (stepper newmark-massive): the rig's smooth stroke through the FMU at
// the scenario's step is simulate() of the same scenario record for record, bit for bit: the
// stepper reads w, w', w'' only at its record times, where the samples are the values the
// importer set, i.e. the scenario's own TimeFunction at the same times (the same doubles).
BOOST_AUTO_TEST_CASE(leaf_mass_newmark_through_the_fmu_is_simulate_bit_for_bit) {
    const Fmu f(FMU_LEAF_MASS_SCENARIO, "newmark");
    const stackbeam::SimulationOptions& so = f.scenario.simulation;
    const auto ref = stackbeam::simulate(stackbeam::System(stackbeam::Model::build(f.scenario.model)), so);
    fmi2Component c = started(f, "newmark");
    const Outputs o = drive(f, c, so.dt_s, static_cast<long>(ref.size()) - 1);
    require_records_equal(o, ref);
    BOOST_CHECK_GT(force_deviation(o, ref).second, 100.0);  // a 4 mm stroke: hundreds of newtons, not zeros
    BOOST_CHECK_GT(ref.back().leaf_kinetic_energy_j + ref[ref.size() / 2].leaf_kinetic_energy_j, 0.0);  // the leaves move
    f.api.fmi2FreeInstance(c);
}

// Leaf mass, mode cvode (the whole massive stack, cvode-massive): the same stroke through the
// FMU against simulate(). Not bit for bit: CVODE evaluates the seat's motion between records,
// where the FMU's samples are interpolated linearly (error (dt^2/8) |w''| = 6e-9 m, and on the
// acceleration (dt^2/8) |w''''|: 3e-6 of its amplitude, at dt = 1e-4 s, 8 Hz) and its step
// sequence differs accordingly, so the records agree to the integrator's own accuracy:
// test_leaf_mass_loadings bounds cvode's rig force against the exact solution by 1e-3 of the
// amplitude (measured 3e-4, the mesh and layer modes' ringing), and that is the bound here
// (measured here: 4.7e-5 N of 22 N, 2e-6).
// seat.max_stroke_m is left at its start value, the scenario's largest w (4 mm), so the FMU's
// error and event scales are simulate()'s (EventScales' motion_max).
BOOST_AUTO_TEST_CASE(leaf_mass_cvode_through_the_fmu_is_simulate_within_the_integrators_accuracy) {
    const std::string path = leaf_mass_scenario("cvode");
    const Fmu f(path, "cvode");
    fs::remove(path);
    BOOST_CHECK_CLOSE(f.desc.by_name("seat.max_stroke_m").start, 0.004, 1e-12);
    const stackbeam::SimulationOptions& so = f.scenario.simulation;
    const auto ref = stackbeam::simulate(stackbeam::System(stackbeam::Model::build(f.scenario.model)), so);
    fmi2Component c = started(f, "cvode");
    const Outputs o = drive(f, c, so.dt_s, static_cast<long>(ref.size()) - 1);
    BOOST_REQUIRE_EQUAL(o.rows.size(), ref.size());
    const auto [dev, peak] = force_deviation(o, ref);
    BOOST_TEST_MESSAGE("cvode through the FMU: max |force - simulate| = " << dev << " N of " << peak << " N");
    BOOST_CHECK_GT(peak, 10.0);  // 10 ms of the stroke: w reaches 0.24 mm, tens of newtons (measured 22 N)
    BOOST_CHECK_LT(dev, 1e-3 * peak);
    // the dissipated energy and the seat's work: the same bound relative to the work done
    double edev = 0.0;
    for (std::size_t i = 0; i < ref.size(); ++i) edev = std::max(edev, std::abs(o.rows[i][3] - ref[i].external_work_j));
    BOOST_TEST_MESSAGE("max |external work - simulate| = " << edev << " J of " << ref.back().external_work_j << " J");
    BOOST_CHECK_LT(edev, 1e-3 * std::abs(ref.back().external_work_j) + 1e-9);
    f.api.fmi2FreeInstance(c);
}

// ---------------------------------------------------------------- the seat's rotation (windup)
