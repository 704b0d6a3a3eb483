// Loadings of a run (loading.hpp): time functions, their validation and the
// external force on the rigid body.
#include "stackbeam/model/loading.hpp"

#include <algorithm>
#include <cmath>

#include "stackbeam/errors.hpp"

namespace stackbeam {

namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;

/// Fractional part of x in [0, 1).
double frac(double x) { return x - std::floor(x); }

/// Index i of the table interval [t_i, t_i+1] holding t (t inside the table).
std::size_t interval(const std::vector<double>& ts, double t) {
    const auto it = std::upper_bound(ts.begin(), ts.end(), t);
    const std::size_t i = static_cast<std::size_t>(it - ts.begin());
    return std::min(i == 0 ? 0 : i - 1, ts.size() - 2);
}

void require_finite(const std::string& field, double v, const std::string& what) {
    if (!std::isfinite(v)) throw InputError(field, "value " + format_value(v) + " is not allowed: " + what + " must be finite");
}

}  // namespace

STACKBEAM_ENUM_WORDS(TimeFunction::Shape, {TimeFunction::Shape::constant, "constant"},
    {TimeFunction::Shape::harmonic, "harmonic"}, {TimeFunction::Shape::triangle, "triangle"},
    {TimeFunction::Shape::table, "table"})

STACKBEAM_ENUM_WORDS(LoadingKind, {LoadingKind::initial_conditions, "initial-conditions"},
    {LoadingKind::applied_force, "applied-force"}, {LoadingKind::prescribed_displacement, "prescribed-displacement"},
    {LoadingKind::base_excitation, "base-excitation"})

const char* to_string(TimeFunction::Shape shape) { return word_of(shape); }
const char* to_string(LoadingKind kind) { return word_of(kind); }

void TimeFunction::validate(const std::string& field, bool smooth) const {
    require_finite(field + ".mean", mean, "the mean");
    if (shape == Shape::harmonic || shape == Shape::triangle) {
        if (!std::isfinite(amplitude) || amplitude < 0.0)
            throw InputError(field + ".amplitude", "value " + format_value(amplitude) +
                                                       " is not allowed: the amplitude must be finite and >= 0");
        if (!std::isfinite(frequency_hz) || frequency_hz <= 0.0)
            throw InputError(field + ".frequency_hz", "value " + format_value(frequency_hz) +
                                                          " is not allowed: the frequency must be finite and > 0 [Hz]");
        require_finite(field + ".phase_rad", phase_rad, "the phase");
    }
    if (shape == Shape::triangle && smooth)
        throw InputError(field + ".shape", "value 'triangle' is not allowed here: a base displacement, or a rig's "
                                           "displacement with leaf mass, needs a continuous acceleration (its "
                                           "inertial force; a triangle's velocity jumps at its turning points); use "
                                           "harmonic or table (a table is then a C2 spline)");
    if (shape == Shape::table) {
        if (times_s.size() < 2)
            throw InputError(field + ".times_s", "has " + std::to_string(times_s.size()) +
                                                     " points: a table needs at least 2");
        if (values.size() != times_s.size())
            throw InputError(field + ".values", "has " + std::to_string(values.size()) + " values for " +
                                                    std::to_string(times_s.size()) + " times: give one value per time");
        for (std::size_t i = 0; i < times_s.size(); ++i) {
            const std::string ti = field + ".times_s[" + std::to_string(i) + "]";
            require_finite(ti, times_s[i], "a time");
            require_finite(field + ".values[" + std::to_string(i) + "]", values[i], "a value");
            if (i > 0 && !(times_s[i] > times_s[i - 1]))
                throw InputError(ti, "value " + format_value(times_s[i]) + " is not allowed: the times must increase "
                                     "strictly (previous " + format_value(times_s[i - 1]) + ")");
        }
    }
}

