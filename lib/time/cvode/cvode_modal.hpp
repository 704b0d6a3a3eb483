#pragma once
// Internal: mode "cvode" with leaf inertia by retained modes on stacks with friction
// (cvode_modal.cpp, docs/time-integration.md).
#include "stackbeam/time/simulation.hpp"
#include "time/cvode/event_driver.hpp"
#include "time/initial_state.hpp"

namespace stackbeam::detail {

/// Mode "cvode" with leaf inertia on stacks with friction (pairs that stick, slip, open
/// and close): the retained modes of the stack below CvodeOptions::modal_cutoff_rad_per_s
/// carry the inertia, the modes above it respond quasi-statically (residual
/// flexibility), so the contact points are massless and the events are those of the
/// massless cvode mode (docs/time-integration.md).
class CvodeModalStepper final : public EventStepper {
public:
    /// From the shared set-up stage's state (initial_state.hpp; the options checked there).
    CvodeModalStepper(const System& system, const InitialState& start);

private:
    struct Impl;
};

}  // namespace stackbeam::detail
