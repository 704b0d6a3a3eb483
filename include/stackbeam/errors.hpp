#pragma once
/// @file errors.hpp
/// Exceptions thrown by stackbeam. Every message names the parameter, the value
/// and what is allowed (InputError), or carries the diagnostics of a numerical
/// failure (SolverError).
#include <stdexcept>
#include <string>

namespace stackbeam {

/// Bad input: a field of a model or option out of range, inconsistent geometry.
/// `field()` is the path of the offending field, e.g. "leaves[2].height_m"; what() is
/// "field: message", or "location: field: message" when the input has a place, e.g.
/// "paper.toml:87:8: integrator.cvode.rtol: value 1 is not allowed: ..." (a scenario file).
class InputError : public std::invalid_argument {
public:
    InputError(std::string field, const std::string& message)
        : std::invalid_argument(field + ": " + message), field_(std::move(field)) {}
    /// `location`: where the value is written, "file:line:column".
    InputError(std::string field, const std::string& message, std::string location)
        : std::invalid_argument(location + ": " + field + ": " + message),
          field_(std::move(field)),
          location_(std::move(location)) {}
    const std::string& field() const noexcept { return field_; }
    const std::string& location() const noexcept { return location_; }  ///< "" if none

private:
    std::string field_;
    std::string location_;
};

/// A numerical procedure that did not reach its goal: a contact iteration that
/// hit its iteration limit, a time integrator failure. Carries where it happened.
class SolverError : public std::runtime_error {
public:
    SolverError(const std::string& message, long step, double time_s, double residual)
        : std::runtime_error(message), step_(step), time_s_(time_s), residual_(residual) {}
    long step() const noexcept { return step_; }         ///< step index (1-based) at failure
    double time_s() const noexcept { return time_s_; }   ///< time at failure [s]
    double residual() const noexcept { return residual_; } ///< residual reached (solver units)

private:
    long step_;
    double time_s_;
    double residual_;
};

/// A run stopped because its caller asked for it (SimulationOptions::stop_requested returned
/// true, e.g. on SIGINT in the command line): not a failure. Carries where the run stood.
class RunStopped : public std::runtime_error {
public:
    RunStopped(const std::string& message, long step, double time_s)
        : std::runtime_error(message), step_(step), time_s_(time_s) {}
    long step() const noexcept { return step_; }        ///< the integrator's steps so far
    double time_s() const noexcept { return time_s_; }  ///< the last accepted time [s]

private:
    long step_;
    double time_s_;
};

/// Formats "value" for messages with full precision.
std::string format_value(double value);

}  // namespace stackbeam