void TimeFunction::prepare(bool smooth) {
    spline_m2.clear();
    if (shape != Shape::table || !smooth) return;
    // Clamped cubic spline (zero slope at both ends): tridiagonal system for the
    // second derivatives M_i, solved by the Thomas algorithm.
    const std::size_t n = times_s.size();
    std::vector<double> a(n, 0.0), b(n, 0.0), c(n, 0.0), r(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
        const double hl = i > 0 ? times_s[i] - times_s[i - 1] : 0.0;
        const double hr = i + 1 < n ? times_s[i + 1] - times_s[i] : 0.0;
        const double sl = i > 0 ? (values[i] - values[i - 1]) / hl : 0.0;      // slope 0 before the first point
        const double sr = i + 1 < n ? (values[i + 1] - values[i]) / hr : 0.0;  // and after the last
        a[i] = hl;
        b[i] = 2.0 * (hl + hr);
        c[i] = hr;
        r[i] = 6.0 * (sr - sl);
    }
    for (std::size_t i = 1; i < n; ++i) {
        const double m = a[i] / b[i - 1];
        b[i] -= m * c[i - 1];
        r[i] -= m * r[i - 1];
    }
    spline_m2.assign(n, 0.0);
    spline_m2[n - 1] = r[n - 1] / b[n - 1];
    for (std::size_t i = n - 1; i-- > 0;) spline_m2[i] = (r[i] - c[i] * spline_m2[i + 1]) / b[i];
}

void ExternalSamples::set(double t, double v, double d, double dd) {
    const auto keep = static_cast<std::size_t>(std::lower_bound(times_s.begin(), times_s.end(), t) - times_s.begin());
    times_s.resize(keep);
    values.resize(keep);
    derivatives.resize(keep);
    second_derivatives.resize(keep);
    times_s.push_back(t);
    values.push_back(v);
    derivatives.push_back(d);
    second_derivatives.push_back(dd);
}

namespace {
/// The first-order hold of ExternalSamples: ys at the samples' times exactly, linear between.
double hold(const std::vector<double>& ts, const std::vector<double>& ys, double t) {
    if (ts.empty()) return 0.0;
    if (t <= ts.front()) return ys.front();
    if (t >= ts.back()) return ys.back();
    const std::size_t i = interval(ts, t);
    if (t == ts[i]) return ys[i];
    const double h = ts[i + 1] - ts[i];
    return (ys[i] * (ts[i + 1] - t) + ys[i + 1] * (t - ts[i])) / h;
}
}  // namespace

double ExternalSamples::value(double t) const { return hold(times_s, values, t); }
double ExternalSamples::derivative(double t) const { return hold(times_s, derivatives, t); }
double ExternalSamples::second_derivative(double t) const { return hold(times_s, second_derivatives, t); }

double TimeFunction::value(double t) const {
    if (external) return external->value(t);
    switch (shape) {
        case Shape::constant: return mean;
        case Shape::harmonic: return mean + amplitude * std::sin(kTwoPi * frequency_hz * t + phase_rad);
        case Shape::triangle: {
            const double x = frac(frequency_hz * t + phase_rad / kTwoPi);
            const double tri = x < 0.25 ? 4.0 * x : x < 0.75 ? 2.0 - 4.0 * x : 4.0 * x - 4.0;
            return mean + amplitude * tri;
        }
        case Shape::table: {
            if (t <= times_s.front()) return values.front();
            if (t >= times_s.back()) return values.back();
            const std::size_t i = interval(times_s, t);
            const double h = times_s[i + 1] - times_s[i], A = times_s[i + 1] - t, B = t - times_s[i];
            if (spline_m2.empty()) return (values[i] * A + values[i + 1] * B) / h;
            const double Mi = spline_m2[i], Mj = spline_m2[i + 1];
            return Mi * A * A * A / (6 * h) + Mj * B * B * B / (6 * h) + (values[i] / h - Mi * h / 6) * A +
                   (values[i + 1] / h - Mj * h / 6) * B;
        }
    }
    return 0.0;
}

