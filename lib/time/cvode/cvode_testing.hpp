#pragma once
// Internal, for tests: switches of the event-driven cvode steppers that are no user
// options (tests/ have lib/ on their include path). A test sets them for the steppers it
// constructs while a ScopedCvodeTesting lives; the public headers know nothing of them.
namespace stackbeam::detail {

struct CvodeTesting {
    /// Locate transitions by CVODE's root-finding (the mode's method). false: only the
    /// per-step contact check finds them, by bisection on the dense output, to test
    /// that safety net alone (cvode_stepper.hpp).
    bool root_finding = true;
};

/// The switches an event driver constructed now on this thread takes (the defaults unless
/// a ScopedCvodeTesting is alive).
const CvodeTesting& cvode_testing() noexcept;

/// Sets the switches on this thread for its lifetime; the previous ones come back after.
class ScopedCvodeTesting {
public:
    explicit ScopedCvodeTesting(const CvodeTesting& testing);
    ~ScopedCvodeTesting();
    ScopedCvodeTesting(const ScopedCvodeTesting&) = delete;
    ScopedCvodeTesting& operator=(const ScopedCvodeTesting&) = delete;

private:
    CvodeTesting previous_;
};

}  // namespace stackbeam::detail
