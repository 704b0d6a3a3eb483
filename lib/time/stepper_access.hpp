#pragma once
// Internal: how make_stepper (the registry's rows, stepper_registry.cpp) builds the public
// closed-form and newmark steppers from the shared set-up stage's state (initial_state.hpp). Their
// public headers name only the friendship; the massless cvode stepper's is cvode/cvode_massless.hpp.
#include <memory>

#include "stackbeam/fe/system.hpp"
#include "stackbeam/time/stepper.hpp"

namespace stackbeam {

namespace detail {
struct InitialState;  // initial_state.hpp
}

struct ClosedFormStepperAccess {
    /// The closed-form stepper from the set-up stage's state (the options checked there).
    static std::unique_ptr<Stepper> build(const System& system, const detail::InitialState& start);
};

struct NewmarkStepperAccess {
    /// The newmark stepper (massless or massive leaves) from the set-up stage's state.
    static std::unique_ptr<Stepper> build(const System& system, const detail::InitialState& start);
};

}  // namespace stackbeam