double TimeFunction::derivative(double t) const {
    if (external) return external->derivative(t);
    switch (shape) {
        case Shape::constant: return 0.0;
        case Shape::harmonic:
            return amplitude * kTwoPi * frequency_hz * std::cos(kTwoPi * frequency_hz * t + phase_rad);
        case Shape::triangle: {
            const double x = frac(frequency_hz * t + phase_rad / kTwoPi);
            return (x < 0.25 || x >= 0.75 ? 4.0 : -4.0) * amplitude * frequency_hz;
        }
        case Shape::table: {
            if (t < times_s.front() || t >= times_s.back()) return 0.0;
            const std::size_t i = interval(times_s, t);
            const double h = times_s[i + 1] - times_s[i], A = times_s[i + 1] - t, B = t - times_s[i];
            if (spline_m2.empty()) return (values[i + 1] - values[i]) / h;
            const double Mi = spline_m2[i], Mj = spline_m2[i + 1];
            return -Mi * A * A / (2 * h) + Mj * B * B / (2 * h) - (values[i] / h - Mi * h / 6) +
                   (values[i + 1] / h - Mj * h / 6);
        }
    }
    return 0.0;
}

double TimeFunction::second_derivative(double t) const {
    if (external) return external->second_derivative(t);
    switch (shape) {
        case Shape::constant:
        case Shape::triangle: return 0.0;  // triangle: impulses at the turning points (refused where it matters)
        case Shape::harmonic: {
            const double om = kTwoPi * frequency_hz;
            return -amplitude * om * om * std::sin(om * t + phase_rad);
        }
        case Shape::table: {
            if (spline_m2.empty() || t < times_s.front() || t > times_s.back()) return 0.0;
            const std::size_t i = interval(times_s, t);
            const double h = times_s[i + 1] - times_s[i], A = times_s[i + 1] - t, B = t - times_s[i];
            return (spline_m2[i] * A + spline_m2[i + 1] * B) / h;
        }
    }
    return 0.0;
}

double TimeFunction::period_s() const {
    return (shape == Shape::harmonic || shape == Shape::triangle) && frequency_hz > 0.0 ? 1.0 / frequency_hz : 0.0;
}

void Loading::validate(bool leaf_mass) const {
    if (!std::isfinite(gravity_m_per_s2) || gravity_m_per_s2 < 0.0)
        throw InputError("loading.gravity_m_per_s2", "value " + format_value(gravity_m_per_s2) +
                                                         " is not allowed: g must be finite and >= 0 [m/s^2] (it acts in -y)");
    switch (kind) {
        case LoadingKind::initial_conditions: break;
        case LoadingKind::applied_force: force_n.validate("loading.force_n", false); break;
        case LoadingKind::prescribed_displacement:
            displacement_m.validate("loading.displacement_m", leaf_mass);
            if (gravity_m_per_s2 != 0.0)
                throw InputError("loading.gravity_m_per_s2",
                                 "value " + format_value(gravity_m_per_s2) +
                                     " is not allowed with a prescribed displacement: the rig holds R, so its weight "
                                     "does not load the spring (give 0, or shift the displacement's mean)");
            break;
        case LoadingKind::base_excitation: displacement_m.validate("loading.displacement_m", true); break;
    }
    // seat loads and the windup rig (loading.hpp)
    if (seat_moment_n_m) seat_moment_n_m->validate("loading.seat_moment_n_m", false);
    if (longitudinal_force_n) longitudinal_force_n->validate("loading.longitudinal_force_n", false);
    if (!std::isfinite(longitudinal_force_height_m))
        throw InputError("loading.longitudinal_force_height_m", "value " + format_value(longitudinal_force_height_m) +
                                                                    " is not allowed: the height [m] must be finite");
    if (longitudinal_force_height_m != 0.0 && !longitudinal_force_n)
        throw InputError("loading.longitudinal_force_height_m",
                         "value " + format_value(longitudinal_force_height_m) +
                             " is given without a longitudinal force (loading.longitudinal_force_n): give both, or remove it");
    if (seat_rotation_rad) {
        seat_rotation_rad->validate("loading.seat_rotation_rad", leaf_mass);
        if (seat_moment_n_m)
            throw InputError("loading.seat_moment_n_m", "is given together with a prescribed seat rotation "
                                                        "(loading.seat_rotation_rad): the windup rig's moment is a result; give one of them");
        if (kind == LoadingKind::base_excitation)
            throw InputError("loading.seat_rotation_rad", "is not available with kind = 'base-excitation': the windup rig "
                                                          "holds the seat vertically (kind 'prescribed-displacement') or "
                                                          "leaves it free under a force (kinds 'initial-conditions', 'applied-force')");
        // "zero" to rounding of the shape's own scale (sin(-pi/2) + 1, cos(-pi/2) are not exactly 0)
        const TimeFunction& f = *seat_rotation_rad;
        double scale = std::abs(f.mean) + f.amplitude, rate_scale = 2.0 * 3.14159265358979323846 * f.frequency_hz;
        for (double v : f.values) scale = std::max(scale, std::abs(v));
        if (f.times_s.size() >= 2) rate_scale = 1.0 / (f.times_s[1] - f.times_s[0]);
        const double theta0 = f.value(0.0);
        if (std::abs(theta0) > 1e-12 * scale)
            throw InputError("loading.seat_rotation_rad", "has the value " + format_value(theta0) +
                                                          " rad at t = 0: the run starts from the unwound seat, so theta_R(0) must be 0 "
                                                          "(a harmonic's phase or a table's first value)");
        // with leaf mass the rig's motion loads the leaves' inertia, and the run starts them at rest
        if (leaf_mass && std::abs(seat_rotation_rad->derivative(0.0)) > 1e-12 * scale * rate_scale)
            throw InputError("loading.seat_rotation_rad", "has the rate " + format_value(seat_rotation_rad->derivative(0.0)) +
                                                          " rad/s at t = 0: with leaf mass the run starts at rest, so theta_R'(0) "
                                                          "must be 0 (a harmonic from rest: mean = amplitude, phase_rad = -pi/2)");
    }
}

