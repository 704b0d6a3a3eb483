// The FMU's binary (binaries/linux64/stackbeam_spring.so): an FMI 2.0 co-simulation slave of a
// scenario's spring, the seat held by the importer (docs/fmu.md, docs/decisions/060-fmu.md).
//
// The spring is the scenario's stack under the rig loading (LoadingKind::prescribed_displacement,
// loading.hpp) whose seat displacement w(t), velocity and acceleration are the FMU's inputs: the
// stepper's TimeFunction reads them from an ExternalSamples table that this file fills at every
// communication point. The interval that ends at a communication point is integrated when its
// outputs are first needed (fmi2GetReal, or the next fmi2DoStep), with the inputs set at that
// point: the outputs depend directly on the inputs (direct feedthrough, declared in the XML),
// exactly as the rig's record at t depends on w(t). Between two communication points the inputs
// are interpolated linearly (the stepper's records inside a longer communication step).
//
// Where the scenario's stepper takes the windup rig with the vertical rig (windup_of, variables.hpp:
// the library's own check, decided once from the scenario), the seat's rotation theta_R(t), its rate
// and acceleration are inputs too, read by the windup rig's TimeFunction (Loading::seat_rotation_rad)
// from a second ExternalSamples table, and the moment (and, where the seat slides, u_R) are outputs.
// Elsewhere those value references do not exist: setting one is refused.
//
// FMU states (fmi2GetFMUstate) are the inputs' history, not a copy of the stepper: setting one
// rebuilds the stepper and replays the history from t = 0, which gives the same records bit for
// bit (the steppers are deterministic) at a cost linear in the time reached (decision 060).
//
// Every function catches every exception: an error is fmi2Error with a message through the
// importer's logger, never a crash. Instances share nothing mutable: each may run on its own thread.
#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <new>
#include <sstream>
#include <string>
#include <vector>

#include "fmi2Functions.h"
#include "stackbeam/errors.hpp"
#include "stackbeam/io/scenario.hpp"
#include "stackbeam/model/model.hpp"
#include "stackbeam/time/stepper.hpp"
#include "variables.hpp"

namespace {

using namespace stackbeam;
using namespace stackbeam::fmu;

enum class Phase { instantiated, initialization, step_complete, terminated, error };

const char* to_string(Phase p) {
    switch (p) {
        case Phase::instantiated: return "instantiated";
        case Phase::initialization: return "initialization mode";
        case Phase::step_complete: return "step complete";
        case Phase::terminated: return "terminated";
        case Phase::error: return "error";
    }
    return "?";
}

/// What fmi2GetFMUstate keeps: the parameters, the inputs' history and the communication point.
struct Snapshot {
    std::vector<double> friction, preload;
    double dt_s = 0.0;
    double max_stroke_m = 0.0;
    ExternalSamples samples;
    ExternalSamples rotation_samples;
    long comm_index = 0;
    double u[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
};

struct Instance {
    std::string name;
    fmi2CallbackLogger logger = nullptr;
    fmi2ComponentEnvironment env = nullptr;
    bool logging = false;
    Phase phase = Phase::instantiated;

    Scenario scenario;  // as read from resources/scenario.toml
    ModelSpec spec;     // with the parameters set
    SimulationOptions options;
    double max_stroke_m = 1e-3;  // seat.max_stroke_m: the importer's bound on |w| [m] (the cvode scales)
    double start_s = 0.0;
    double stop_s = 0.0;  // stop time - start time when the experiment defines it [s], 0: none

