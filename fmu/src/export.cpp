// The FMU's exporter (export.hpp): modelDescription.xml from the scenario and the variables'
// table (variables.hpp), and the zip archive (libzip).
#include "stackbeam_fmu/export.hpp"

#include <zip.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "stackbeam/errors.hpp"
#include "variables.hpp"

namespace stackbeam::fmu {

namespace {

std::string xml_escape(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            case '\n': out += "&#10;"; break;
            default: out += c;
        }
    }
    return out;
}

std::string num(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

struct Var {
    std::string name;
    unsigned int vr;
    const char* causality;
    const char* variability;
    const char* initial;  // "" for none
    const char* unit;
    std::string description;
    bool has_start;
    double start;
};

std::string read_file(const std::string& path, const std::string& field) {
    std::ifstream is(path, std::ios::binary);
    if (!is) throw InputError(field, "cannot read '" + path + "'");
    std::stringstream s;
    s << is.rdbuf();
    return s.str();
}

}  // namespace

std::string default_binary_path() {
    if (const char* env = std::getenv("STACKBEAM_FMU_BINARY"); env != nullptr && env[0] != '\0') return env;
    return STACKBEAM_FMU_BINARY;
}

std::string model_description(const Scenario& scenario, const std::string& scenario_text) {
    const ModelSpec& m = scenario.model;
    const SimulationOptions& o = scenario.simulation;
    const Windup windup = windup_of(System(Model::build(m)), o);
    std::vector<Var> vars = {
        {"seat.displacement_m", vr_seat_displacement, "input", "continuous", "", "m",
         "seat (axle seat, rigid body R) displacement w relative to the spring's supports, +y up", true, 0.0},
        {"seat.velocity_m_per_s", vr_seat_velocity, "input", "continuous", "", "m/s",
         "seat velocity dw/dt, +y (the rig's kinetic energy bookkeeping; leaf mass: the stepper uses it)", true, 0.0},
        {"seat.acceleration_m_per_s2", vr_seat_acceleration, "input", "continuous", "", "m/s2",
         "seat acceleration d2w/dt2, +y (leaf mass: the inertial load of the leaves)", true, 0.0},
        {"seat.force_n", vr_seat_force, "output", "continuous", "", "N",
         "force of the spring on the seat, +y up, whole spring (= -(k w - c^T p), the load cell's force reversed)", false, 0.0},
        {"spring.dissipated_energy_j", vr_dissipated, "output", "continuous", "", "J",
         "friction work between the leaves since the start", false, 0.0},
        {"spring.max_leaf_stress_pa", vr_max_stress, "output", "continuous", "", "Pa",
         "largest absolute fibre stress over every leaf (Stepper::stresses)", false, 0.0},
        {"spring.strain_energy_j", vr_strain_energy, "output", "continuous", "", "J", "elastic energy of the leaves", false, 0.0},
        {"spring.external_work_j", vr_external_work, "output", "continuous", "", "J",
         "work done on the spring through the seat since the start", false, 0.0},
        {"integrator.dt_s", vr_dt, "parameter", "fixed", "exact", "s",
         "the stepper's time step: every communication step is a whole number of it", true, o.dt_s},
        {"seat.max_stroke_m", vr_max_stroke, "parameter", "fixed", "exact", "m",
         "largest |seat.displacement_m| the importer will set (the cvode steppers' error and event scales), > 0",
         true, default_max_stroke_m(o.loading.displacement_m, seat_moves(o.loading))},
    };
    if (windup.carried) {
        vars.insert(vars.begin() + 3,
                    {{"seat.rotation_rad", vr_seat_rotation, "input", "continuous", "", "rad",
                      "seat (axle) rotation theta_R relative to the spring's supports, counter-clockwise (x forward "
                      "along the spring, y up); 0 at the start",
                      true, 0.0},
                     {"seat.angular_velocity_rad_per_s", vr_seat_angular_velocity, "input", "continuous", "", "rad/s",
                      "d theta_R/dt, counter-clockwise (leaf mass: the stepper uses it; 0 at the start)", true, 0.0},
                     {"seat.angular_acceleration_rad_per_s2", vr_seat_angular_acceleration, "input", "continuous", "",
                      "rad/s2", "d2 theta_R/dt2, counter-clockwise (leaf mass: the inertial load of the leaves)", true,
                      0.0}});
        vars.insert(vars.begin() + 7,
                    {"seat.moment_n_m", vr_seat_moment, "output", "continuous", "", "N.m",
                     "moment of the spring on the seat, counter-clockwise, whole spring (= -seat_moment, the "
                     "windup rig's moment on the spring)", false, 0.0});
        if (windup.axial)
            vars.insert(vars.begin() + 8,
                        {"seat.axial_displacement_m", vr_seat_axial, "output", "continuous", "", "m",
                         "the seat's axial displacement u_R, +x, as the spring locates it (no longitudinal force on "
                         "the seat: there is no axial input)", false, 0.0});
    }
    for (std::size_t i = 0; i < m.interfaces.size() && i < kMaxListed; ++i)
        vars.push_back({"interfaces[" + std::to_string(i) + "].friction_coefficient", vr_friction0 + unsigned(i), "parameter",
                        "fixed", "exact", "1", "Coulomb friction coefficient mu between leaves " + std::to_string(i) +
                                                   " and " + std::to_string(i + 1), true, m.interfaces[i].friction_coefficient});
    for (std::size_t j = 0; j < m.clamps.size() && j < kMaxListed; ++j)
        vars.push_back({"clamps[" + std::to_string(j) + "].preload_n", vr_preload0 + unsigned(j), "parameter", "fixed",
                        "exact", "N", "clamp preload at x = " + num(m.clamps[j].x_m) + " m", true, m.clamps[j].preload_n});

    std::ostringstream x;
    x << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<fmiModelDescription fmiVersion=\"2.0\" modelName=\"stackbeam_spring\" guid=\"" << guid_of(scenario_text)
      << "\"\n  description=\""
      << xml_escape((scenario.description.empty() ? std::string("stackbeam leaf spring") : scenario.description) +
                    (windup.note.empty() ? "" : "\n" + windup.note))
      << "\"\n  generationTool=\"stackbeam\" variableNamingConvention=\"structured\" numberOfEventIndicators=\"0\">\n"
      << "  <CoSimulation modelIdentifier=\"" << model_identifier() << "\" needsExecutionTool=\"false\""
      << " canHandleVariableCommunicationStepSize=\"true\" canInterpolateInputs=\"false\" maxOutputDerivativeOrder=\"0\""
      << " canRunAsynchronuously=\"false\" canBeInstantiatedOnlyOncePerProcess=\"false\""
      << " canNotUseMemoryManagementFunctions=\"true\" canGetAndSetFMUstate=\"true\" canSerializeFMUstate=\"true\""
      << " providesDirectionalDerivative=\"false\"/>\n"
      << "  <UnitDefinitions>\n"
      << "    <Unit name=\"1\"/>\n"
      << "    <Unit name=\"s\"><BaseUnit s=\"1\"/></Unit>\n"
      << "    <Unit name=\"m\"><BaseUnit m=\"1\"/></Unit>\n"
      << "    <Unit name=\"m/s\"><BaseUnit m=\"1\" s=\"-1\"/></Unit>\n"
      << "    <Unit name=\"m/s2\"><BaseUnit m=\"1\" s=\"-2\"/></Unit>\n"
      << "    <Unit name=\"N\"><BaseUnit kg=\"1\" m=\"1\" s=\"-2\"/></Unit>\n"
      << "    <Unit name=\"N.m\"><BaseUnit kg=\"1\" m=\"2\" s=\"-2\"/></Unit>\n"
      << "    <Unit name=\"rad\"><BaseUnit rad=\"1\"/></Unit>\n"
      << "    <Unit name=\"rad/s\"><BaseUnit s=\"-1\" rad=\"1\"/></Unit>\n"
      << "    <Unit name=\"rad/s2\"><BaseUnit s=\"-2\" rad=\"1\"/></Unit>\n"
      << "    <Unit name=\"J\"><BaseUnit kg=\"1\" m=\"2\" s=\"-2\"/></Unit>\n"
      << "    <Unit name=\"Pa\"><BaseUnit kg=\"1\" m=\"-1\" s=\"-2\"/></Unit>\n"
      << "  </UnitDefinitions>\n"
      << "  <DefaultExperiment startTime=\"0\" stopTime=\"" << num(o.t_end_s) << "\" stepSize=\"" << num(o.dt_s) << "\"/>\n"
      << "  <ModelVariables>\n";
    std::vector<std::size_t> inputs, outputs;
    for (std::size_t k = 0; k < vars.size(); ++k) {
        const Var& v = vars[k];
        if (std::string(v.causality) == "input") inputs.push_back(k + 1);
        if (std::string(v.causality) == "output") outputs.push_back(k + 1);
        x << "    <ScalarVariable name=\"" << xml_escape(v.name) << "\" valueReference=\"" << v.vr << "\" causality=\""
          << v.causality << "\" variability=\"" << v.variability << "\"";
        if (v.initial[0] != '\0') x << " initial=\"" << v.initial << "\"";
        x << "\n      description=\"" << xml_escape(v.description) << "\">\n        <Real unit=\"" << v.unit << "\"";
        if (v.has_start) x << " start=\"" << num(v.start) << "\"";
        x << "/>\n    </ScalarVariable>\n";
    }
    x << "  </ModelVariables>\n  <ModelStructure>\n";
    std::string deps, kinds;
    for (std::size_t i : inputs) {
        deps += (deps.empty() ? "" : " ") + std::to_string(i);
        kinds += std::string(kinds.empty() ? "" : " ") + "dependent";
    }
    for (const char* section : {"Outputs", "InitialUnknowns"}) {
        x << "    <" << section << ">\n";
        for (std::size_t i : outputs)
            x << "      <Unknown index=\"" << i << "\" dependencies=\"" << deps << "\" dependenciesKind=\"" << kinds << "\"/>\n";
        x << "    </" << section << ">\n";
    }
    x << "  </ModelStructure>\n</fmiModelDescription>\n";
    return x.str();
}

