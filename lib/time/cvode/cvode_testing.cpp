// The test-only switches of the event-driven cvode steppers (cvode_testing.hpp).
#include "time/cvode/cvode_testing.hpp"

namespace stackbeam::detail {

namespace {
thread_local CvodeTesting current_testing;
}  // namespace

const CvodeTesting& cvode_testing() noexcept { return current_testing; }

ScopedCvodeTesting::ScopedCvodeTesting(const CvodeTesting& testing) : previous_(current_testing) {
    current_testing = testing;
}

ScopedCvodeTesting::~ScopedCvodeTesting() { current_testing = previous_; }

}  // namespace stackbeam::detail