    std::unique_ptr<System> system;
    Windup windup;  // whether the windup variables exist (windup_of, from the scenario)
    std::shared_ptr<ExternalSamples> samples = std::make_shared<ExternalSamples>();
    std::shared_ptr<ExternalSamples> rotation_samples = std::make_shared<ExternalSamples>();
    std::unique_ptr<Stepper> stepper;
    long comm_index = 0;  // the current communication point is start + comm_index dt
    // inputs at the current communication point (w, w', w'', theta_R, theta_R', theta_R''), by value reference - 1
    double u[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    bool stale = false;               // the stepper's record at comm_index was made with other inputs
    long stress_index = -1;           // record whose largest stress is cached
    double stress_pa = 0.0;

    void log(fmi2Status status, const char* category, const std::string& message) const {
        if (logger != nullptr && (logging || status >= fmi2Warning))
            logger(env, name.c_str(), status, category, "%s", message.c_str());
    }
};

/// The seat's rotation [rad] and its rate [rad/s] at the first communication point taken as the unwound
/// seat at rest (0) when within this of 0: the rounding of an importer's shape.
constexpr double kStartRoundoff = 1e-12;

/// An error to report as fmi2Error (the message names the cause).
struct FmuError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

std::string fmt(double v) {
    std::ostringstream s;
    s.precision(17);
    s << v;
    return s.str();
}

/// The path of a file: URI (fmuResourceLocation, FMI 2.0 section 2.1.5), percent-decoded.
std::string path_of_uri(const std::string& uri) {
    std::string p = uri;
    if (p.rfind("file://", 0) == 0) {
        p = p.substr(7);
        if (!p.empty() && p[0] != '/') p = p.substr(p.find('/'));  // file://host/path
    } else if (p.rfind("file:", 0) == 0) {
        p = p.substr(5);
    }
    std::string out;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p[i] == '%' && i + 2 < p.size()) {
            out += static_cast<char>(std::stoi(p.substr(i + 1, 2), nullptr, 16));
            i += 2;
        } else {
            out += p[i];
        }
    }
    while (out.size() > 1 && out.back() == '/') out.pop_back();
    return out;
}

void require_phase(const Instance& in, const char* function, std::initializer_list<Phase> allowed) {
    for (Phase p : allowed)
        if (in.phase == p) return;
    std::string list;
    for (Phase p : allowed) list += std::string(list.empty() ? "" : ", ") + to_string(p);
    throw FmuError(std::string(function) + " is not allowed in state '" + to_string(in.phase) + "' (allowed in: " +
                   list + ")");
}

/// The model of the current parameters; InputError (naming the parameter) when one is out of range.
void rebuild_system(Instance& in) {
    in.system = std::make_unique<System>(Model::build(in.spec));
}

double record_time(const Instance& in, long index) { return static_cast<double>(index) * in.options.dt_s; }

/// Makes the stepper's record the one at the current communication point with the current inputs.
void ensure_current(Instance& in) {
    if (in.stepper && !in.stale && in.stepper->record_index() == in.comm_index) return;
    in.samples->set(record_time(in, in.comm_index), in.u[0], in.u[1], in.u[2]);
    if (in.windup.carried) {
        double theta = in.u[3], rate = in.u[4];
        if (in.comm_index == 0) {
            // The run starts unwound and, with leaf mass, at rest (Loading::validate, exactly: the samples have
            // no shape whose rounding it could allow for). An importer's own shape rounds there (a harmonic from
            // rest: sin(-pi/2) + 1, cos(-pi/2) = 6e-17): |theta| <= 1e-12 rad, |theta'| <= 1e-12 rad/s are 0.
            if (std::abs(theta) <= kStartRoundoff) theta = 0.0;
            if (std::abs(rate) <= kStartRoundoff) rate = 0.0;
        }
        in.rotation_samples->set(record_time(in, in.comm_index), theta, rate, in.u[5]);
    }
    if (!in.stepper || in.stale || in.stepper->record_index() > in.comm_index) {
        SimulationOptions options = in.options;
        // the importer decides when to stop: the experiment's stop time, else 1e8 steps (validate() allows 1e9)
        options.t_end_s = in.stop_s > 0.0 ? std::max(in.stop_s, record_time(in, in.comm_index)) : 1e8 * options.dt_s;
        options.loading = rig_loading(in.samples, in.windup.carried ? in.rotation_samples : nullptr, in.max_stroke_m);
        if (in.windup.carried) {
            // the run starts from the unwound seat (Loading::validate, by the scenario's key): say it by the inputs
            const ExternalSamples& r = *in.rotation_samples;
            const bool leaf_mass = in.spec.leaves[0].density_kg_per_m3 > 0.0;
            if (r.values.front() != 0.0 || (leaf_mass && r.derivatives.front() != 0.0))
                throw FmuError("input seat.rotation_rad = " + fmt(r.values.front()) + " rad" +
                               (leaf_mass ? ", seat.angular_velocity_rad_per_s = " + fmt(r.derivatives.front()) + " rad/s" : "") +
                               " at the start is not allowed: the spring starts unwound, so the rotation must be 0" +
                               (leaf_mass ? " and, with leaf mass (the leaves start at rest), its rate 0" : "") +
                               " (to 1e-12)" +
                               " at the first communication point (give the rotation relative to the start)");
        }
        if (!in.system) rebuild_system(in);
        in.stepper.reset();
        in.stepper = make_stepper(*in.system, options);
        in.stale = false;
        in.stress_index = -1;
    }
    while (in.stepper->record_index() < in.comm_index) in.stepper->advance();
}

double output(Instance& in, fmi2ValueReference vr) {
    ensure_current(in);
    const StepRecord& r = in.stepper->current();
    switch (vr) {
        case vr_seat_force: return -r.spring_force_n;
        case vr_dissipated: return r.dissipated_energy_j;
        case vr_strain_energy: return r.strain_energy_j;
        case vr_external_work: return r.external_work_j;
        case vr_seat_moment:
            if (in.windup.carried) return -r.seat_moment_n_m;
            break;
        case vr_seat_axial:
            if (in.windup.axial) return r.seat_axial_m;
            break;
        case vr_max_stress:
            if (in.stress_index != in.stepper->record_index()) {
                double m = 0.0;
                for (const auto& leaf : in.stepper->stresses().leaves) {
                    for (double s : leaf.top_stress_pa) m = std::max(m, std::abs(s));
                    for (double s : leaf.bottom_stress_pa) m = std::max(m, std::abs(s));
                }
                in.stress_pa = m;
                in.stress_index = in.stepper->record_index();
            }
            return in.stress_pa;
        default: break;
    }
    throw FmuError("value reference " + std::to_string(vr) + " is not an output");
}

bool is_input(const Instance& in, fmi2ValueReference vr) {
    const fmi2ValueReference last = in.windup.carried ? vr_seat_angular_acceleration : vr_seat_acceleration;
    return vr >= vr_seat_displacement && vr <= last;
}

/// Index of a friction (preload) parameter, or -1.
long friction_index(const Instance& in, fmi2ValueReference vr) {
    const long i = static_cast<long>(vr) - vr_friction0;
    return i >= 0 && i < static_cast<long>(in.spec.interfaces.size()) && i < kMaxListed ? i : -1;
}
long preload_index(const Instance& in, fmi2ValueReference vr) {
    const long j = static_cast<long>(vr) - vr_preload0;
    return j >= 0 && j < static_cast<long>(in.spec.clamps.size()) && j < kMaxListed ? j : -1;
}

double get_real(Instance& in, fmi2ValueReference vr) {
    if (is_input(in, vr)) return in.u[vr - vr_seat_displacement];
    if (vr == vr_dt) return in.options.dt_s;
    if (vr == vr_max_stroke) return in.max_stroke_m;
    if (const long i = friction_index(in, vr); i >= 0) return in.spec.interfaces[i].friction_coefficient;
    if (const long j = preload_index(in, vr); j >= 0) return in.spec.clamps[j].preload_n;
    require_phase(in, "fmi2GetReal of an output", {Phase::initialization, Phase::step_complete, Phase::terminated});
    return output(in, vr);
}

void set_real(Instance& in, fmi2ValueReference vr, double v) {
    if (is_input(in, vr)) {
        if (!std::isfinite(v))
            throw FmuError("input " + std::to_string(vr) + " (seat motion) = " + fmt(v) + " is not allowed: it must be finite");
        double& slot = in.u[vr - vr_seat_displacement];
        if (slot != v && in.stepper && in.stepper->record_index() == in.comm_index) in.stale = true;
        slot = v;
        return;
    }
    const bool parameter = vr == vr_dt || vr == vr_max_stroke || friction_index(in, vr) >= 0 || preload_index(in, vr) >= 0;
    if (!parameter) {
        if (vr >= vr_seat_rotation && vr <= vr_seat_angular_acceleration)  // !in.windup.carried
            throw FmuError("value reference " + std::to_string(vr) + " (the seat's rotation) is not an input of this FMU: " +
                           in.windup.note);
        throw FmuError("value reference " + std::to_string(vr) + " cannot be set (not an input or parameter)");
    }
    require_phase(in, "fmi2SetReal of a parameter (variability fixed)", {Phase::instantiated, Phase::initialization});
    if (vr == vr_max_stroke) {
        if (!(std::isfinite(v) && v > 0.0))
            throw FmuError("parameter seat.max_stroke_m = " + fmt(v) +
                           " is not allowed: it must be a finite length > 0 m (the largest |seat.displacement_m| to come)");
        in.max_stroke_m = v;
        in.stepper.reset();
        return;
    }
    if (vr == vr_dt) {
        SimulationOptions o = in.options;
        o.dt_s = v;
        try {
            o.validate();
        } catch (const InputError& e) {
            throw FmuError("parameter integrator.dt_s = " + fmt(v) + ": " + e.what());
        }
        in.options = o;
        in.stepper.reset();
        return;
    }
    // Each value alone: finite and >= 0 (both are). The model is rebuilt, with the library's checks
    // of the whole stack (e.g. the half model's mirrored clamps, set one by one), when the run starts
    // (fmi2ExitInitializationMode, or the first read of an output): a message naming the key.
    const long i = friction_index(in, vr), j = preload_index(in, vr);
    const std::string name = i >= 0 ? "interfaces[" + std::to_string(i) + "].friction_coefficient"
                                    : "clamps[" + std::to_string(j) + "].preload_n";
    if (!(std::isfinite(v) && v >= 0.0))
        throw FmuError("parameter " + name + " = " + fmt(v) + " is not allowed: it must be a finite number >= 0");
    (i >= 0 ? in.spec.interfaces[i].friction_coefficient : in.spec.clamps[j].preload_n) = v;
    in.system.reset();
    in.stepper.reset();
}

/// Runs `body` for an instance, turning every exception into fmi2Error with a logged message.
template <class Body>
fmi2Status guarded(fmi2Component c, const char* function, Body body) {
    if (c == nullptr) return fmi2Error;
    auto* in = static_cast<Instance*>(c);
    try {
        body(*in);
        return fmi2OK;
    } catch (const SolverError& e) {
        in->phase = Phase::error;
        in->log(fmi2Error, "logStatusError",
                std::string(function) + ": solver failure at step " + std::to_string(e.step()) + " (t = " +
                    fmt(in->start_s + e.time_s()) + " s, residual " + fmt(e.residual()) + " m): " + e.what());
    } catch (const InputError& e) {
        in->log(fmi2Error, "logStatusError", std::string(function) + ": bad input: " + e.what());
    } catch (const FmuError& e) {
        in->log(fmi2Error, "logStatusError", std::string(function) + ": " + e.what());
    } catch (const std::exception& e) {
        in->phase = Phase::error;
        in->log(fmi2Error, "logStatusError", std::string(function) + ": " + e.what());
    } catch (...) {
        in->phase = Phase::error;
        in->log(fmi2Error, "logStatusError", std::string(function) + ": unknown error");
    }
    return fmi2Error;
}

void reset_instance(Instance& in) {
    in.spec = in.scenario.model;
    in.options = in.scenario.simulation;
    in.max_stroke_m = default_max_stroke_m(in.options.loading.displacement_m, seat_moves(in.options.loading));
    in.start_s = 0.0;
    in.stop_s = 0.0;
    in.stepper.reset();
    in.samples = std::make_shared<ExternalSamples>();
    in.rotation_samples = std::make_shared<ExternalSamples>();
    in.comm_index = 0;
    std::fill(std::begin(in.u), std::end(in.u), 0.0);
    in.stale = false;
    in.stress_index = -1;
    rebuild_system(in);
    in.windup = windup_of(*in.system, in.options);
    in.phase = Phase::instantiated;
}

}  // namespace

