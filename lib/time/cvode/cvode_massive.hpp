#pragma once
// Internal: mode "cvode" with the whole massive stack on elastic interfaces (cvode_massive.cpp).
#include "stackbeam/time/simulation.hpp"
#include "time/cvode/event_driver.hpp"
#include "time/initial_state.hpp"

namespace stackbeam::detail {

/// Mode "cvode" with leaf inertia on stacks with friction and an elastic layer on every
/// contact row: the whole massive stack in CVODE, BDF with Newton, events on every
/// transition (cvode_massive.cpp, docs/time-integration.md). Rigid contact rows are refused
/// where it is chosen (its row of the registry, stepper_registry.hpp).
class CvodeMassiveStepper final : public EventStepper {
public:
    /// From the shared set-up stage's state (initial_state.hpp; the options checked there).
    CvodeMassiveStepper(const System& system, const InitialState& start);

private:
    struct Impl;
};

}  // namespace stackbeam::detail
