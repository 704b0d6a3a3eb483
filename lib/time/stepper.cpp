// make_stepper: the stepper chosen from the registry (stepper_registry.hpp), the options checked
// against its row and the initial state computed once (initial_state.hpp), then built.
#include "stackbeam/time/stepper.hpp"

#include "time/initial_state.hpp"
#include "time/stepper_registry.hpp"

namespace stackbeam {

std::unique_ptr<Stepper> make_stepper(const System& system, const SimulationOptions& options) {
    options.validate();
    const detail::StepperCapabilities& row = detail::choose_stepper(system, options);
    return row.build(system, detail::initial_state(row, system, options));
}

}  // namespace stackbeam