void export_fmu(const std::string& scenario_path, const std::string& out_path, const std::string& binary_path) {
    const std::string text = read_file(scenario_path, "scenario");
    const Scenario scenario = parse_scenario(text, scenario_path);  // InputError with the key and line
    const std::string binary_file = binary_path.empty() ? default_binary_path() : binary_path;
    const std::string binary = read_file(binary_file, "binary");
    const std::string xml = model_description(scenario, text);

    int error = 0;
    zip_t* z = zip_open(out_path.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
    if (z == nullptr) {
        zip_error_t ze;
        zip_error_init_with_code(&ze, error);
        const std::string why = zip_error_strerror(&ze);
        zip_error_fini(&ze);
        throw std::runtime_error("cannot write '" + out_path + "': " + why);
    }
    auto add = [&](const std::string& name, const std::string& data) {
        zip_source_t* src = zip_source_buffer(z, data.data(), data.size(), 0);
        if (src == nullptr || zip_file_add(z, name.c_str(), src, ZIP_FL_ENC_UTF_8) < 0) {
            if (src != nullptr) zip_source_free(src);
            const std::string why = zip_strerror(z);
            zip_discard(z);
            throw std::runtime_error("cannot add " + name + " to '" + out_path + "': " + why);
        }
    };
    for (const char* dir : {"binaries/", "binaries/linux64/", "resources/"}) zip_dir_add(z, dir, ZIP_FL_ENC_UTF_8);
    add("modelDescription.xml", xml);
    add("resources/scenario.toml", text);
    add(std::string("binaries/linux64/") + model_identifier() + ".so", binary);
    if (zip_close(z) < 0) {  // the buffers above must live until here (zip_close reads them)
        const std::string why = zip_strerror(z);
        zip_discard(z);
        throw std::runtime_error("cannot write '" + out_path + "': " + why);
    }
}

}  // namespace stackbeam::fmu
