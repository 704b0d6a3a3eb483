// Simulation options, the record columns and simulate(): the loop over the steppers.
#include "stackbeam/time/simulation.hpp"
#include "stackbeam/time/option_table.hpp"

#include <cmath>
#include <limits>

#include "stackbeam/errors.hpp"
#include "stackbeam/time/stepper.hpp"
#include "time/record_loop.hpp"

namespace stackbeam {

std::vector<std::string> step_record_columns() {
    return {"t",           "w",              "w_dot",          "force_on_mass",     "probe_friction_force",
            "contact_iterations", "n_stick", "n_slip",         "n_open",            "kinetic_energy",
            "strain_energy", "dissipated_energy", "energy_balance_error", "contact_residual", "factorizations",
            "spring_force", "external_force", "base_displacement", "external_work", "leaf_kinetic_energy",
            "impact_loss", "damping_energy", "seat_rotation", "seat_moment", "seat_axial"};
}

std::vector<double> step_record_values(const StepRecord& r) {
    return {r.t_s,
            r.w_m,
            r.w_dot_m_per_s,
            r.force_on_mass_n,
            r.probe_friction_force_n,
            static_cast<double>(r.contact_iterations),
            static_cast<double>(r.n_stick),
            static_cast<double>(r.n_slip),
            static_cast<double>(r.n_open),
            r.kinetic_energy_j,
            r.strain_energy_j,
            r.dissipated_energy_j,
            r.energy_balance_error_j,
            r.contact_residual_m,
            static_cast<double>(r.factorizations),
            r.spring_force_n,
            r.external_force_n,
            r.base_displacement_m,
            r.external_work_j,
            r.leaf_kinetic_energy_j,
            r.impact_loss_j,
            r.damping_energy_j,
            r.seat_rotation_rad,
            r.seat_moment_n_m,
            r.seat_axial_m};
}

STACKBEAM_ENUM_WORDS(Mode, {Mode::closed_form, "closed-form"}, {Mode::cvode, "cvode"}, {Mode::newmark, "newmark"})

STACKBEAM_ENUM_WORDS(LeafInertia, {LeafInertia::automatic, "auto"}, {LeafInertia::massive, "massive"},
    {LeafInertia::modal, "modal"})

const char* to_string(Mode m) { return word_of(m); }
const char* to_string(LeafInertia kind) { return word_of(kind); }

Mode parse_mode(const std::string& text, const std::string& field) {
    return parse_word<Mode>(text, field, "mode");
}

LeafInertia parse_leaf_inertia(const std::string& text, const std::string& field) {
    return parse_word<LeafInertia>(text, field, "leaf-inertia formulation");
}

ContactPath choose_contact_path(const System& system, const SimulationOptions& options) {
    return resolve_contact_path(options.contact_path, system.num_components(), options.solver.kind);
}

void SimulationOptions::validate() const {
    // Every number of the option table (option_table.hpp) in its range; field(): the member's path.
    for (const OptionSpec& spec : simulation_option_table())
        if (spec.type != OptionSpec::Type::keyword) check_option(spec, spec.get(*this));
    if (t_end_s / dt_s > 1e9)
        throw InputError("dt_s", "value " + format_value(dt_s) + " gives more than 1e9 steps to t_end_s = " + format_value(t_end_s) + " s");
    solver.validate();
    loading.validate();
    if (restitution > 0.0 && mode != Mode::newmark)
        throw InputError("restitution", "value " + format_value(restitution) + " is not used by mode " + to_string(mode) +
                                            ": only mode newmark with massive leaves has impacts (give 0)");
    if (mode == Mode::cvode && contact_path == ContactPath::sparse)
        throw InputError("contact_path", "value 'sparse' is not available in mode cvode: its mode sets are factorised "
                                         "on the dense compliance C' (use auto or dense)");
    if (contact_path == ContactPath::sparse && solver.kind != SolverKind::exact)
        throw InputError("contact_path", std::string("value 'sparse' needs the exact solver (solver is '") +
                                             to_string(solver.kind) + "')");
}

void require_loading_fits(const ModelSpec& model, const Loading& loading) {
    const auto& rb = model.rigid_body;
    // seat loads and the windup rig (loading.hpp): not symmetric, so the full model; H needs a sliding seat
    const char* seat_key = loading.seat_moment_n_m ? "loading.seat_moment_n_m"
                           : loading.longitudinal_force_n ? "loading.longitudinal_force_n"
                           : loading.seat_rotation_rad ? "loading.seat_rotation_rad"
                                                       : nullptr;
    if (seat_key && model.symmetry == Symmetry::half)
        throw InputError(seat_key, "is not available on the half model (mesh.symmetry = 'half'): a load that turns or "
                                   "pushes the seat is not symmetric about it; use mesh.symmetry = 'full'");
    if (loading.longitudinal_force_n && !seat_slides(model))
        throw InputError("loading.longitudinal_force_n",
                         std::string("needs a seat that slides, but the seat locates the stack axially (rigid_body.axial = '") +
                             to_string(rb.axial) + "'" + (ends_locate_axially(model) ? "" : ", and no end holds it axially") +
                             "): give rigid_body.axial = 'free' with an end that locates the stack (a hinged eye, an inclined "
                             "shackle or a bushing with bushing_x_n_per_m > 0)");
    if (loading.seat_rotation_rad && loading.kind != LoadingKind::prescribed_displacement) {
        // the seat free vertically under the windup rig is quasi-static: no initial motion of R
        if (rb.initial_displacement_m != 0.0)
            throw InputError("rigid_body.initial_displacement_m",
                             "value " + format_value(rb.initial_displacement_m) +
                                 " is not allowed with the windup rig (loading.seat_rotation_rad): the seat follows the "
                                 "rig quasi-statically (give 0)");
        if (rb.initial_velocity_m_per_s != 0.0)
            throw InputError("rigid_body.initial_velocity_m_per_s",
                             "value " + format_value(rb.initial_velocity_m_per_s) +
                                 " is not allowed with the windup rig (loading.seat_rotation_rad): the seat follows the "
                                 "rig quasi-statically (give 0)");
    }
    if (loading.kind == LoadingKind::prescribed_displacement) {
        if (rb.initial_displacement_m != 0.0)
            throw InputError("rigid_body.initial_displacement_m",
                             "value " + format_value(rb.initial_displacement_m) +
                                 " is not allowed with a prescribed displacement: w(0) is the prescribed w(0) (give 0)");
        if (rb.initial_velocity_m_per_s != 0.0)
            throw InputError("rigid_body.initial_velocity_m_per_s",
                             "value " + format_value(rb.initial_velocity_m_per_s) +
                                 " is not allowed with a prescribed displacement: w'(0) is the prescribed one (give 0)");
    }
}

long detail::record_steps(const SimulationOptions& options) {
    return static_cast<long>(std::ceil(options.t_end_s / options.dt_s - 1e-9));
}

RunReport detail::run_records(const System& system, const SimulationOptions& options,
                              const std::function<void(const Stepper&, const StepRecord&)>& on_record) {
    const std::unique_ptr<Stepper> stepper = make_stepper(system, options);  // validates the options
    const long n = record_steps(options);
    for (long i = 0; i <= n; ++i) {
        // the caller's stop check between outputs (mode cvode also polls it inside a step: event_driver.hpp)
        if (i > 0 && options.stop_requested && options.stop_requested())
            throw RunStopped("stopped on request at t = " + format_value(stepper->current().t_s) + " s (the last output)",
                             stepper->report().steps, stepper->current().t_s);
        on_record(*stepper, i == 0 ? stepper->current() : stepper->advance());
    }
    return stepper->report();
}

std::vector<StepRecord> simulate(const System& system, const SimulationOptions& options,
                                 const std::function<void(const StepRecord&)>& on_step, RunReport* report,
                                 const PairObserver& on_pairs, const NodeObserver& on_nodes) {
    std::vector<StepRecord> out;
    const RunReport r = detail::run_records(system, options, [&](const Stepper& stepper, const StepRecord& record) {
        if (out.empty()) out.reserve(static_cast<std::size_t>(detail::record_steps(options)) + 1);  // options valid now
        out.push_back(record);
        if (on_step) on_step(record);
        if (on_pairs) on_pairs(record.t_s, stepper.pairs());
        if (on_nodes) on_nodes(record.t_s, stepper.nodes());
    });
    if (report) *report = r;
    return out;
}

}  // namespace stackbeam
