#pragma once
// Internal, for tests: switches of the event-driven cvode steppers that are no user
// options (tests/ have lib/ on their include path).
namespace stackbeam::detail {

struct CvodeTesting {
    /// Locate transitions by CVODE's root-finding (the mode's method). false: only the
    /// per-step contact check finds them, by bisection on the dense output, to test
    /// that safety net alone (cvode_stepper.hpp).
    bool root_finding = true;
};

}  // namespace stackbeam::detail