extern "C" {

const char* fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char* fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t, const fmi2String[]) {
    return guarded(c, "fmi2SetDebugLogging", [&](Instance& in) { in.logging = loggingOn != fmi2False; });
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions* functions,
                              fmi2Boolean, fmi2Boolean loggingOn) {
    fmi2CallbackLogger logger = functions != nullptr ? functions->logger : nullptr;
    fmi2ComponentEnvironment env = functions != nullptr ? functions->componentEnvironment : nullptr;
    const char* name = instanceName != nullptr ? instanceName : "";
    auto fail = [&](const std::string& message) -> fmi2Component {
        if (logger != nullptr) logger(env, name, fmi2Error, "logStatusError", "fmi2Instantiate: %s", message.c_str());
        return nullptr;
    };
    try {
        if (instanceName == nullptr || instanceName[0] == '\0') return fail("instanceName is empty: give the instance a name");
        if (fmuType != fmi2CoSimulation)
            return fail("fmuType " + std::to_string(static_cast<int>(fmuType)) +
                        " is not allowed: this FMU is for co-simulation only (fmi2CoSimulation)");
        if (fmuResourceLocation == nullptr) return fail("fmuResourceLocation is null: give the URI of the FMU's resources/");
        const std::string file = path_of_uri(fmuResourceLocation) + "/scenario.toml";
        std::ifstream is(file, std::ios::binary);
        if (!is) return fail("cannot read " + file + " (fmuResourceLocation = '" + fmuResourceLocation + "')");
        std::stringstream text;
        text << is.rdbuf();
        const std::string guid = guid_of(text.str());
        if (fmuGUID == nullptr || guid != fmuGUID)
            return fail(std::string("fmuGUID '") + (fmuGUID ? fmuGUID : "(null)") + "' is not this FMU's (" + guid +
                        "): the resources do not belong to this modelDescription.xml");
        auto in = std::make_unique<Instance>();
        in->name = name;
        in->logger = logger;
        in->env = env;
        in->logging = loggingOn != fmi2False;
        in->scenario = parse_scenario(text.str(), file);
        reset_instance(*in);
        in->log(fmi2OK, "logAll", "instantiated from " + file);
        return in.release();
    } catch (const std::exception& e) {
        return fail(e.what());
    } catch (...) {
        return fail("unknown error");
    }
}

