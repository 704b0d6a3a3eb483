#pragma once
// The FMU as an importer sees it (docs/fmu.md): the harness the FMU tests share (test_fmu.cpp,
// test_fmu_windup.cpp): `stackbeam fmu` makes the FMU, libzip opens the archive into a fresh
// directory (the "clean system": only the FMU's files, no stackbeam installed), expat reads
// modelDescription.xml, dlopen() loads the binary, and the tests drive it through the FMI 2.0 calls
// only. It shares no code with the exporter or the FMU (only the standard's declarations,
// fmu/include/fmi2*.h).
#include <boost/test/unit_test.hpp>


#include <dlfcn.h>
#include <expat.h>
#include <zip.h>

#include <array>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "fmi2FunctionTypes.h"
#include "stackbeam/io/scenario.hpp"
#include "stackbeam/time/stepper.hpp"


namespace stackbeam::fmu_importer {

namespace fs = std::filesystem;


// ---------------------------------------------------------------- the archive and its XML
struct Variable {
    std::string name, causality, variability, unit;
    unsigned vr = 0;
    bool has_start = false;
    double start = 0.0;
};
struct Description {
    std::string fmi_version, guid, model_identifier, description;
    std::map<std::string, std::string> cosim;  // the CoSimulation element's attributes
    std::vector<Variable> variables;
    std::vector<int> output_indices;            // ModelStructure/Outputs, 1-based
    const Variable& by_name(const std::string& n) const {
        for (const auto& v : variables)
            if (v.name == n) return v;
        throw std::runtime_error("no variable " + n);
    }
};

inline void on_start(void* data, const XML_Char* el, const XML_Char** attr) {
    auto& d = *static_cast<std::pair<Description, std::string>*>(data);
    std::map<std::string, std::string> a;
    for (int i = 0; attr[i]; i += 2) a[attr[i]] = attr[i + 1];
    const std::string e = el;
    if (e == "fmiModelDescription") {
        d.first.fmi_version = a["fmiVersion"];
        d.first.guid = a["guid"];
        d.first.description = a["description"];
    } else if (e == "CoSimulation") {
        d.first.cosim = a;
        d.first.model_identifier = a["modelIdentifier"];
    } else if (e == "ScalarVariable") {
        Variable v;
        v.name = a["name"];
        v.vr = static_cast<unsigned>(std::stoul(a["valueReference"]));
        v.causality = a["causality"];
        v.variability = a["variability"];
        d.first.variables.push_back(v);
    } else if (e == "Real" && !d.first.variables.empty()) {
        d.first.variables.back().unit = a["unit"];
        if (a.count("start")) {
            d.first.variables.back().has_start = true;
            d.first.variables.back().start = std::stod(a["start"]);
        }
    } else if (e == "Outputs") {
        d.second = "Outputs";
    } else if (e == "Unknown" && d.second == "Outputs") {
        d.first.output_indices.push_back(std::stoi(a["index"]));
    }
}
inline void on_end(void* data, const XML_Char* el) {
    if (std::string(el) == "Outputs") static_cast<std::pair<Description, std::string>*>(data)->second.clear();
}

inline Description parse_description(const std::string& xml) {
    std::pair<Description, std::string> d;
    XML_Parser p = XML_ParserCreate(nullptr);
    XML_SetUserData(p, &d);
    XML_SetElementHandler(p, on_start, on_end);
    const bool ok = XML_Parse(p, xml.data(), static_cast<int>(xml.size()), 1) == XML_STATUS_OK;
    XML_ParserFree(p);
    if (!ok) throw std::runtime_error("modelDescription.xml is not well-formed");
    return d.first;
}

/// Unzips `fmu` into `dir` (libzip), every entry.
inline void unzip(const std::string& fmu, const fs::path& dir) {
    int err = 0;
    zip_t* z = zip_open(fmu.c_str(), ZIP_RDONLY, &err);
    if (z == nullptr) throw std::runtime_error("cannot open " + fmu);
    const zip_int64_t n = zip_get_num_entries(z, 0);
    for (zip_int64_t i = 0; i < n; ++i) {
        const std::string name = zip_get_name(z, i, 0);
        const fs::path out = dir / name;
        if (!name.empty() && name.back() == '/') {
            fs::create_directories(out);
            continue;
        }
        fs::create_directories(out.parent_path());
        zip_file_t* f = zip_fopen_index(z, i, 0);
        std::ofstream os(out, std::ios::binary);
        char buf[65536];
        zip_int64_t got;
        while ((got = zip_fread(f, buf, sizeof buf)) > 0) os.write(buf, got);
        zip_fclose(f);
    }
    zip_close(z);
}

inline std::string slurp(const fs::path& p) {
    std::ifstream is(p, std::ios::binary);
    std::stringstream s;
    s << is.rdbuf();
    return s.str();
}

// ---------------------------------------------------------------- the binary
/// The functions a co-simulation FMU must export (FMI 2.0 sections 2.1 and 4.2), written here
/// from the standard's list, not from the FMU's headers.
inline const std::vector<std::string> kRequired = {
    "fmi2GetTypesPlatform", "fmi2GetVersion", "fmi2SetDebugLogging", "fmi2Instantiate", "fmi2FreeInstance",
    "fmi2SetupExperiment", "fmi2EnterInitializationMode", "fmi2ExitInitializationMode", "fmi2Terminate", "fmi2Reset",
    "fmi2GetReal", "fmi2GetInteger", "fmi2GetBoolean", "fmi2GetString", "fmi2SetReal", "fmi2SetInteger",
    "fmi2SetBoolean", "fmi2SetString", "fmi2GetFMUstate", "fmi2SetFMUstate", "fmi2FreeFMUstate",
    "fmi2SerializedFMUstateSize", "fmi2SerializeFMUstate", "fmi2DeSerializeFMUstate", "fmi2GetDirectionalDerivative",
    "fmi2SetRealInputDerivatives", "fmi2GetRealOutputDerivatives", "fmi2DoStep", "fmi2CancelStep", "fmi2GetStatus",
    "fmi2GetRealStatus", "fmi2GetIntegerStatus", "fmi2GetBooleanStatus", "fmi2GetStringStatus"};

inline thread_local std::string g_last_message;
inline void logger(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String format, ...) {
    char buf[4096];
    va_list ap;
    va_start(ap, format);
    std::vsnprintf(buf, sizeof buf, format, ap);
    va_end(ap);
    g_last_message = buf;
}
inline const fmi2CallbackFunctions kCallbacks = {logger, std::calloc, std::free, nullptr, nullptr};

// the functions the tests call, each through its pointer
#define STACKBEAM_TEST_FMI_FUNCTIONS(F)                                                                          \
    F(fmi2GetTypesPlatform) F(fmi2GetVersion) F(fmi2Instantiate) F(fmi2FreeInstance) F(fmi2SetupExperiment)     \
    F(fmi2EnterInitializationMode) F(fmi2ExitInitializationMode) F(fmi2Terminate) F(fmi2Reset) F(fmi2GetReal)   \
    F(fmi2SetReal) F(fmi2GetInteger) F(fmi2GetFMUstate) F(fmi2SetFMUstate) F(fmi2FreeFMUstate)                 \
    F(fmi2SerializedFMUstateSize) F(fmi2SerializeFMUstate) F(fmi2DeSerializeFMUstate) F(fmi2DoStep)            \
    F(fmi2GetRealStatus) F(fmi2CancelStep)

struct Api {
    void* handle = nullptr;
#define F(name) name##TYPE* name = nullptr;
    STACKBEAM_TEST_FMI_FUNCTIONS(F)
#undef F
};

/// The FMU made once for the whole test run, unpacked and loaded.
struct Fmu {
    fs::path dir;
    Description desc;
    Api api;
    std::string resources_uri;
    stackbeam::Scenario scenario;
    /// The FMU of scenario file `scenario_path`, made in a directory of its own named after `tag`.
    explicit Fmu(const std::string& scenario_path = FMU_SCENARIO, const std::string& tag = "rig") {
        dir = fs::temp_directory_path() / ("stackbeam_test_fmu_" + tag + "_" + std::to_string(::getpid()));
        fs::remove_all(dir);
        fs::create_directories(dir / "unpacked");
        const std::string fmu = (dir / "spring.fmu").string();
        const std::string cmd = std::string(STACKBEAM_CLI) + " fmu " + scenario_path + " --out " + fmu + " > /dev/null";
        if (std::system(cmd.c_str()) != 0) throw std::runtime_error("failed: " + cmd);
        unzip(fmu, dir / "unpacked");
        desc = parse_description(slurp(dir / "unpacked" / "modelDescription.xml"));
        resources_uri = "file://" + (dir / "unpacked" / "resources").string();
        const fs::path so = dir / "unpacked" / "binaries" / "linux64" / (desc.model_identifier + ".so");
        api.handle = dlopen(so.c_str(), RTLD_NOW | RTLD_LOCAL);
        if (api.handle == nullptr) throw std::runtime_error(std::string("dlopen: ") + dlerror());
#define F(name) api.name = reinterpret_cast<name##TYPE*>(dlsym(api.handle, #name));
        STACKBEAM_TEST_FMI_FUNCTIONS(F)
#undef F
        scenario = stackbeam::load_scenario(scenario_path);
        scenario.simulation.loading.prepare(false);
    }
    ~Fmu() {
        if (api.handle) dlclose(api.handle);
        fs::remove_all(dir);
    }
    fmi2Component instantiate(const char* name = "spring") const {
        return api.fmi2Instantiate(name, fmi2CoSimulation, desc.guid.c_str(), resources_uri.c_str(), &kCallbacks,
                                   fmi2False, fmi2False);
    }
    unsigned vr(const std::string& name) const { return desc.by_name(name).vr; }
    bool has(const std::string& name) const {
        for (const auto& v : desc.variables)
            if (v.name == name) return true;
        return false;
    }
};

inline Fmu& fmu() {
    static Fmu f;
    return f;
}

/// The outputs the tests compare: force, dissipated energy, strain energy, external work, stress.
struct Outputs {
    std::vector<std::array<double, 5>> rows;
};

/// Drives instance `c` from t = 0 with the seat on w(t) = scale * (the scenario's rig stroke), at the
/// communication step `h` (a whole number of the FMU's dt), for `n` communication steps after t = 0.
inline Outputs drive(const Fmu& f, fmi2Component c, double h, long n, double scale = 1.0, bool with_stress = false) {
    const auto& w = f.scenario.simulation.loading.displacement_m;
    const fmi2ValueReference in[3] = {f.vr("seat.displacement_m"), f.vr("seat.velocity_m_per_s"),
                                      f.vr("seat.acceleration_m_per_s2")};
    const fmi2ValueReference out[5] = {f.vr("seat.force_n"), f.vr("spring.dissipated_energy_j"),
                                       f.vr("spring.strain_energy_j"), f.vr("spring.external_work_j"),
                                       f.vr("spring.max_leaf_stress_pa")};
    const double dt = f.scenario.simulation.dt_s;
    const long m = std::lround(h / dt);
    Outputs o;
    auto sample = [&](long i) {
        const double t = static_cast<double>(i * m) * dt;  // the stepper's grid
        const double u[3] = {scale * w.value(t), scale * w.derivative(t), scale * w.second_derivative(t)};
        BOOST_REQUIRE_EQUAL(f.api.fmi2SetReal(c, in, 3, u), fmi2OK);
        std::array<double, 5> y{};
        BOOST_REQUIRE_EQUAL(f.api.fmi2GetReal(c, out, with_stress ? 5 : 4, y.data()), fmi2OK);
        o.rows.push_back(y);
    };
    sample(0);
    for (long i = 0; i < n; ++i) {
        BOOST_REQUIRE_MESSAGE(f.api.fmi2DoStep(c, static_cast<double>(i * m) * dt, h, fmi2True) == fmi2OK, g_last_message);
        sample(i + 1);
    }
    return o;
}

/// The FMU's outputs equal simulate()'s records, bit for bit: force, dissipated energy, strain energy, work.
inline void require_records_equal(const Outputs& o, const std::vector<stackbeam::StepRecord>& ref) {
    BOOST_REQUIRE_EQUAL(o.rows.size(), ref.size());
    for (std::size_t i = 0; i < ref.size(); ++i) {
        BOOST_REQUIRE_MESSAGE(o.rows[i][0] == -ref[i].spring_force_n, "record " << i << ": force " << o.rows[i][0]
                                                                               << " vs " << -ref[i].spring_force_n);
        BOOST_REQUIRE_EQUAL(o.rows[i][1], ref[i].dissipated_energy_j);
        BOOST_REQUIRE_EQUAL(o.rows[i][2], ref[i].strain_energy_j);
        BOOST_REQUIRE_EQUAL(o.rows[i][3], ref[i].external_work_j);
    }
}

inline fmi2Component started(const Fmu& f, const char* name = "spring") {
    fmi2Component c = f.instantiate(name);
    BOOST_REQUIRE(c != nullptr);
    BOOST_REQUIRE_EQUAL(f.api.fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK);
    BOOST_REQUIRE_EQUAL(f.api.fmi2EnterInitializationMode(c), fmi2OK);
    BOOST_REQUIRE_EQUAL(f.api.fmi2ExitInitializationMode(c), fmi2OK);
    return c;
}

}  // namespace stackbeam::fmu_importer