double Loading::seat_moment_n_m_at(double t) const {
    double M = seat_moment_n_m ? seat_moment_n_m->value(t) : 0.0;
    if (longitudinal_force_n) M -= longitudinal_force_n->value(t) * longitudinal_force_height_m;  // H at h: -H h
    return M;
}

double Loading::longitudinal_force_n_at(double t) const {
    return longitudinal_force_n ? longitudinal_force_n->value(t) : 0.0;
}

void Loading::prepare(bool leaf_mass) {
    validate(leaf_mass);
    force_n.prepare(false);
    if (seat_moment_n_m) seat_moment_n_m->prepare(false);
    if (longitudinal_force_n) longitudinal_force_n->prepare(false);
    if (seat_rotation_rad) seat_rotation_rad->prepare(leaf_mass);
    displacement_m.prepare(kind == LoadingKind::base_excitation ||
                           (leaf_mass && kind == LoadingKind::prescribed_displacement));
}

double Loading::external_force_n(double t, double mass_kg) const {
    if (kind == LoadingKind::prescribed_displacement) return 0.0;  // the rig's force is a result
    double F = -mass_kg * gravity_m_per_s2;
    if (kind == LoadingKind::applied_force) F += force_n.value(t);
    if (kind == LoadingKind::base_excitation) F -= mass_kg * displacement_m.second_derivative(t);
    return F;
}

double Loading::base_displacement_m(double t) const {
    return kind == LoadingKind::base_excitation ? displacement_m.value(t) : 0.0;
}

double Loading::base_velocity_m_per_s(double t) const {
    return kind == LoadingKind::base_excitation ? displacement_m.derivative(t) : 0.0;
}

double Loading::period_s() const {
    double period = 0.0;
    switch (kind) {
        case LoadingKind::applied_force: period = force_n.period_s(); break;
        case LoadingKind::prescribed_displacement:
        case LoadingKind::base_excitation: period = displacement_m.period_s(); break;
        case LoadingKind::initial_conditions: break;
    }
    if (period == 0.0 && seat_rotation_rad) period = seat_rotation_rad->period_s();  // the windup rig's
    return period;
}

}  // namespace stackbeam