void fmi2FreeInstance(fmi2Component c) { delete static_cast<Instance*>(c); }

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean, fmi2Real, fmi2Real startTime, fmi2Boolean stopTimeDefined,
                               fmi2Real stopTime) {
    return guarded(c, "fmi2SetupExperiment", [&](Instance& in) {
        require_phase(in, "fmi2SetupExperiment", {Phase::instantiated});
        if (!std::isfinite(startTime)) throw FmuError("startTime = " + fmt(startTime) + " is not allowed: it must be finite");
        in.start_s = startTime;
        if (stopTimeDefined != fmi2False) {
            if (!std::isfinite(stopTime) || stopTime < startTime)
                throw FmuError("stopTime = " + fmt(stopTime) + " is not allowed: it must be finite and >= startTime = " + fmt(startTime));
            in.stop_s = stopTime - startTime;
        }
    });
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    return guarded(c, "fmi2EnterInitializationMode", [&](Instance& in) {
        require_phase(in, "fmi2EnterInitializationMode", {Phase::instantiated});
        in.phase = Phase::initialization;
    });
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    return guarded(c, "fmi2ExitInitializationMode", [&](Instance& in) {
        require_phase(in, "fmi2ExitInitializationMode", {Phase::initialization});
        // the stepper of the parameters set, at t = 0 with the inputs set: a mode that cannot run the
        // rig, or a bad combination of parameters, is refused here, naming the scenario's key
        ensure_current(in);
        in.phase = Phase::step_complete;
    });
}

