#pragma once
/// @file loading.hpp
/// How a run loads the spring: the rigid body's initial conditions (the paper), an
/// applied force on the rigid body, a prescribed displacement of the rigid body (the
/// test-rig loop of a leaf spring), gravity on the rigid body with the static
/// equilibrium computed first, and a prescribed motion of the supports (base excitation).
///
/// Signs (conventions.hpp): y is up; w and every force on R are +y. Forces are
/// whole-spring values (on the half model the meshed part carries half of them, as it
/// carries half of R's mass).
///
/// How each loading enters the equation of motion of R (massless leaves, system.hpp):
///     m w'' = c^T p - k w + F_e(t)                       (meshed part)
///     F_e(t) = F(t)/f - m g - m y_b''(t)                 (f = System::whole_spring_factor)
///  - applied force: F(t) on R;
///  - gravity: R's weight -m g (the leaves are massless, so they weigh nothing). The
///    run starts from the static equilibrium under it: the contact problem of a
///    quasi-static load step from the unloaded stack (w = (F_e + c^T p)/k), then the
///    initial displacement and velocity are added to that state;
///  - base excitation: every support moves by y_b(t) (the leaf ends' pins and built-in
///    ends together; a rigid translation of the stack, which the massless leaves follow
///    without force). The run is written in the frame of the supports: w is the
///    deflection of R relative to them (so the spring sees w as in the other loadings),
///    R feels the inertial force -m y_b''(t), and R's absolute displacement is
///    w + y_b (StepRecord::base_displacement_m). Energies are those of the relative
///    motion (kinetic energy m w'^2/2 with the relative velocity), and the work of the
///    inertial force is the external work;
///  - prescribed displacement: w(t) is imposed (a servo-hydraulic rig holding R); the
///    contact problem is quasi-static at each step (s = C'p + c w(t) - d), the rig
///    force is the spring force k w - c^T p (a load cell between rig and spring: R's
///    own inertia is not part of the loop) and the rig's work is the external work.
/// With leaf mass (modes newmark and cvode with density > 0) the loading acts on every
/// reduced DOF z = [z_r; w]:
///     M z'' + K z = G^T p + q(t),   q(t) = e_w F(t)/f - (g + y_b''(t)) l,
/// l = System::vertical_inertia_kg() (the leaves' consistent mass times a unit translation
/// in y, plus R's mass on w): gravity is the leaves' weight and R's, the static equilibrium
/// of the whole stack first; a base acceleration loads every mass in the supports' frame.
/// The rig imposes w(t) through a reaction lambda on w chosen so that w'' = w_p''(t); the load
/// cell between R and the spring reads lambda - m w_p'' (the leaves' inertia included), and
/// w(t) must then be smooth (validate(true): a triangle is refused, a table splined).
/// Energy balance of every loading: E(0) + W_ext(t) = kinetic + strain + dissipated.
///
/// Seat loads and the windup rig (full model only; signs in conventions.hpp, "Seat"), alone or
/// with any of the above: a moment M(t) on the seat [N m, counter-clockwise = +theta_R] and a
/// longitudinal force H(t) [N, +x] whose line of action lies h [m] above the seat's reference
/// (the tied leaves' mid-height). A point at height h moves u_R - h theta_R, so H does the work
/// H (u_R - h theta_R): on the reduced DOFs
///     q(t) += e_theta (M(t) - H(t) h) + e_u H(t),
/// H needs a seat that slides (rigid_body.axial: the ends locate the stack, not the seat). The
/// windup rig prescribes theta_R(t) instead of a moment (a servo rotating the seat, quasi-static as
/// the vertical rig: R's inertia, w's and u_R's mass and J, is not part of the loop); the record's
/// seat_moment is the rig's reaction moment on the spring. Vertically the seat is then held
/// (kind prescribed-displacement, w(t) the vertical rig's) or free under the vertical loads.
/// The loads act from t = 0 on the state without them (the run starts unwound).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "stackbeam/words.hpp"

namespace stackbeam {

/// Samples of a function of time supplied by the caller while the run goes: the seat
/// displacement an FMU's importer sets at each communication point (docs/fmu.md). At a
/// sample's time the function and its two derivatives are the sample's values exactly;
/// between two samples each of the three is interpolated linearly (a first-order hold);
/// before the first sample the first, after the last the last. Units: those of the
/// function it stands for ([m], [m/s], [m/s^2] for a displacement).
struct ExternalSamples {
    std::vector<double> times_s;             ///< strictly increasing [s]
    std::vector<double> values;              ///< f(t_i)
    std::vector<double> derivatives;         ///< f'(t_i) [unit/s]
    std::vector<double> second_derivatives;  ///< f''(t_i) [unit/s^2]
    /// Appends a sample at t_s; a sample at the last sample's time (or earlier) replaces
    /// the samples from there on (a caller that steps back). Values are not checked here.
    void set(double t_s, double value, double derivative, double second_derivative);
    double value(double t_s) const;
    double derivative(double t_s) const;
    double second_derivative(double t_s) const;
};

/// A scalar function of time, in the unit of what it describes ([N] or [m]).
struct TimeFunction {
    enum class Shape {
        constant,  ///< mean
        harmonic,  ///< mean + amplitude sin(2 pi frequency t + phase)
        triangle,  ///< mean + amplitude tri(frequency t + phase/(2 pi)): 0 at t = 0 rising to +amplitude
                   ///< at a quarter period, -amplitude at three quarters (a rig's constant-speed stroke)
        table,     ///< through the points (times_s[i], values[i]); constant before the first and after the
                   ///< last. Forces and prescribed displacements: piecewise linear. Base displacement: a C2
                   ///< cubic spline with zero slope at both ends (its acceleration is continuous)
    };
    Shape shape = Shape::constant;
    double mean = 0.0;           ///< offset (constant value) [N or m]
    double amplitude = 0.0;      ///< [N or m], >= 0 (harmonic, triangle)
    double frequency_hz = 0.0;   ///< [Hz], > 0 (harmonic, triangle)
    double phase_rad = 0.0;      ///< [rad] (harmonic, triangle)
    std::vector<double> times_s; ///< table: strictly increasing times [s], >= 2 points
    std::vector<double> values;  ///< table: values [N or m], as many as times_s

