#pragma once
// Internal: mode "cvode" with the whole massive stack on elastic interfaces (cvode_massive.cpp).
#include "stackbeam/time/simulation.hpp"
#include "time/cvode/event_driver.hpp"

namespace stackbeam::detail {

/// Mode "cvode" with leaf inertia on stacks with friction and an elastic layer on every
/// contact row: the whole massive stack in CVODE, BDF with Newton, events on every
/// transition (cvode_massive.cpp, docs/time-integration.md). Refuses a rigid contact row
/// (InputError naming the interface's contact or the clamp's length_m).
class CvodeMassiveStepper final : public EventStepper {
public:
    CvodeMassiveStepper(const System& system, const SimulationOptions& options);

private:
    struct Impl;
};

}  // namespace stackbeam::detail