fmi2Status fmi2Terminate(fmi2Component c) {
    return guarded(c, "fmi2Terminate", [&](Instance& in) {
        require_phase(in, "fmi2Terminate", {Phase::step_complete});
        in.phase = Phase::terminated;
    });
}

fmi2Status fmi2Reset(fmi2Component c) {
    return guarded(c, "fmi2Reset", [&](Instance& in) { reset_instance(in); });
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    return guarded(c, "fmi2GetReal", [&](Instance& in) {
        require_phase(in, "fmi2GetReal", {Phase::initialization, Phase::step_complete, Phase::terminated});
        if (nvr > 0 && (vr == nullptr || value == nullptr)) throw FmuError("vr or value is null");
        for (size_t i = 0; i < nvr; ++i) value[i] = get_real(in, vr[i]);
    });
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
    return guarded(c, "fmi2SetReal", [&](Instance& in) {
        require_phase(in, "fmi2SetReal", {Phase::instantiated, Phase::initialization, Phase::step_complete});
        if (nvr > 0 && (vr == nullptr || value == nullptr)) throw FmuError("vr or value is null");
        for (size_t i = 0; i < nvr; ++i) set_real(in, vr[i], value[i]);
    });
}

// No Integer, Boolean or String variables: only empty requests succeed.
#define STACKBEAM_FMU_NO_VARIABLES(function, type, constness)                                                       \
    fmi2Status function(fmi2Component c, const fmi2ValueReference[], size_t nvr, constness type[]) {               \
        return guarded(c, #function, [&](Instance&) {                                                              \
            if (nvr > 0) throw FmuError("this FMU has no variables of this type (see modelDescription.xml)");      \
        });                                                                                                        \
    }
