// make_stepper: the mode and leaf-mass dispatch (stepper.hpp), decided once.
#include "stackbeam/time/stepper.hpp"

#include "stackbeam/time/closed_form_stepper.hpp"
#include "stackbeam/time/cvode_stepper.hpp"
#include "stackbeam/time/newmark_stepper.hpp"
#include "time/cvode/cvode_inertia.hpp"

namespace stackbeam {

std::unique_ptr<Stepper> make_stepper(const System& system, const SimulationOptions& options) {
    if (options.mode != Mode::closed_form) require_no_assembly(system.model().spec(), options.mode);
    switch (options.mode) {
        case Mode::closed_form: return std::make_unique<ClosedFormStepper>(system, options);
        case Mode::newmark: return std::make_unique<NewmarkStepper>(system, options);
        case Mode::cvode:
            if (!detail::has_leaf_mass(system)) return std::make_unique<CvodeStepper>(system, options);
            // leaf inertia (docs/time-integration.md): modal with events when a pair may stick or slip
            if (detail::has_mode_changes(system)) return std::make_unique<detail::CvodeModalStepper>(system, options);
            return std::make_unique<detail::CvodeInertiaStepper>(system, options);
    }
    return std::make_unique<ClosedFormStepper>(system, options);
}

}  // namespace stackbeam
