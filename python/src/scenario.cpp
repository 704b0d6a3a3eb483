// The scenario from Python: Scenario, its model's entries named as the scenario file's keys,
// the integrator's options by member (the option table), the checks (bindings.hpp).
#include "bindings.hpp"

namespace stackbeam_py {

namespace {

const std::vector<std::pair<const char*, SupportKind>> kSupports = {
    {"free", SupportKind::free},       {"pinned", SupportKind::pinned},   {"fixed", SupportKind::fixed},
    {"hinged", SupportKind::hinged},   {"shackle", SupportKind::shackle}, {"bushing", SupportKind::bushing}};
const std::vector<std::pair<const char*, LoadingKind>> kLoadingKinds = {
    {"initial-conditions", LoadingKind::initial_conditions},
    {"applied-force", LoadingKind::applied_force},
    {"prescribed-displacement", LoadingKind::prescribed_displacement},
    {"base-excitation", LoadingKind::base_excitation}};
const std::vector<std::pair<const char*, TimeFunction::Shape>> kShapes = {{"constant", TimeFunction::Shape::constant},
                                                                          {"harmonic", TimeFunction::Shape::harmonic},
                                                                          {"triangle", TimeFunction::Shape::triangle},
                                                                          {"table", TimeFunction::Shape::table}};


/// A string property for an enum member, parsed by `words`, the field named `name`.
template <class Cls, class C, class E>
void enum_property(Cls& cls, const char* name, E C::*member, const std::vector<std::pair<const char*, E>>& words) {
    cls.def_property(
        name,
        [member, words](const C& c) {
            for (const auto& [w, e] : words)
                if (e == c.*member) return std::string(w);
            return std::string("?");
        },
        [member, words, name](C& c, const std::string& text) { c.*member = parse_word(text, name, words); });
}

}  // namespace

// --- options by member name (the option table) --------------------------------------------

/// Sets the option `member` of `o` from a Python value, checked by its row of the option
/// table; InputError naming the member otherwise.
void set_option(SimulationOptions& o, const std::string& member, const py::handle& value) {
    const OptionSpec* spec = find_option_by_member(member);
    if (!spec) {
        std::string names;
        for (const OptionSpec& s : simulation_option_table()) names += (names.empty() ? "" : ", ") + std::string(s.member);
        throw InputError(member, "unknown option: the options are " + names);
    }
    if (spec->type == OptionSpec::Type::keyword) {
        if (!py::isinstance<py::str>(value))
            throw InputError(member, "value " + py::repr(value).cast<std::string>() + " is not allowed: must be " + spec->allowed());
        spec->set_word(o, value.cast<std::string>(), member);
        return;
    }
    if (py::isinstance<py::bool_>(value) || !(py::isinstance<py::int_>(value) || py::isinstance<py::float_>(value) ||
                                             py::hasattr(value, "__float__")))
        throw InputError(member, "value " + py::repr(value).cast<std::string>() + " is not allowed: must be " + spec->allowed());
    const double v = value.cast<double>();
    if (spec->type == OptionSpec::Type::integer && v != static_cast<double>(static_cast<long long>(v)))
        throw InputError(member, "value " + format_value(v) + " is not allowed: must be " + spec->allowed());
    check_option(*spec, v);
    spec->set(o, v);
}

py::object get_option(const SimulationOptions& o, const OptionSpec& spec) {
    switch (spec.type) {
        case OptionSpec::Type::keyword: return py::str(spec.get_word(o));
        case OptionSpec::Type::integer: return py::int_(static_cast<long long>(spec.get(o)));
        case OptionSpec::Type::real: break;
    }
    return py::float_(spec.get(o));
}

/// The sub-tables of the options under `prefix` ("cvode", "solver", ...) and its own members.
std::vector<std::string> option_names(const std::string& prefix) {
    std::vector<std::string> names;
    for (const OptionSpec& s : simulation_option_table()) {
        const std::string m = s.member;
        if (m.compare(0, prefix.size(), prefix) != 0) continue;
        std::string rest = m.substr(prefix.size());
        const auto dot = rest.find('.');
        if (dot != std::string::npos) rest = rest.substr(0, dot);
        if (std::find(names.begin(), names.end(), rest) == names.end()) names.push_back(rest);
    }
    return names;
}

// --- validation and errors ----------------------------------------------------------------

/// Checks a scenario as the file reader does, with `options` for its integrator; returns the
/// built model. A model's error names the scenario key (with its file:line:column when the
/// scenario came from a file), an option's error names the member.
Model build_checked(const PyScenario& ps, const SimulationOptions& options) {
    try {
        Model model = Model::build(ps.scenario.model);
        options.validate();
        require_loading_fits(ps.scenario.model, options.loading);
        return model;
    } catch (const InputError& e) {
        if (!e.location().empty() || find_option_by_member(e.field())) throw;
        rethrow_in_scenario(ps.scenario, e);
    }
}

SimulationOptions options_with(const PyScenario& ps, const py::dict& overrides) {
    SimulationOptions o = ps.scenario.simulation;
    for (const auto& [k, v] : overrides) set_option(o, k.cast<std::string>(), v);
    return o;
}
ScenarioPtr make_scenario(Scenario s, std::string setup) { return std::make_shared<PyScenario>(std::move(s), std::move(setup)); }

/// The command line's summary line for a scenario file.
std::string file_setup(const Scenario& s) {
    return "scenario " + s.source + (s.description.empty() ? "" : " (" + s.description + ")") + "\n";
}
void bind_scenario(py::module_& m) {
    // --- the model's entries: attributes named as the scenario file's keys
    py::class_<LeafProfile>(m, "LeafProfile", "[leaves.profile]: thickness / width along the leaf (assign whole lists)")
        .def(py::init<>())
        .def_readwrite("x_m", &LeafProfile::x_m)
        .def_readwrite("thickness_m", &LeafProfile::thickness_m)
        .def_readwrite("width_m", &LeafProfile::width_m);
    py::class_<LeafEndSpec>(m, "LeafEnd", "[leaves.left_end] / [leaves.right_end]: eye, shackle, bushings")
        .def(py::init<>())
        .def_readwrite("eye_offset_m", &LeafEndSpec::eye_offset_m)
        .def_readwrite("shackle_angle_rad", &LeafEndSpec::shackle_angle_rad)
        .def_readwrite("bushing_x_n_per_m", &LeafEndSpec::bushing_x_n_per_m)
        .def_readwrite("bushing_y_n_per_m", &LeafEndSpec::bushing_y_n_per_m)
        .def_readwrite("bushing_rotation_n_m_per_rad", &LeafEndSpec::bushing_rotation_n_m_per_rad);
    py::class_<LeafSpec, std::shared_ptr<LeafSpec>> leaf(m, "Leaf", "[[leaves]]: one leaf, from the top of the stack down");
    leaf.def(py::init<>())
        .def_readwrite("length_m", &LeafSpec::length_m)
        .def_readwrite("x_start_m", &LeafSpec::x_start_m)
        .def_readwrite("height_m", &LeafSpec::height_m)
        .def_readwrite("width_m", &LeafSpec::width_m)
        .def_readwrite("youngs_modulus_pa", &LeafSpec::youngs_modulus_pa)
        .def_readwrite("density_kg_per_m3", &LeafSpec::density_kg_per_m3)
        .def_readwrite("poisson_ratio", &LeafSpec::poisson_ratio)
        .def_readwrite("profile", &LeafSpec::profile)
        .def_readwrite("left_end", &LeafSpec::left_end)
        .def_readwrite("right_end", &LeafSpec::right_end)
        .def_readwrite("free_camber_m", &LeafSpec::free_camber_m)
        .def_readwrite("free_radius_m", &LeafSpec::free_radius_m);
    enum_property(leaf, "left_support", &LeafSpec::left_support, kSupports);
    enum_property(leaf, "right_support", &LeafSpec::right_support, kSupports);

    py::class_<InterfaceSpec, std::shared_ptr<InterfaceSpec>> interface(m, "Interface", "[[interfaces]]: between leaves i and i+1");
    interface.def(py::init<>())
        .def_property(
            "law", [](const InterfaceSpec& f) { return std::string(f.law == InterfaceLaw::bonded ? "bonded" : "coulomb"); },
            [](InterfaceSpec& f, const std::string& text) {
                // 'frictionless' as in the file: coulomb with mu = 0
                const int law = parse_word<int>(text, "law", {{"coulomb", 0}, {"frictionless", 1}, {"bonded", 2}});
                f.law = law == 2 ? InterfaceLaw::bonded : InterfaceLaw::coulomb;
                if (law != 0) f.friction_coefficient = 0.0;
            })
        .def_readwrite("friction_coefficient", &InterfaceSpec::friction_coefficient)
        .def_readwrite("initial_gap_m", &InterfaceSpec::initial_gap_m)
        .def_property(
            "contact", [](const InterfaceSpec& f) { return std::string(to_string(f.contact)); },
            [](InterfaceSpec& f, const std::string& text) { f.contact = parse_interface_contact(text, "contact"); })
        .def_readwrite("normal_stiffness_pa_per_m", &InterfaceSpec::normal_stiffness_pa_per_m)
        .def_readwrite("tangential_stiffness_pa_per_m", &InterfaceSpec::tangential_stiffness_pa_per_m);
    py::class_<ClampSpec, std::shared_ptr<ClampSpec>>(m, "Clamp", "[[clamps]]: a clamp (band, U-bolt)")
        .def(py::init<>())
        .def_readwrite("x_m", &ClampSpec::x_m)
        .def_readwrite("preload_n", &ClampSpec::preload_n)
        .def_readwrite("length_m", &ClampSpec::length_m);
    py::class_<ClipSpec, std::shared_ptr<ClipSpec>>(m, "Clip", "[[clips]]: a rebound clip")
        .def(py::init<>())
        .def_readwrite("x_m", &ClipSpec::x_m)
        .def_readwrite("first_leaf", &ClipSpec::first_leaf)
        .def_readwrite("last_leaf", &ClipSpec::last_leaf)
        .def_readwrite("clearance_m", &ClipSpec::clearance_m)
        .def_readwrite("stiffness_n_per_m", &ClipSpec::stiffness_n_per_m);
    py::class_<RigidBodySpec>(m, "RigidBody", "[rigid_body]: the axle seat R (its initial conditions: model.loading)")
        .def_readwrite("mass_kg", &RigidBodySpec::mass_kg)
        .def_readwrite("x_m", &RigidBodySpec::x_m)
        .def_readwrite("tied_leaves", &RigidBodySpec::tied_leaves);
    py::class_<ProbeSpec, std::shared_ptr<ProbeSpec>>(m, "Probe", "[probe]: where the probe friction force is read")
        .def(py::init<>())
        .def(py::init([](int i, double x) { return ProbeSpec{i, x}; }), "interface_index"_a, "x_m"_a)
        .def_readwrite("interface_index", &ProbeSpec::interface_index)
        .def_readwrite("x_m", &ProbeSpec::x_m);
    py::class_<TimeFunction> tf(m, "TimeFunction", "[loading.force_n] / [loading.displacement_m]: a function of time");
    tf.def(py::init<>())
        .def_readwrite("mean", &TimeFunction::mean)
        .def_readwrite("amplitude", &TimeFunction::amplitude)
        .def_readwrite("frequency_hz", &TimeFunction::frequency_hz)
        .def_readwrite("phase_rad", &TimeFunction::phase_rad)
        .def_readwrite("times_s", &TimeFunction::times_s)
        .def_readwrite("values", &TimeFunction::values);
    enum_property(tf, "shape", &TimeFunction::shape, kShapes);

    py::bind_vector<Shared<LeafSpec>>(m, "LeafList");
    py::bind_vector<Shared<InterfaceSpec>>(m, "InterfaceList");
    py::bind_vector<Shared<ClampSpec>>(m, "ClampList");
    py::bind_vector<Shared<ClipSpec>>(m, "ClipList");

    py::class_<LoadingView>(m, "Loading", "[loading]: how the run loads the spring, and R's initial conditions")
        .def_property(
            "kind", [](const LoadingView& v) { return std::string(to_string(v.s->scenario.simulation.loading.kind)); },
            [](LoadingView& v, const std::string& text) {
                v.s->scenario.simulation.loading.kind = parse_word(text, "loading.kind", kLoadingKinds);
            })
        .def_property(
            "initial_displacement_m", [](const LoadingView& v) { return v.s->scenario.model.rigid_body.initial_displacement_m; },
            [](LoadingView& v, double x) { v.s->scenario.model.rigid_body.initial_displacement_m = x; })
        .def_property(
            "initial_velocity_m_per_s",
            [](const LoadingView& v) { return v.s->scenario.model.rigid_body.initial_velocity_m_per_s; },
            [](LoadingView& v, double x) { v.s->scenario.model.rigid_body.initial_velocity_m_per_s = x; })
        .def_property(
            "gravity_m_per_s2", [](const LoadingView& v) { return v.s->scenario.simulation.loading.gravity_m_per_s2; },
            [](LoadingView& v, double x) { v.s->scenario.simulation.loading.gravity_m_per_s2 = x; })
        .def_property(
            "force_n", [](LoadingView& v) -> TimeFunction& { return v.s->scenario.simulation.loading.force_n; },
            [](LoadingView& v, const TimeFunction& f) { v.s->scenario.simulation.loading.force_n = f; },
            py::return_value_policy::reference_internal)
        .def_property(
            "displacement_m", [](LoadingView& v) -> TimeFunction& { return v.s->scenario.simulation.loading.displacement_m; },
            [](LoadingView& v, const TimeFunction& f) { v.s->scenario.simulation.loading.displacement_m = f; },
            py::return_value_policy::reference_internal);
    py::class_<MeshView>(m, "Mesh", "[mesh]: the node grid and the symmetry")
        .def_property(
            "element_length_m", [](const MeshView& v) { return v.s->scenario.model.mesh.element_length_m; },
            [](MeshView& v, double x) { v.s->scenario.model.mesh.element_length_m = x; })
        .def_property(
            "symmetry", [](const MeshView& v) { return std::string(v.s->scenario.model.symmetry == Symmetry::half ? "half" : "full"); },
            [](MeshView& v, const std::string& text) {
                v.s->scenario.model.symmetry = parse_word<Symmetry>(text, "mesh.symmetry", {{"full", Symmetry::full}, {"half", Symmetry::half}});
            });

    const auto ref = py::return_value_policy::reference_internal;
    py::class_<ModelView>(m, "Model", "The stack: attributes named as the scenario file's tables")
        .def_property_readonly("leaves", [](ModelView& v) -> Shared<LeafSpec>& { return v.s->leaves; }, ref)
        .def_property_readonly("interfaces", [](ModelView& v) -> Shared<InterfaceSpec>& { return v.s->interfaces; }, ref)
        .def_property_readonly("clamps", [](ModelView& v) -> Shared<ClampSpec>& { return v.s->clamps; }, ref)
        .def_property_readonly("clips", [](ModelView& v) -> Shared<ClipSpec>& { return v.s->clips; }, ref)
        .def_property_readonly("rigid_body", [](ModelView& v) -> RigidBodySpec& { return v.s->scenario.model.rigid_body; }, ref)
        .def_property_readonly("loading", [](ModelView& v) { return LoadingView{v.s}; })
        .def_property_readonly("mesh", [](ModelView& v) { return MeshView{v.s}; })
        .def_property(
            "probe", [](ModelView& v) { return v.s->probe; },  // None when there is none
            [](ModelView& v, std::shared_ptr<ProbeSpec> p) { v.s->probe = std::move(p); });

    py::class_<OptionsView>(m, "Simulation", "The integrator's options by SimulationOptions member (file: [integrator])")
        .def("__getattr__",
             [](const OptionsView& v, const std::string& name) -> py::object {
                 const std::string member = v.prefix + name;
                 if (const OptionSpec* spec = find_option_by_member(member)) return get_option(v.s->scenario.simulation, *spec);
                 const auto subs = option_names(member + ".");
                 if (!subs.empty()) return py::cast(OptionsView{v.s, member + "."});
                 throw py::attribute_error("no option '" + member + "'");
             })
        .def("__setattr__",
             [](OptionsView& v, const std::string& name, const py::object& value) {
                 set_option(v.s->scenario.simulation, v.prefix + name, value);
             })
        .def("__dir__", [](const OptionsView& v) { return option_names(v.prefix); });

    py::class_<ScenarioOutputs>(m, "Outputs", "[outputs]: where the command line writes a run's files")
        .def_readwrite("csv_path", &ScenarioOutputs::csv_path)
        .def_readwrite("events_path", &ScenarioOutputs::events_path)
        .def_readwrite("summary_path", &ScenarioOutputs::summary_path)
        .def_readwrite("pairs_path", &ScenarioOutputs::pairs_path)
        .def_readwrite("nodes_path", &ScenarioOutputs::nodes_path)
        .def_readwrite("plot_prefix", &ScenarioOutputs::plot_prefix);

    py::class_<PyScenario, ScenarioPtr>(m, "Scenario", "A whole run: the stack, the loading, the integrator, the outputs")
        .def(py::init([] {
            Scenario s;
            s.source = "<python>";
            return make_scenario(s, file_setup(s));
        }))
        .def_static(
            "from_toml",
            [](const std::string& text, const std::string& source) {
                Scenario s = parse_scenario(text, source);
                return make_scenario(s, file_setup(s));
            },
            "text"_a, "source"_a = "<string>", "Parses scenario TOML text (docs/model-and-scenarios.md)")
        .def("to_toml", [](PyScenario& p) { return to_toml(p.synced()); }, "The scenario as TOML text")
        .def("validate", [](PyScenario& p) { build_checked(p, p.synced().simulation); },
             "Checks the model and the options as a scenario file is checked; InputError names the key")
        .def("copy", [](const PyScenario& p) { return std::make_shared<PyScenario>(p); })
        .def("__copy__", [](const PyScenario& p) { return std::make_shared<PyScenario>(p); })
        .def("__deepcopy__", [](const PyScenario& p, py::dict) { return std::make_shared<PyScenario>(p); })
        .def_property("description", [](const PyScenario& p) { return p.scenario.description; },
                      [](PyScenario& p, const std::string& d) { p.scenario.description = d; })
        .def_property_readonly("source", [](const PyScenario& p) { return p.scenario.source; })
        .def_property_readonly("setup", [](const PyScenario& p) { return p.setup; })
        .def_property_readonly("model", [](const ScenarioPtr& p) { return ModelView{p}; })
        .def_property_readonly("simulation", [](const ScenarioPtr& p) { return OptionsView{p, ""}; })
        .def_property_readonly("outputs", [](PyScenario& p) -> ScenarioOutputs& { return p.scenario.outputs; }, ref);

    m.def(
        "load_scenario",
        [](const std::string& path) {
            Scenario s = load_scenario(path);
            return make_scenario(s, file_setup(s));
        },
        "path"_a);
    m.def(
        "paper_example",
        [](const std::string& name, int elements_per_half_leaf, bool full_model) {
            PaperExampleOptions o;
            o.elements_per_half_leaf = elements_per_half_leaf;
            o.symmetry = full_model ? Symmetry::full : Symmetry::half;
            const PaperCase c = parse_paper_case(name, "case");
            Scenario s;
            s.source = std::string("paper_example(") + to_string(c) + ")";
            s.description = std::string("the paper's ") + to_string(c) + " case (Lee & Lim 1992, section 5)";
            s.model = paper_example(c, o);
            // as `stackbeam simulate --case NAME` writes it
            const std::string setup = std::string("case ") + to_string(c) + ", " + std::to_string(o.elements_per_half_leaf) +
                                      " elements per half leaf (" + (full_model ? "full" : "half") + " model), ";
            return make_scenario(s, setup);
        },
        "case"_a, "elements_per_half_leaf"_a = PaperExampleOptions{}.elements_per_half_leaf, "full_model"_a = false);

    m.def(
        "option_table",
        [] {
            py::list rows;
            for (const OptionSpec& s : simulation_option_table())
                rows.append(py::dict("member"_a = s.member, "key"_a = s.key, "flag"_a = s.flag, "unit"_a = s.unit,
                                     "help"_a = s.help, "allowed"_a = s.allowed()));
            return rows;
        },
        "The integrator's options: member, scenario key, command-line flag, unit, help, what is allowed");

}

}  // namespace stackbeam_py
