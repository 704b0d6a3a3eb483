// The steppers make_stepper can build, what each takes, and the one check of the options
// against the chosen one (stepper_registry.hpp).
#include "time/stepper_registry.hpp"

#include <cmath>
#include <functional>
#include <stdexcept>

#include "stackbeam/errors.hpp"
#include "stackbeam/time/cvode_stepper.hpp"
#include "time/cvode/cvode_held.hpp"
#include "time/cvode/cvode_massless.hpp"
#include "time/cvode/cvode_massive.hpp"
#include "time/cvode/cvode_modal.hpp"
#include "time/initial_state.hpp"
#include "time/stack_properties.hpp"
#include "time/stepper_access.hpp"

namespace stackbeam::detail {

namespace {

template <class T>
std::unique_ptr<Stepper> build(const System& system, const InitialState& start) {
    return std::make_unique<T>(system, start);
}

// The rows. Loadings: initial conditions are taken by every stepper; outputs: the record's
// common columns by every one.
std::vector<StepperCapabilities> make_registry() {
    std::vector<StepperCapabilities> rows;
    StepperCapabilities c{};
    c.name = "closed-form";
    c.description = "mode closed-form";
    c.mode = Mode::closed_form;
    c.applied_force = c.base_excitation = c.gravity = c.rig = c.rig_on_rigid_contact = true;
    c.assembly = c.previous_step_tau = c.friction = c.rigid_rows = c.elastic_layer = true;
    // seat loads condensed with theta_R (System::SeatCondensation), also with the vertical rig; the windup
    // rig as theta_R held in that condensation (decision 069); no J (theta_R is not a DOF of its own)
    c.seat_loads = c.seat_loads_with_rig = c.windup_rig = c.windup_rig_on_rigid_contact = true;
    c.start = StartKind::massless_stack;
    c.build = &ClosedFormStepperAccess::build;
    rows.push_back(c);

    c = StepperCapabilities{};
    c.name = "newmark-massless";
    c.description = "mode newmark with massless leaves";
    c.mode = Mode::newmark;
    c.applied_force = c.base_excitation = c.gravity = true;
    c.seat_loads = c.windup_rig = c.windup_rig_on_rigid_contact = c.pitch_inertia = true;
    c.assembly = c.previous_step_tau = c.friction = c.rigid_rows = c.elastic_layer = true;
    c.start = StartKind::whole_stack;
    c.build = &NewmarkStepperAccess::build;
    rows.push_back(c);

    c.name = "newmark-massive";
    c.description = "mode newmark with massive leaves";
    c.massive_leaves = true;
    c.rig = c.damping = c.restitution = true;  // the rig on elastic contact only (the impact law)
    c.windup_rig_on_rigid_contact = false;     // the windup rig too
    c.seat_loads_with_rig = true;
    c.leaf_kinetic_energy = c.impact_loss = true;
    rows.push_back(c);

    c = StepperCapabilities{};
    c.name = "cvode-massless";
    c.description = "mode cvode with massless leaves";
    c.mode = Mode::cvode;
    c.applied_force = c.base_excitation = c.gravity = true;
    c.friction = c.rigid_rows = c.elastic_layer = c.cvode_stats = true;
    c.seat_loads = true;  // condensed as closed-form's, t in the state (decision 069)
    c.start = StartKind::massless_stack;
    c.exact_start = true;
    c.build = &CvodeStepperAccess::build;
    rows.push_back(c);

    c = StepperCapabilities{};
    c.name = "cvode-held";
    c.description = "mode cvode with leaf mass on a bonded or frictionless stack (held-for-good contact)";
    c.mode = Mode::cvode;
    c.massive_leaves = true;
    c.previous_step_tau = true;  // no friction: the limit is never read
    c.rigid_rows = c.elastic_layer = c.leaf_kinetic_energy = c.cvode_stats = true;
    c.start = StartKind::tied_shape;
    c.build = &build<CvodeHeldStepper>;
    rows.push_back(c);

    c = StepperCapabilities{};
    c.name = "cvode-modal";
    c.description = "mode cvode with modal leaf inertia (cvode.leaf_inertia = 'modal')";
    c.mode = Mode::cvode;
    c.massive_leaves = true;
    c.applied_force = c.base_excitation = c.gravity = c.assembly = true;  // every loading but the rig
    c.seat_loads = c.pitch_inertia = true;  // two more channels of the modal load (modal_load.hpp); J in M's modes
    c.friction = c.rigid_rows = c.elastic_layer = c.leaf_kinetic_energy = c.cvode_stats = true;
    c.start = StartKind::whole_stack_static;
    c.build = &build<CvodeModalStepper>;
    rows.push_back(c);

    c = StepperCapabilities{};
    c.name = "cvode-massive";
    c.description = "mode cvode with the whole massive stack (cvode.leaf_inertia = 'massive')";
    c.mode = Mode::cvode;
    c.massive_leaves = true;
    c.applied_force = c.base_excitation = c.gravity = c.rig = true;
    c.seat_loads = c.pitch_inertia = true;  // through q(t) (ReducedLoad) and M
    c.windup_rig = true;                    // theta_R's acceleration prescribed as the rig's w'' (decision 069)
    c.seat_loads_with_rig = true;           // the rig's and the seat loads' work both booked (decision 069)
    c.assembly = c.damping = c.friction = c.elastic_layer = c.leaf_kinetic_energy = c.cvode_stats = true;
    c.layer_damping = true;  // its contact points carry mass: only they vibrate on the layer
    c.start = StartKind::whole_stack_static;
    c.build = &build<CvodeMassiveStepper>;
    rows.push_back(c);
    return rows;
}

/// "taken by A; B; C" from the rows with `takes`, or "taken by no stepper yet".
std::string taken_by(const std::function<bool(const StepperCapabilities&)>& takes) {
    std::string list;
    for (const StepperCapabilities& r : stepper_registry())
        if (takes(r)) list += (list.empty() ? "" : "; ") + std::string(r.description);
    return list.empty() ? "taken by no stepper yet" : "taken by " + list;
}

/// The scenario field that makes contact row `row` of pair kk rigid, for the message.
std::string rigid_row_field(const System& system, int kk) {
    const PairSpec& ps = system.pair_spec(kk);
    const auto& spec = system.model().spec();
    if (ps.kind == PairKind::clamp) {
        for (std::size_t j = 0; j < spec.clamps.size(); ++j)
            if (std::abs(spec.clamps[j].x_m - ps.x_m) <= system.model().x_tolerance_m())
                return "clamps[" + std::to_string(j) + "].length_m";
    }
    return "interfaces[" + std::to_string(ps.interface_index) + "].contact";
}

/// Every leaf massive (density > 0) or every leaf massless: InputError naming the first leaf that
/// differs from leaves[0] (mode `mode_name` cannot run a mix).
void require_uniform_leaf_mass(const System& system, const char* mode_name) {
    const auto& leaves = system.model().spec().leaves;
    for (std::size_t i = 1; i < leaves.size(); ++i)
        if ((leaves[i].density_kg_per_m3 > 0.0) != (leaves[0].density_kg_per_m3 > 0.0))
            throw InputError("leaves[" + std::to_string(i) + "].density_kg_per_m3",
                             "value " + format_value(leaves[i].density_kg_per_m3) + " with leaves[0] at " +
                                 format_value(leaves[0].density_kg_per_m3) + ": mode " + mode_name +
                                 " needs every leaf massive (> 0) or every leaf massless (0)");
}

void check_leaf_mass(const StepperCapabilities& s, const System& system) {
    const auto& leaves = system.model().spec().leaves;
    bool sibling = false;  // a row of the same mode with the other leaf mass: the mode takes both, not a mix
    for (const StepperCapabilities& r : stepper_registry())
        sibling = sibling || (r.mode == s.mode && r.massive_leaves != s.massive_leaves);
    if (sibling || s.massive_leaves) require_uniform_leaf_mass(system, to_string(s.mode));
    if (!s.massive_leaves) {
        for (std::size_t i = 0; i < leaves.size(); ++i)
            if (leaves[i].density_kg_per_m3 != 0.0)
                throw InputError("leaves[" + std::to_string(i) + "].density_kg_per_m3",
                                 "value " + format_value(leaves[i].density_kg_per_m3) + " is not used by " +
                                     s.description + ", which treats the leaves as massless (the paper): give 0 "
                                     "(the leaves' inertia is " + taken_by([](auto& r) { return r.massive_leaves; }) + ")");
    } else if (!has_leaf_mass(system)) {
        throw InputError("leaves[0].density_kg_per_m3",
                         "value 0: " + std::string(s.description) + " needs leaves with mass (massless leaves are " +
                             taken_by([](auto& r) { return !r.massive_leaves; }) + ")");
    }
}

void check_assembly(const StepperCapabilities& s, const ModelSpec& model) {
    if (s.assembly) return;
    const std::string rest = std::string(" is not available in ") + s.description +
                             ": the assembly and the clips' limit are " +
                             taken_by([](auto& r) { return r.assembly; });
    for (std::size_t i = 0; i < model.leaves.size(); ++i)
        for (const auto& [key, v] : {std::pair<const char*, double>{"free_camber_m", model.leaves[i].free_camber_m},
                                     {"free_radius_m", model.leaves[i].free_radius_m}})
            if (v != 0.0)
                throw InputError("leaves[" + std::to_string(i) + "]." + key,
                                 "value " + format_value(v) + ": a free camber" + rest + " (use one of them)");
    if (!model.clips.empty()) throw InputError("clips[0]", "a rebound clip" + rest + " (use one of them)");
    for (std::size_t i = 0; i < model.interfaces.size(); ++i)
        if (model.interfaces[i].initial_gap_m < 0.0)
            throw InputError("interfaces[" + std::to_string(i) + "].initial_gap_m",
                             "value " + format_value(model.interfaces[i].initial_gap_m) +
                                 ": an interference (a gap < 0)" + rest + " (use one of them, or a gap >= 0)");
}

void check_contact(const StepperCapabilities& s, const System& system) {
    const int kk = first_rigid_pair(system);
    if (!s.rigid_rows && kk >= 0) {
        const std::string field = rigid_row_field(system, kk);
        const bool clamp = system.pairs()[kk].kind == PairKind::clamp && field.rfind("clamps", 0) == 0;
        throw InputError(field, std::string("value ") + (clamp ? "0" : "'rigid'") + ": " + s.description +
                                    " needs an elastic layer on every contact row (a rigid contact point with mass "
                                    "has no force law: every transition would be an impulse). Give " +
                                    (clamp ? field + " > 0 on an elastic interface" : field + " = 'elastic'") +
                                    "; rigid contact rows are " + taken_by([](auto& r) { return r.rigid_rows; }));
    }
    if (!s.elastic_layer && system.has_layer())
        throw InputError("interfaces[].contact", "value 'elastic' is not available in " + std::string(s.description) +
                                                     ": the elastic layer is " + taken_by([](auto& r) { return r.elastic_layer; }));
    if (!s.friction && has_mode_changes(system)) {
        for (std::size_t j = 0; j < system.pairs().size(); ++j) {
            const auto& pr = system.pairs()[j];
            if (pr.kind == PairKind::bonded || pr.friction_coefficient == 0.0) continue;
            throw InputError("mode", "value '" + std::string(to_string(s.mode)) + "': " + s.description +
                                         " takes bonded and frictionless pairs only (pair " + std::to_string(j) +
                                         " is " + to_string(pr.kind) + " with mu = " +
                                         format_value(pr.friction_coefficient) + "); friction is " +
                                         taken_by([](auto& r) { return r.friction; }));
        }
    }
}

/// Seat loads and the windup rig (loading.hpp) against the row.
void check_seat_loading(const StepperCapabilities& s, const System& system, const Loading& L) {
    const char* seat_key = L.seat_moment_n_m ? "loading.seat_moment_n_m" : "loading.longitudinal_force_n";
    if (L.has_seat_load() && !s.seat_loads)
        throw InputError(seat_key, "is not available in " + std::string(s.description) + ": seat loads are " +
                                       taken_by([](auto& r) { return r.seat_loads; }));
    if (L.has_seat_load() && L.kind == LoadingKind::prescribed_displacement && !L.windup_rig() && !s.seat_loads_with_rig)
        throw InputError(seat_key, "with kind = 'prescribed-displacement' is not available in " + std::string(s.description) +
                                       ": seat loads with the vertical rig are " +
                                       taken_by([](auto& r) { return r.seat_loads_with_rig; }));
    const double J = system.model().spec().rigid_body.pitch_inertia_kg_m2;
    if (J > 0.0 && !s.pitch_inertia)
        throw InputError("rigid_body.pitch_inertia_kg_m2",
                         "value " + format_value(J) + " is not taken by " + s.description +
                             " (its seat rotation has no inertia: give 0); the axle's pitch inertia is " +
                             taken_by([](auto& r) { return r.pitch_inertia; }));
    if (L.windup_rig() && !s.windup_rig)
        throw InputError("loading.seat_rotation_rad", "is not available in " + std::string(s.description) +
                                                          ": the windup rig is " + taken_by([](auto& r) { return r.windup_rig; }));
    if (L.windup_rig() && !s.windup_rig_on_rigid_contact && first_rigid_pair(system) >= 0)
        throw InputError("loading.seat_rotation_rad", "with rigid contact (pair " + std::to_string(first_rigid_pair(system)) +
                                                          ") is not available in " + s.description +
                                                          " (the impact law would move the rig's seat): give the interfaces an "
                                                          "elastic layer (interfaces[i].contact = 'elastic'); the windup rig on "
                                                          "rigid contact is " +
                                                          taken_by([](auto& r) { return r.windup_rig_on_rigid_contact; }));
}

void check_loading(const StepperCapabilities& s, const System& system, const Loading& L) {
    check_seat_loading(s, system, L);
    // the windup rig holds w by the vertical rig's displacement as part of itself
    const bool windup_holds_w = L.windup_rig() && s.windup_rig;
    const bool takes = L.kind == LoadingKind::initial_conditions ||
                       (L.kind == LoadingKind::applied_force && s.applied_force) ||
                       (L.kind == LoadingKind::base_excitation && s.base_excitation) ||
                       (L.kind == LoadingKind::prescribed_displacement && (s.rig || windup_holds_w));
    const LoadingKind kind = L.kind;
    if (!takes)
        throw InputError("loading.kind", "value '" + std::string(to_string(kind)) + "' is not available in " +
                                             s.description + ": it is " + taken_by([kind](auto& r) {
                                                 return (kind == LoadingKind::applied_force && r.applied_force) ||
                                                        (kind == LoadingKind::base_excitation && r.base_excitation) ||
                                                        (kind == LoadingKind::prescribed_displacement && r.rig);
                                             }));
    if (L.kind == LoadingKind::prescribed_displacement && !s.rig_on_rigid_contact && !windup_holds_w &&
        first_rigid_pair(system) >= 0)
        throw InputError("loading.kind", "value 'prescribed-displacement' with rigid contact (pair " +
                                             std::to_string(first_rigid_pair(system)) + ") is not available in " +
                                             s.description + " (the impact law would move the rig's seat): give the "
                                             "interfaces an elastic layer (interfaces[i].contact = 'elastic'); the rig "
                                             "on rigid contact is " + taken_by([](auto& r) { return r.rig_on_rigid_contact; }));
    if (L.gravity_m_per_s2 != 0.0 && !s.gravity)
        throw InputError("loading.gravity_m_per_s2", "value " + format_value(L.gravity_m_per_s2) + " is not available in " +
                                                         s.description + " (give 0): gravity is " +
                                                         taken_by([](auto& r) { return r.gravity; }));
}

void check_options(const StepperCapabilities& s, const SimulationOptions& o) {
    if (!s.damping && o.damping.active()) {
        const bool alpha = o.damping.rayleigh_alpha_per_s > 0.0;
        throw InputError(alpha ? "damping.rayleigh_alpha_per_s" : "damping.rayleigh_beta_s",
                         "value " + format_value(alpha ? o.damping.rayleigh_alpha_per_s : o.damping.rayleigh_beta_s) +
                             ": structural damping is not taken by " + s.description + " (give 0); it is " +
                             taken_by([](auto& r) { return r.damping; }));
    }
    if (!s.layer_damping && o.damping.layer_normal_time_s > 0.0)
        throw InputError("damping.layer_normal_time_s",
                         "value " + format_value(o.damping.layer_normal_time_s) + ": the elastic layer's normal dashpots "
                             "are not taken by " + s.description + " (give 0; a massless contact layer does not vibrate "
                             "on it); they are " + taken_by([](auto& r) { return r.layer_damping; }));
    if (!s.previous_step_tau && o.tau_rule == TauRule::previous_step)
        throw InputError("tau_rule", "value 'previous-step' is not available in " + std::string(s.description) +
                                         ", which takes the friction limit from the current normal force (tau rule "
                                         "'current'; 'previous-step' is a fixed-step device of the paper, " +
                                         taken_by([](auto& r) { return r.previous_step_tau; }) + ")");
    if (!s.restitution && o.restitution > 0.0)
        throw InputError("restitution", "value " + format_value(o.restitution) + " is not used by " + s.description +
                                            " (no impacts: give 0); restitution is " +
                                            taken_by([](auto& r) { return r.restitution; }));
}

}  // namespace

const std::vector<StepperCapabilities>& stepper_registry() {
    static const std::vector<StepperCapabilities> rows = make_registry();
    return rows;
}

const StepperCapabilities& registered_stepper(const std::string& name) {
    for (const StepperCapabilities& r : stepper_registry())
        if (name == r.name) return r;
    throw std::out_of_range("no stepper '" + name + "' in the registry");
}

const StepperCapabilities& newmark_row(const System& system) {
    const auto& leaves = system.model().spec().leaves;
    return registered_stepper(!leaves.empty() && leaves[0].density_kg_per_m3 > 0.0 ? "newmark-massive"
                                                                                   : "newmark-massless");
}

const StepperCapabilities& choose_stepper(const System& system, const SimulationOptions& options) {
    switch (options.mode) {
        case Mode::closed_form: break;
        case Mode::newmark: return newmark_row(system);
        case Mode::cvode: {
            if (!has_leaf_mass(system)) return registered_stepper("cvode-massless");
            // leaf inertia (docs/time-integration.md "Which leaf-inertia stepper"): with friction the
            // modal stepper (every loading but the rig, the assembly; cheap: the contact layer is
            // massless, so transitions excite no mesh-scale ringing) unless the whole massive stack
            // is asked for, or needed for what only it takes (structural damping, the rigs) and every
            // row is elastic; without friction the held-for-good stepper under the paper's initial
            // conditions, else the massive stack on elastic rows (no transitions: cheap) or the modal one
            const LeafInertia li = options.cvode.leaf_inertia;
            const bool elastic = first_rigid_pair(system) < 0;
            const bool changes = has_mode_changes(system);
            const bool assembled = needs_assembly(system.model().spec());
            const bool massive_only =
                options.damping.active() || options.damping.layer_normal_time_s > 0.0 ||
                options.loading.kind == LoadingKind::prescribed_displacement || options.loading.windup_rig();
            if (li == LeafInertia::massive || (li == LeafInertia::automatic && elastic && massive_only))
                return registered_stepper("cvode-massive");
            if (changes || li == LeafInertia::modal) return registered_stepper("cvode-modal");
            if (assembled || !options.loading.is_free())
                return registered_stepper(li == LeafInertia::automatic && elastic ? "cvode-massive" : "cvode-modal");
            return registered_stepper("cvode-held");
        }
    }
    return registered_stepper("closed-form");
}

void check_capabilities(const StepperCapabilities& s, const System& system, const SimulationOptions& options) {
    check_leaf_mass(s, system);
    check_options(s, options);
    check_assembly(s, system.model().spec());
    check_contact(s, system);
    check_loading(s, system, options.loading);
    require_loading_fits(system.model().spec(), options.loading);
}

}  // namespace stackbeam::detail
