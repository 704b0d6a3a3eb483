#pragma once
// The FMU's variables (docs/fmu.md): one table read by the FMU's binary (stackbeam_spring.cpp)
// and by the exporter (export.cpp, which writes modelDescription.xml from it), so the value
// references, names and units cannot drift apart. The importers (tests/fmu/, python/tests/)
// do not use it: they read the XML.
//
// Signs (include/stackbeam/conventions.hpp): y is up. The seat (the rigid body R's attachment,
// the axle seat) moves by w relative to the spring's frame (the supports), +y; the force output
// is the force of the spring on the seat, +y (a spring pushed down, w < 0, pushes the seat up).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include "stackbeam/model/loading.hpp"

namespace stackbeam::fmu {

/// Value references.
enum : unsigned int {
    vr_seat_displacement = 1,  ///< input w [m]
    vr_seat_velocity = 2,      ///< input w' [m/s]
    vr_seat_acceleration = 3,  ///< input w'' [m/s^2] (leaf mass: the rig's inertial load on the leaves)
    vr_seat_force = 10,        ///< output: force of the spring on the seat, +y [N] (= -StepRecord::spring_force_n)
    vr_dissipated = 11,        ///< output: friction work since t = 0 [J]
    vr_max_stress = 12,        ///< output: largest |fibre stress| over every leaf [Pa] (Stepper::stresses())
    vr_strain_energy = 13,     ///< output: elastic energy of the leaves [J]
    vr_external_work = 14,     ///< output: work done on the spring through the seat since t = 0 [J]
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
