// make_stepper: the mode and leaf-mass dispatch (stepper.hpp), decided once.
#include "stackbeam/time/stepper.hpp"

#include "stackbeam/time/closed_form_stepper.hpp"
#include "stackbeam/time/cvode_stepper.hpp"
#include "stackbeam/time/newmark_stepper.hpp"
#include "time/cvode/cvode_inertia.hpp"
#include "stackbeam/errors.hpp"

namespace stackbeam {

namespace {

/// Structural damping is taken by the massive-stack stepper only: elsewhere it is refused,
/// never ignored.
void require_no_damping(const SimulationOptions& options, const std::string& stepper) {
    const StructuralDamping& c = options.damping;
    if (!c.active()) return;
    const bool alpha = c.rayleigh_alpha_per_s > 0.0;
    throw InputError(alpha ? "damping.rayleigh_alpha_per_s" : "damping.rayleigh_beta_s",
                     "value " + format_value(alpha ? c.rayleigh_alpha_per_s : c.rayleigh_beta_s) +
                         ": structural damping is taken by mode cvode with the massive stack only (leaves with "
                         "mass, friction, an elastic layer on every contact row), not by " + stepper + " (give 0)");
}

}  // namespace

std::unique_ptr<Stepper> make_stepper(const System& system, const SimulationOptions& options) {
    if (options.mode != Mode::closed_form) require_no_assembly(system.model().spec(), options.mode);
    switch (options.mode) {
        case Mode::closed_form:
            require_no_damping(options, "mode closed-form");
            return std::make_unique<ClosedFormStepper>(system, options);
        case Mode::newmark:
            require_no_damping(options, "mode newmark");
            return std::make_unique<NewmarkStepper>(system, options);
        case Mode::cvode:
            if (!detail::has_leaf_mass(system)) {
                require_no_damping(options, "mode cvode with massless leaves");
                return std::make_unique<CvodeStepper>(system, options);
            }
            // leaf inertia (docs/time-integration.md): with events when a pair may stick or slip,
            // the whole massive stack where every contact row has an elastic layer, else modal
            if (detail::has_mode_changes(system)) {
                const LeafInertia li = options.cvode.leaf_inertia;
                if (li == LeafInertia::massive || (li == LeafInertia::automatic && !detail::has_rigid_contact_row(system)))
                    return std::make_unique<detail::CvodeMassiveStepper>(system, options);
                require_no_damping(options, "mode cvode with modal leaf inertia");
                return std::make_unique<detail::CvodeModalStepper>(system, options);
            }
            require_no_damping(options, "mode cvode with a bonded or frictionless stack");
            return std::make_unique<detail::CvodeInertiaStepper>(system, options);
    }
    return std::make_unique<ClosedFormStepper>(system, options);
}

}  // namespace stackbeam