STACKBEAM_FMU_NO_VARIABLES(fmi2GetInteger, fmi2Integer, )
STACKBEAM_FMU_NO_VARIABLES(fmi2GetBoolean, fmi2Boolean, )
STACKBEAM_FMU_NO_VARIABLES(fmi2GetString, fmi2String, )
STACKBEAM_FMU_NO_VARIABLES(fmi2SetInteger, fmi2Integer, const)
STACKBEAM_FMU_NO_VARIABLES(fmi2SetBoolean, fmi2Boolean, const)
STACKBEAM_FMU_NO_VARIABLES(fmi2SetString, fmi2String, const)
#undef STACKBEAM_FMU_NO_VARIABLES

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate* state) {
    return guarded(c, "fmi2GetFMUstate", [&](Instance& in) {
        require_phase(in, "fmi2GetFMUstate", {Phase::initialization, Phase::step_complete, Phase::terminated});
        if (state == nullptr) throw FmuError("FMUstate is null");
        auto* s = *state != nullptr ? static_cast<Snapshot*>(*state) : new Snapshot;
        s->friction.clear();
        s->preload.clear();
        for (const auto& i : in.spec.interfaces) s->friction.push_back(i.friction_coefficient);
        for (const auto& j : in.spec.clamps) s->preload.push_back(j.preload_n);
        s->dt_s = in.options.dt_s;
        s->max_stroke_m = in.max_stroke_m;
        s->samples = *in.samples;
        s->rotation_samples = *in.rotation_samples;
        s->comm_index = in.comm_index;
        std::memcpy(s->u, in.u, sizeof in.u);
        *state = s;
    });
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state) {
    return guarded(c, "fmi2SetFMUstate", [&](Instance& in) {
        require_phase(in, "fmi2SetFMUstate", {Phase::initialization, Phase::step_complete, Phase::terminated, Phase::error});
        if (state == nullptr) throw FmuError("FMUstate is null");
        const auto& s = *static_cast<const Snapshot*>(state);
        if (s.friction.size() != in.spec.interfaces.size() || s.preload.size() != in.spec.clamps.size())
            throw FmuError("the FMU state is not one of this FMU's (its numbers of interfaces or clamps differ)");
        for (std::size_t i = 0; i < s.friction.size(); ++i) in.spec.interfaces[i].friction_coefficient = s.friction[i];
        for (std::size_t j = 0; j < s.preload.size(); ++j) in.spec.clamps[j].preload_n = s.preload[j];
        in.options.dt_s = s.dt_s;
        in.max_stroke_m = s.max_stroke_m;
        rebuild_system(in);
        in.stepper.reset();  // rebuilt and replayed on demand (ensure_current)
        in.samples = std::make_shared<ExternalSamples>(s.samples);
        in.rotation_samples = std::make_shared<ExternalSamples>(s.rotation_samples);
        in.comm_index = s.comm_index;
        std::memcpy(in.u, s.u, sizeof in.u);
        in.stale = false;
        in.stress_index = -1;
        if (in.phase == Phase::error) in.phase = Phase::step_complete;
    });
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate* state) {
    return guarded(c, "fmi2FreeFMUstate", [&](Instance&) {
        if (state == nullptr) return;
        delete static_cast<Snapshot*>(*state);
        *state = nullptr;
    });
}

