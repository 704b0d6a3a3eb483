#pragma once
// Internal: how make_stepper builds the public massless cvode stepper (stackbeam/time/
// cvode_stepper.hpp) from the shared set-up stage; the public header names only the friendship.
#include <memory>

#include "stackbeam/time/cvode_stepper.hpp"
#include "time/initial_state.hpp"

namespace stackbeam {

struct CvodeStepperAccess {
    /// The massless cvode stepper from the set-up stage's state (initial_state.hpp; the options checked there).
    static std::unique_ptr<Stepper> build(const System& system, const detail::InitialState& start);
};

}  // namespace stackbeam
