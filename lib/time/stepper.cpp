// make_stepper: the mode and leaf-mass dispatch (stepper.hpp), decided once.
#include "stackbeam/time/stepper.hpp"

#include "stackbeam/time/closed_form_stepper.hpp"
#include "stackbeam/time/cvode_stepper.hpp"
#include "stackbeam/time/newmark_stepper.hpp"
#include "time/cvode/cvode_held.hpp"
#include "time/cvode/cvode_massive.hpp"
#include "time/cvode/cvode_modal.hpp"
#include "time/stack_properties.hpp"

namespace stackbeam {

std::unique_ptr<Stepper> make_stepper(const System& system, const SimulationOptions& options) {
    // each stepper refuses what it does not take (leaf mass, assembly, damping, loadings)
    switch (options.mode) {
        case Mode::closed_form: return std::make_unique<ClosedFormStepper>(system, options);
        case Mode::newmark: return std::make_unique<NewmarkStepper>(system, options);
        case Mode::cvode:
            if (!detail::has_leaf_mass(system)) return std::make_unique<CvodeStepper>(system, options);
            // leaf inertia (docs/time-integration.md "Which leaf-inertia stepper"): with friction the
            // modal stepper (every loading but the rig, the assembly; cheap: the contact layer is
            // massless, so transitions excite no mesh-scale ringing) unless the whole massive stack
            // is asked for, or needed for what only it takes (structural damping, the rig) and every
            // row is elastic, and wherever it is asked for; without friction the held-for-good
            // stepper under the paper's initial conditions, else the massive stack on elastic rows
            // (no transitions: cheap) or the modal one
            {
                const LeafInertia li = options.cvode.leaf_inertia;
                const bool elastic = detail::first_rigid_pair(system) < 0;
                const bool changes = detail::has_mode_changes(system);
                const bool assembled = needs_assembly(system.model().spec());
                const bool rig = options.loading.kind == LoadingKind::prescribed_displacement;
                const bool massive_only = options.damping.active() || rig;
                if (li == LeafInertia::massive || (li == LeafInertia::automatic && elastic && massive_only))
                    return std::make_unique<detail::CvodeMassiveStepper>(system, options);
                if (changes || li == LeafInertia::modal) return std::make_unique<detail::CvodeModalStepper>(system, options);
                if (assembled || !options.loading.is_free()) {
                    if (li == LeafInertia::automatic && elastic)
                        return std::make_unique<detail::CvodeMassiveStepper>(system, options);
                    return std::make_unique<detail::CvodeModalStepper>(system, options);
                }
                return std::make_unique<detail::CvodeHeldStepper>(system, options);
            }
    }
    return std::make_unique<ClosedFormStepper>(system, options);
}

}  // namespace stackbeam
