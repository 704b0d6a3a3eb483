#pragma once
// The FMU's variables (docs/fmu.md): one table read by the FMU's binary (stackbeam_spring.cpp)
// and by the exporter (export.cpp, which writes modelDescription.xml from it), so the value
// references, names and units cannot drift apart. The importers (tests/fmu/, python/tests/)
// do not use it: they read the XML.
//
// Signs (include/stackbeam/conventions.hpp): y is up. The seat (the rigid body R's attachment,
// the axle seat) moves by w relative to the spring's frame (the supports), +y; the force output
// is the force of the spring on the seat, +y (a spring pushed down, w < 0, pushes the seat up).
// The seat's rotation theta_R is counter-clockwise (+z out of the plane, x forward along the spring,
// y up: docs/windup.md); the moment output is the moment of the spring on the seat, counter-clockwise
// (minus the record's seat_moment, the moment on the spring, as the force output is minus the
// record's spring force).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>

#include "stackbeam/errors.hpp"
#include "stackbeam/fe/system.hpp"
#include "stackbeam/model/loading.hpp"
#include "stackbeam/time/stepper.hpp"

namespace stackbeam::fmu {

/// Value references.
enum : unsigned int {
    vr_seat_displacement = 1,  ///< input w [m]
    vr_seat_velocity = 2,      ///< input w' [m/s]
    vr_seat_acceleration = 3,  ///< input w'' [m/s^2] (leaf mass: the rig's inertial load on the leaves)
    // the windup variables (only where windup_of() carries them)
    vr_seat_rotation = 4,              ///< input theta_R [rad], counter-clockwise (the windup rig)
    vr_seat_angular_velocity = 5,      ///< input theta_R' [rad/s]
    vr_seat_angular_acceleration = 6,  ///< input theta_R'' [rad/s^2] (leaf mass: the rig's inertial load)
    vr_seat_force = 10,        ///< output: force of the spring on the seat, +y [N] (= -StepRecord::spring_force_n)
    vr_dissipated = 11,        ///< output: friction work since t = 0 [J]
    vr_max_stress = 12,        ///< output: largest |fibre stress| over every leaf [Pa] (Stepper::stresses())
    vr_strain_energy = 13,     ///< output: elastic energy of the leaves [J]
    vr_external_work = 14,     ///< output: work done on the spring through the seat since t = 0 [J]
    vr_seat_moment = 15,       ///< output: moment of the spring on the seat, counter-clockwise [N m]
                               ///< (= -StepRecord::seat_moment_n_m; windup only)
    vr_seat_axial = 16,        ///< output: u_R, the seat's axial displacement, +x [m] (StepRecord::seat_axial_m;
                               ///< windup and a seat that slides only)
    vr_dt = 100,               ///< parameter integrator.dt_s [s]
    vr_max_stroke = 101,       ///< parameter seat.max_stroke_m [m]: the largest |w| the importer will set
                               ///< (the cvode steppers' scales: EventScales' motion_max, event_driver.cpp)
    vr_friction0 = 1000,       ///< parameter interfaces[i].friction_coefficient, vr 1000 + i [-]
    vr_preload0 = 2000,        ///< parameter clamps[j].preload_n, vr 2000 + j [N]
};
constexpr unsigned int kMaxListed = 1000;  ///< at most this many interfaces (clamps) get a parameter each

/// The start value of seat.max_stroke_m [m]: the largest |w| of the scenario's own seat motion
/// (|mean| + amplitude, or the table's largest |value|) when its loading moves the seat (rig or
/// base excitation), else 1 mm (the event driver's own scale of a spring at rest). The importer
/// sets its vehicle's travel; only the cvode steppers read it (their error and event scales).
inline double default_max_stroke_m(const TimeFunction& w, bool moves_seat) {
    double v = std::abs(w.mean) + w.amplitude;
    for (double x : w.values) v = std::max(v, std::abs(x));
    return moves_seat && v > 0.0 ? v : 1e-3;
}

/// Whether the scenario's loading moves the seat (its displacement_m is the seat's motion).
inline bool seat_moves(const Loading& L) {
    return L.kind == LoadingKind::prescribed_displacement || L.kind == LoadingKind::base_excitation;
}

/// The FMU's loading: the vertical rig on w(t) (the importer's samples `w`), and with `theta` the
/// windup rig on theta_R(t) (the importer's samples) too. `max_stroke_m`: seat.max_stroke_m, which
/// stands for the samples' largest |w| in the cvode steppers' scales (event_driver.cpp: largest_value
/// = |mean| + amplitude, EventScales' motion_max); value() and its derivatives are the samples'
/// whatever the shape (TimeFunction::external). theta's amplitude stays 0, so the library's check
/// theta_R(0) = 0 (Loading::validate) is exact, as the FMU's own (fmi2ExitInitializationMode).
inline Loading rig_loading(std::shared_ptr<const ExternalSamples> w, std::shared_ptr<const ExternalSamples> theta,
                           double max_stroke_m) {
    Loading L;
    L.kind = LoadingKind::prescribed_displacement;
    L.displacement_m.external = std::move(w);
    L.displacement_m.amplitude = max_stroke_m;
    if (theta) {
        L.seat_rotation_rad.emplace();
        L.seat_rotation_rad->external = std::move(theta);
    }
    return L;
}

/// Whether the FMU of a scenario carries the windup variables (the seat's rotation as inputs, the
/// moment and, where the seat slides, u_R as outputs), decided once from the scenario by the library
/// itself: the scenario's stepper is built under the vertical rig and the windup rig together, both
/// at rest, and the windup variables are carried when it is accepted. A refusal (the half model,
/// a stepper whose registry row does not take the windup rig, with the vertical rig or at all) leaves
/// them out, with the library's message as `note` (the model description says it): an importer never
/// gets a rotation input that the spring ignores. The exporter and the binary both decide by this,
/// so the XML and the calls cannot differ.
struct Windup {
    bool carried = false;
    bool axial = false;  ///< seat.axial_displacement_m is an output (carried, and the seat slides)
    std::string note;    ///< why not carried ("" when carried)
};
inline Windup windup_of(const System& system, const SimulationOptions& scenario_options) {
    Windup out;
    SimulationOptions o = scenario_options;
    o.loading = rig_loading(std::make_shared<ExternalSamples>(), std::make_shared<ExternalSamples>(), 1e-3);
    try {
        make_stepper(system, o);
    } catch (const std::exception& e) {
        out.note = std::string("The seat's rotation is not an input of this FMU and its moment not an output "
                               "(the library does not take the windup rig with the vertical rig on this scenario: ") +
                   e.what() + ")";
        return out;
    }
    out.carried = true;
    out.axial = system.seat_axial_dof() >= 0;
    return out;
}

/// The FMU's model identifier: the binary is binaries/linux64/<it>.so.
inline const char* model_identifier() { return "stackbeam_spring"; }

/// The GUID of an FMU made from scenario text `text`: FNV-1a (64 bit) of the text, twice with
/// two offsets, as a GUID-shaped string. The exporter writes it; the binary recomputes it from
/// resources/scenario.toml and refuses a mismatched fmuGUID.
inline std::string guid_of(const std::string& text) {
    auto fnv = [&](std::uint64_t h) {
        for (unsigned char c : text) {
            h ^= c;
            h *= 1099511628211ull;
        }
        return h;
    };
    const std::uint64_t a = fnv(14695981039346656037ull), b = fnv(0x9e3779b97f4a7c15ull);
    char buf[64];
    std::snprintf(buf, sizeof buf, "{%08x-%04x-%04x-%04x-%012llx}", static_cast<unsigned>(a >> 32),
                  static_cast<unsigned>((a >> 16) & 0xffff), static_cast<unsigned>(a & 0xffff),
                  static_cast<unsigned>(b >> 48), static_cast<unsigned long long>(b & 0xffffffffffffull));
    return buf;
}

}  // namespace stackbeam::fmu
