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
            // leaf inertia (docs/time-integration.md): the whole massive stack where every contact
            // row has an elastic layer and the stack has friction, an assembly or a loading (or when
            // asked for); else, when a pair may stick or slip, the modal stepper, and the
            // held-for-good one for bonded and frictionless stacks under the paper's initial
            // conditions (it takes no assembly and no other loading)
            {
                const LeafInertia li = options.cvode.leaf_inertia;
                const bool elastic = detail::first_rigid_pair(system) < 0;
                const bool changes = detail::has_mode_changes(system);
                const ModelSpec& spec = system.model().spec();
                const bool assembled = needs_assembly(spec);
                if (li == LeafInertia::massive ||
                    (li == LeafInertia::automatic && elastic && (changes || assembled || !options.loading.is_free())))
                    return std::make_unique<detail::CvodeMassiveStepper>(system, options);
                if (changes) return std::make_unique<detail::CvodeModalStepper>(system, options);
                return std::make_unique<detail::CvodeHeldStepper>(system, options);
            }
    }
    return std::make_unique<ClosedFormStepper>(system, options);
}

}  // namespace stackbeam