namespace {
// The serialized state: a byte image of the Snapshot's numbers (this platform's doubles, little-endian x86-64).
void put(std::vector<char>& b, const void* p, std::size_t n) { b.insert(b.end(), static_cast<const char*>(p), static_cast<const char*>(p) + n); }
void put_vec(std::vector<char>& b, const std::vector<double>& v) {
    const std::uint64_t n = v.size();
    put(b, &n, sizeof n);
    put(b, v.data(), n * sizeof(double));
}
std::vector<char> serialize(const Snapshot& s) {
    std::vector<char> b;
    const char magic[8] = {'S', 'B', 'F', 'M', 'U', 'S', '3', '\0'};  // 3: with the rotation's samples
    put(b, magic, sizeof magic);
    put_vec(b, s.friction);
    put_vec(b, s.preload);
    put(b, &s.dt_s, sizeof s.dt_s);
    put(b, &s.max_stroke_m, sizeof s.max_stroke_m);
    put_vec(b, s.samples.times_s);
    put_vec(b, s.samples.values);
    put_vec(b, s.samples.derivatives);
    put_vec(b, s.samples.second_derivatives);
    put_vec(b, s.rotation_samples.times_s);
    put_vec(b, s.rotation_samples.values);
    put_vec(b, s.rotation_samples.derivatives);
    put_vec(b, s.rotation_samples.second_derivatives);
    put(b, &s.comm_index, sizeof s.comm_index);
    put(b, s.u, sizeof s.u);
    return b;
}
struct Reader {
    const char* p;
    std::size_t left;
    void get(void* out, std::size_t n) {
        if (n > left) throw FmuError("the serialized FMU state is truncated or not one of this FMU's");
        std::memcpy(out, p, n);
        p += n;
        left -= n;
    }
    std::vector<double> vec() {
        std::uint64_t n = 0;
        get(&n, sizeof n);
        if (n > left / sizeof(double)) throw FmuError("the serialized FMU state is truncated or not one of this FMU's");
        std::vector<double> v(n);
        get(v.data(), n * sizeof(double));
        return v;
    }
};
}  // namespace

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t* size) {
    return guarded(c, "fmi2SerializedFMUstateSize", [&](Instance&) {
        if (state == nullptr || size == nullptr) throw FmuError("FMUstate or size is null");
        *size = serialize(*static_cast<const Snapshot*>(state)).size();
    });
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state, fmi2Byte serializedState[], size_t size) {
    return guarded(c, "fmi2SerializeFMUstate", [&](Instance&) {
        if (state == nullptr || serializedState == nullptr) throw FmuError("FMUstate or serializedState is null");
        const auto b = serialize(*static_cast<const Snapshot*>(state));
        if (size < b.size())
            throw FmuError("size " + std::to_string(size) + " is too small: the state needs " + std::to_string(b.size()) +
                           " bytes (fmi2SerializedFMUstateSize)");
        std::memcpy(serializedState, b.data(), b.size());
    });
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[], size_t size, fmi2FMUstate* state) {
    return guarded(c, "fmi2DeSerializeFMUstate", [&](Instance&) {
        if (state == nullptr || serializedState == nullptr) throw FmuError("serializedState or FMUstate is null");
        Reader r{serializedState, size};
        char magic[8];
        r.get(magic, sizeof magic);
        if (std::memcmp(magic, "SBFMUS3", 8) != 0) throw FmuError("the serialized FMU state is not one of this FMU's");
        auto s = std::make_unique<Snapshot>();
        s->friction = r.vec();
        s->preload = r.vec();
        r.get(&s->dt_s, sizeof s->dt_s);
        r.get(&s->max_stroke_m, sizeof s->max_stroke_m);
        s->samples.times_s = r.vec();
        s->samples.values = r.vec();
        s->samples.derivatives = r.vec();
        s->samples.second_derivatives = r.vec();
        s->rotation_samples.times_s = r.vec();
        s->rotation_samples.values = r.vec();
        s->rotation_samples.derivatives = r.vec();
        s->rotation_samples.second_derivatives = r.vec();
        r.get(&s->comm_index, sizeof s->comm_index);
        r.get(s->u, sizeof s->u);
        if (*state != nullptr) delete static_cast<Snapshot*>(*state);
        *state = s.release();
    });
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference[], size_t, const fmi2ValueReference[],
                                        size_t, const fmi2Real[], fmi2Real[]) {
    return guarded(c, "fmi2GetDirectionalDerivative", [&](Instance&) {
        throw FmuError("not provided (providesDirectionalDerivative = false in modelDescription.xml)");
    });
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference[], size_t, const fmi2Integer[],
                                       const fmi2Real[]) {
    return guarded(c, "fmi2SetRealInputDerivatives", [&](Instance&) {
        throw FmuError("not provided (canInterpolateInputs = false): set the seat's velocity and acceleration inputs instead");
    });
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference[], size_t, const fmi2Integer[],
                                        fmi2Real[]) {
    return guarded(c, "fmi2GetRealOutputDerivatives", [&](Instance&) {
        throw FmuError("not provided (maxOutputDerivativeOrder = 0 in modelDescription.xml)");
    });
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize, fmi2Boolean) {
    return guarded(c, "fmi2DoStep", [&](Instance& in) {
        require_phase(in, "fmi2DoStep", {Phase::step_complete});
        const double dt = in.options.dt_s;
        const double now = in.start_s + record_time(in, in.comm_index);
        if (!(std::abs(currentCommunicationPoint - now) <= 1e-6 * dt))
            throw FmuError("currentCommunicationPoint = " + fmt(currentCommunicationPoint) +
                           " s is not the FMU's time " + fmt(now) + " s (the end of the last step)");
        const double m = std::round(communicationStepSize / dt);
        if (!std::isfinite(communicationStepSize) || m < 1.0 || std::abs(m * dt - communicationStepSize) > 1e-6 * dt)
            throw FmuError("communicationStepSize = " + fmt(communicationStepSize) +
                           " s is not allowed: it must be a whole number (>= 1) of the integrator's steps, "
                           "integrator.dt_s = " + fmt(dt) + " s (set that parameter to change it)");
        ensure_current(in);  // the interval ending now, with the inputs set now
        in.comm_index += static_cast<long>(m);
    });
}