    /// Throws InputError naming `field` + ".amplitude" etc. when a value is out of range.
    /// `smooth`: the function must have a continuous second derivative (base displacement:
    /// a triangle is refused, a table is splined).
    void validate(const std::string& field, bool smooth) const;
    /// Prepares the spline of a smooth table (validate first). Called by Loading::prepare.
    void prepare(bool smooth);

    double value(double t_s) const;
    double derivative(double t_s) const;         ///< d/dt [unit/s]
    double second_derivative(double t_s) const;  ///< d2/dt2 [unit/s^2] (smooth functions)
    /// Period [s] of a periodic shape (harmonic, triangle), 0 otherwise.
    double period_s() const;

    /// Spline second derivatives at the table's points (smooth tables; filled by prepare()).
    std::vector<double> spline_m2;
    /// When set, value(), derivative() and second_derivative() are the caller's samples
    /// (ExternalSamples, filled while the run goes, e.g. by an FMU) whatever the shape: the
    /// steppers copy the TimeFunction and share the samples. Not written to scenario files.
    std::shared_ptr<const ExternalSamples> external;
};

template <>
const std::vector<EnumWord<TimeFunction::Shape>>& enum_words<TimeFunction::Shape>();
const char* to_string(TimeFunction::Shape shape);

enum class LoadingKind {
    initial_conditions,       ///< the paper: w(0), w'(0) of the rigid body, no force
    applied_force,            ///< force F(t) on R (plus the initial conditions)
    prescribed_displacement,  ///< w(t) imposed on R: the test-rig loop
    base_excitation,          ///< the supports move by y_b(t) (plus the initial conditions)
};
template <>
const std::vector<EnumWord<LoadingKind>>& enum_words<LoadingKind>();
const char* to_string(LoadingKind kind);

struct Loading {
    LoadingKind kind = LoadingKind::initial_conditions;
    TimeFunction force_n;         ///< applied_force: F(t) on R, +y, whole spring [N]
    TimeFunction displacement_m;  ///< prescribed_displacement: w(t) [m]; base_excitation: y_b(t) [m]
    double gravity_m_per_s2 = 0.0;///< acceleration of gravity g [m/s^2], >= 0, acting in -y on R;
                                  ///< 0: none. Not with prescribed_displacement (the rig holds R)
    /// M(t): a moment on the seat [N m], counter-clockwise (+theta_R) positive; absent: none.
    std::optional<TimeFunction> seat_moment_n_m;
    /// H(t): a longitudinal force on the seat [N], +x, whole spring; absent: none. Needs a seat that
    /// slides (RigidBodySpec::axial; the ends locate the stack).
    std::optional<TimeFunction> longitudinal_force_n;
    /// h: H's line of action above the seat's reference, the tied leaves' mid-height [m], finite
    /// (braking at the tyre's contact patch: minus the seat's height above the road). Adds -H h to the moment.
    double longitudinal_force_height_m = 0.0;
    /// The windup rig: theta_R(t) prescribed [rad] (counter-clockwise), theta_R(0) = 0; absent: none.
    /// Not with seat_moment_n_m (the rig's moment is a result).
    std::optional<TimeFunction> seat_rotation_rad;

    /// Throws InputError naming the field ("loading.force_n.amplitude", ...) when out of range.
    /// `leaf_mass`: the leaves have mass, so a rig's displacement must be smooth too (a
    /// triangle is refused, a table is splined): its acceleration loads the leaves.
    void validate(bool leaf_mass = false) const;
    /// validate(leaf_mass) and the derived data (splines). Steppers call it on their copy.
    void prepare(bool leaf_mass = false);
    /// True when nothing but initial conditions act (the paper).
    bool is_free() const noexcept {
        return kind == LoadingKind::initial_conditions && gravity_m_per_s2 == 0.0 && !has_seat_load() && !windup_rig();
    }

    /// External force on R [N] at t, whole spring, for mass `mass_kg` (the whole R): F(t) - m g - m y_b''(t).
    /// 0 for a prescribed displacement (the rig's force is a result).
    double external_force_n(double t_s, double mass_kg) const;
    /// Base displacement y_b(t) [m] (base_excitation), 0 otherwise.
    double base_displacement_m(double t_s) const;
    /// Base velocity y_b'(t) [m/s] (base_excitation), 0 otherwise.
    double base_velocity_m_per_s(double t_s) const;
    /// Period of the loading's excitation [s] (periodic shapes; else the windup rig's), 0 otherwise.
    double period_s() const;
    /// Whether a seat moment or a longitudinal force acts.
    bool has_seat_load() const noexcept { return seat_moment_n_m.has_value() || longitudinal_force_n.has_value(); }
    /// Whether theta_R is prescribed (the windup rig).
    bool windup_rig() const noexcept { return seat_rotation_rad.has_value(); }
    /// The moment on theta_R [N m] at t: M(t) - H(t) h (0 without seat loads).
    double seat_moment_n_m_at(double t_s) const;
    /// H(t) [N] (0 without).
    double longitudinal_force_n_at(double t_s) const;
};


}  // namespace stackbeam