fmi2Status fmi2CancelStep(fmi2Component c) {
    return guarded(c, "fmi2CancelStep", [&](Instance&) {
        throw FmuError("not provided: fmi2DoStep never returns fmi2Pending (canRunAsynchronuously = false)");
    });
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind, fmi2Status*) {
    return guarded(c, "fmi2GetStatus", [&](Instance&) {
        throw FmuError("not provided: fmi2DoStep never returns fmi2Pending");
    });
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real* value) {
    return guarded(c, "fmi2GetRealStatus", [&](Instance& in) {
        if (s != fmi2LastSuccessfulTime || value == nullptr)
            throw FmuError("only fmi2LastSuccessfulTime is provided, with a non-null value");
        *value = in.start_s + record_time(in, in.comm_index);
    });
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind, fmi2Integer*) {
    return guarded(c, "fmi2GetIntegerStatus", [&](Instance&) { throw FmuError("no integer status is provided"); });
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean* value) {
    return guarded(c, "fmi2GetBooleanStatus", [&](Instance& in) {
        if (s != fmi2Terminated || value == nullptr) throw FmuError("only fmi2Terminated is provided, with a non-null value");
        *value = in.phase == Phase::terminated ? fmi2True : fmi2False;
    });
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind, fmi2String*) {
    return guarded(c, "fmi2GetStringStatus", [&](Instance&) { throw FmuError("no string status is provided"); });
}

}  // extern "C"
