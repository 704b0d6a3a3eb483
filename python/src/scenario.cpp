// The scenario from Python: Scenario, its model's entries named as the scenario file's keys,
// the integrator's options by member (the option table), the checks (bindings.hpp).
#include "bindings.hpp"

namespace stackbeam_py {

namespace {

/// A string property for an enum member, by the enum's word table (words.hpp), the field named `name`.
template <class Cls, class C, class E>
void enum_property(Cls& cls, const char* name, E C::*member) {
    cls.def_property(
        name, [member](const C& c) { return std::string(word_of(c.*member)); },
        [member, name](C& c, const py::object& text) { c.*member = parse_word<E>(string_arg(text, name), name); });
}

/// A property for an optional time function of the loading (a seat load, the windup rig): None when
/// absent; assigning a TimeFunction gives it, assigning None removes it. The function returned is the loading's own (edits reach it).
template <class Cls>
void optional_time_function(Cls& cls, const char* name, std::optional<TimeFunction> Loading::*member) {
    cls.def_property(
        name,
        [member](const py::object& self) -> py::object {
            std::optional<TimeFunction>& f = self.cast<LoadingView&>().s->scenario.simulation.loading.*member;
            if (!f) return py::none();
            return py::cast(&*f, py::return_value_policy::reference_internal, self);
        },
        [member, name](LoadingView& v, const py::object& f) {
            std::optional<TimeFunction>& target = v.s->scenario.simulation.loading.*member;
            if (f.is_none()) target.reset();  // None removes it (as a scenario file without the table)
            else target = checked<TimeFunction>(f, std::string("loading.") + name);
        });
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
            throw InputTypeError(member, "value " + value_repr(value) + " is not allowed: must be " + spec->allowed());
        spec->set_word(o, value.cast<std::string>(), member);
        return;
    }
    if (value.is_none() || py::isinstance<py::str>(value) || py::isinstance<py::bool_>(value))
        throw InputTypeError(member, "value " + value_repr(value) + " is not allowed: must be " + spec->allowed());
    double v = 0.0;
    try {
        v = real_arg(value, member);
    } catch (const InputTypeError&) {
        throw InputTypeError(member, "value " + value_repr(value) + " is not allowed: must be " + spec->allowed());
    } catch (const InputError&) {  // an int beyond a double's range (10**400)
        throw InputError(member, "value " + value_repr(value) + " is not allowed: beyond a double's range; must be " +
                                     spec->allowed());
    }
    if (spec->type == OptionSpec::Type::integer &&
        !(std::abs(v) < 9.0e18 && v == static_cast<double>(static_cast<long long>(v))))
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
    for (const auto& [k, v] : overrides) set_option(o, string_arg(k, "option name"), v);
    return o;
}
ScenarioPtr make_scenario(Scenario s, std::string setup) { return std::make_shared<PyScenario>(std::move(s), std::move(setup)); }

/// The command line's summary line for a scenario file.
std::string file_setup(const Scenario& s) {
    return scenario_setup(s.source, s.description);
}
void bind_scenario(py::module_& m) {
    // --- the model's entries: attributes named as the scenario file's keys
    py::class_<LeafProfile>(m, "LeafProfile", "[leaves.profile]: thickness / width along the leaf (assign whole lists)")
        .def(py::init<>())
        .def_property("x_m", getter(&LeafProfile::x_m), setter(&LeafProfile::x_m, "LeafProfile.x_m"))
        .def_property("thickness_m", getter(&LeafProfile::thickness_m), setter(&LeafProfile::thickness_m, "LeafProfile.thickness_m"))
        .def_property("width_m", getter(&LeafProfile::width_m), setter(&LeafProfile::width_m, "LeafProfile.width_m"));
    py::class_<LeafEndSpec>(m, "LeafEnd", "[leaves.left_end] / [leaves.right_end]: eye, shackle, bushings")
        .def(py::init<>())
        .def_property("eye_offset_m", getter(&LeafEndSpec::eye_offset_m), setter(&LeafEndSpec::eye_offset_m, "LeafEnd.eye_offset_m"))
        .def_property("shackle_angle_rad", getter(&LeafEndSpec::shackle_angle_rad), setter(&LeafEndSpec::shackle_angle_rad, "LeafEnd.shackle_angle_rad"))
        .def_property("bushing_x_n_per_m", getter(&LeafEndSpec::bushing_x_n_per_m), setter(&LeafEndSpec::bushing_x_n_per_m, "LeafEnd.bushing_x_n_per_m"))
        .def_property("bushing_y_n_per_m", getter(&LeafEndSpec::bushing_y_n_per_m), setter(&LeafEndSpec::bushing_y_n_per_m, "LeafEnd.bushing_y_n_per_m"))
        .def_property("bushing_rotation_n_m_per_rad", getter(&LeafEndSpec::bushing_rotation_n_m_per_rad), setter(&LeafEndSpec::bushing_rotation_n_m_per_rad, "LeafEnd.bushing_rotation_n_m_per_rad"));
    py::class_<LeafSpec, std::shared_ptr<LeafSpec>> leaf(m, "Leaf", "[[leaves]]: one leaf, from the top of the stack down");
    leaf.def(py::init<>())
        .def_property("length_m", getter(&LeafSpec::length_m), setter(&LeafSpec::length_m, "Leaf.length_m"))
        .def_property("x_start_m", getter(&LeafSpec::x_start_m), setter(&LeafSpec::x_start_m, "Leaf.x_start_m"))
        .def_property("height_m", getter(&LeafSpec::height_m), setter(&LeafSpec::height_m, "Leaf.height_m"))
        .def_property("width_m", getter(&LeafSpec::width_m), setter(&LeafSpec::width_m, "Leaf.width_m"))
        .def_property("youngs_modulus_pa", getter(&LeafSpec::youngs_modulus_pa), setter(&LeafSpec::youngs_modulus_pa, "Leaf.youngs_modulus_pa"))
        .def_property("density_kg_per_m3", getter(&LeafSpec::density_kg_per_m3), setter(&LeafSpec::density_kg_per_m3, "Leaf.density_kg_per_m3"))
        .def_property("poisson_ratio", getter(&LeafSpec::poisson_ratio), setter(&LeafSpec::poisson_ratio, "Leaf.poisson_ratio"))
        .def_property("profile", getter(&LeafSpec::profile), setter(&LeafSpec::profile, "Leaf.profile"))
        .def_property("left_end", getter(&LeafSpec::left_end), setter(&LeafSpec::left_end, "Leaf.left_end"))
        .def_property("right_end", getter(&LeafSpec::right_end), setter(&LeafSpec::right_end, "Leaf.right_end"))
        .def_property("free_camber_m", getter(&LeafSpec::free_camber_m), setter(&LeafSpec::free_camber_m, "Leaf.free_camber_m"))
        .def_property("free_radius_m", getter(&LeafSpec::free_radius_m), setter(&LeafSpec::free_radius_m, "Leaf.free_radius_m"));
    enum_property(leaf, "left_support", &LeafSpec::left_support);
    enum_property(leaf, "right_support", &LeafSpec::right_support);

    py::class_<InterfaceSpec, std::shared_ptr<InterfaceSpec>> interface(m, "Interface", "[[interfaces]]: between leaves i and i+1");
    interface.def(py::init<>())
        .def_property(
            "law",
            [](const InterfaceSpec& f) {
                return std::string(word_of(f.law == InterfaceLaw::bonded ? InterfaceLawWord::bonded : InterfaceLawWord::coulomb));
            },
            [](InterfaceSpec& f, const py::object& text) {
                // 'frictionless' as in the file: coulomb with mu = 0
                const auto law = parse_word<InterfaceLawWord>(string_arg(text, "Interface.law"), "law");
                f.law = law == InterfaceLawWord::bonded ? InterfaceLaw::bonded : InterfaceLaw::coulomb;
                if (law != InterfaceLawWord::coulomb) f.friction_coefficient = 0.0;
            })
        .def_property("friction_coefficient", getter(&InterfaceSpec::friction_coefficient), setter(&InterfaceSpec::friction_coefficient, "Interface.friction_coefficient"))
        .def_property("initial_gap_m", getter(&InterfaceSpec::initial_gap_m), setter(&InterfaceSpec::initial_gap_m, "Interface.initial_gap_m"))
        .def_property(
            "contact", [](const InterfaceSpec& f) { return std::string(to_string(f.contact)); },
            [](InterfaceSpec& f, const py::object& text) {
                f.contact = parse_interface_contact(string_arg(text, "Interface.contact"), "contact");
            })
        .def_property("normal_stiffness_pa_per_m", getter(&InterfaceSpec::normal_stiffness_pa_per_m), setter(&InterfaceSpec::normal_stiffness_pa_per_m, "Interface.normal_stiffness_pa_per_m"))
        .def_property("tangential_stiffness_pa_per_m", getter(&InterfaceSpec::tangential_stiffness_pa_per_m), setter(&InterfaceSpec::tangential_stiffness_pa_per_m, "Interface.tangential_stiffness_pa_per_m"));
    py::class_<ClampSpec, std::shared_ptr<ClampSpec>>(m, "Clamp", "[[clamps]]: a clamp (band, U-bolt)")
        .def(py::init<>())
        .def_property("x_m", getter(&ClampSpec::x_m), setter(&ClampSpec::x_m, "Clamp.x_m"))
        .def_property("preload_n", getter(&ClampSpec::preload_n), setter(&ClampSpec::preload_n, "Clamp.preload_n"))
        .def_property("length_m", getter(&ClampSpec::length_m), setter(&ClampSpec::length_m, "Clamp.length_m"));
    py::class_<ClipSpec, std::shared_ptr<ClipSpec>>(m, "Clip", "[[clips]]: a rebound clip")
        .def(py::init<>())
        .def_property("x_m", getter(&ClipSpec::x_m), setter(&ClipSpec::x_m, "Clip.x_m"))
        .def_property("first_leaf", getter(&ClipSpec::first_leaf), setter(&ClipSpec::first_leaf, "Clip.first_leaf"))
        .def_property("last_leaf", getter(&ClipSpec::last_leaf), setter(&ClipSpec::last_leaf, "Clip.last_leaf"))
        .def_property("clearance_m", getter(&ClipSpec::clearance_m), setter(&ClipSpec::clearance_m, "Clip.clearance_m"))
        .def_property("stiffness_n_per_m", getter(&ClipSpec::stiffness_n_per_m), setter(&ClipSpec::stiffness_n_per_m, "Clip.stiffness_n_per_m"));
    py::class_<RigidBodySpec> rigid_body(m, "RigidBody", "[rigid_body]: the axle seat R (its initial conditions: model.loading)");
    rigid_body
        .def_property("mass_kg", getter(&RigidBodySpec::mass_kg), setter(&RigidBodySpec::mass_kg, "rigid_body.mass_kg"))
        .def_property("x_m", getter(&RigidBodySpec::x_m), setter(&RigidBodySpec::x_m, "rigid_body.x_m"))
        .def_property("tied_leaves", getter(&RigidBodySpec::tied_leaves), setter(&RigidBodySpec::tied_leaves, "rigid_body.tied_leaves"))
        .def_property("pitch_inertia_kg_m2", getter(&RigidBodySpec::pitch_inertia_kg_m2),
                      setter(&RigidBodySpec::pitch_inertia_kg_m2, "rigid_body.pitch_inertia_kg_m2"));
    enum_property(rigid_body, "axial", &RigidBodySpec::axial);
    py::class_<ProbeSpec, std::shared_ptr<ProbeSpec>>(m, "Probe", "[probe]: where the probe friction force is read")
        .def(py::init<>())
        .def(py::init([](const py::object& i, const py::object& x) {
                 return ProbeSpec{checked<int>(i, "interface_index"), real_arg(x, "x_m")};
             }),
             "interface_index"_a, "x_m"_a)
        .def_property("interface_index", getter(&ProbeSpec::interface_index), setter(&ProbeSpec::interface_index, "Probe.interface_index"))
        .def_property("x_m", getter(&ProbeSpec::x_m), setter(&ProbeSpec::x_m, "Probe.x_m"));
    py::class_<TimeFunction> tf(m, "TimeFunction", "[loading.force_n] / [loading.displacement_m]: a function of time");
    tf.def(py::init<>())
        .def_property("mean", getter(&TimeFunction::mean), setter(&TimeFunction::mean, "TimeFunction.mean"))
        .def_property("amplitude", getter(&TimeFunction::amplitude), setter(&TimeFunction::amplitude, "TimeFunction.amplitude"))
        .def_property("frequency_hz", getter(&TimeFunction::frequency_hz), setter(&TimeFunction::frequency_hz, "TimeFunction.frequency_hz"))
        .def_property("phase_rad", getter(&TimeFunction::phase_rad), setter(&TimeFunction::phase_rad, "TimeFunction.phase_rad"))
        .def_property("times_s", getter(&TimeFunction::times_s), setter(&TimeFunction::times_s, "TimeFunction.times_s"))
        .def_property("values", getter(&TimeFunction::values), setter(&TimeFunction::values, "TimeFunction.values"));
    enum_property(tf, "shape", &TimeFunction::shape);

    py::bind_vector<Shared<LeafSpec>>(m, "LeafList");
    py::bind_vector<Shared<InterfaceSpec>>(m, "InterfaceList");
    py::bind_vector<Shared<ClampSpec>>(m, "ClampList");
    py::bind_vector<Shared<ClipSpec>>(m, "ClipList");

    py::class_<LoadingView> loading(m, "Loading", "[loading]: how the run loads the spring, and R's initial conditions");
    loading
        .def_property(
            "kind", [](const LoadingView& v) { return std::string(to_string(v.s->scenario.simulation.loading.kind)); },
            [](LoadingView& v, const py::object& text) {
                v.s->scenario.simulation.loading.kind = parse_word<LoadingKind>(string_arg(text, "loading.kind"), "loading.kind");
            })
        .def_property(
            "initial_displacement_m", [](const LoadingView& v) { return v.s->scenario.model.rigid_body.initial_displacement_m; },
            [](LoadingView& v, const py::object& x) {
                v.s->scenario.model.rigid_body.initial_displacement_m = real_arg(x, "loading.initial_displacement_m");
            })
        .def_property(
            "initial_velocity_m_per_s",
            [](const LoadingView& v) { return v.s->scenario.model.rigid_body.initial_velocity_m_per_s; },
            [](LoadingView& v, const py::object& x) {
                v.s->scenario.model.rigid_body.initial_velocity_m_per_s = real_arg(x, "loading.initial_velocity_m_per_s");
            })
        .def_property(
            "gravity_m_per_s2", [](const LoadingView& v) { return v.s->scenario.simulation.loading.gravity_m_per_s2; },
            [](LoadingView& v, const py::object& x) {
                v.s->scenario.simulation.loading.gravity_m_per_s2 = real_arg(x, "loading.gravity_m_per_s2");
            })
        .def_property(
            "force_n", [](LoadingView& v) -> TimeFunction& { return v.s->scenario.simulation.loading.force_n; },
            [](LoadingView& v, const py::object& f) {
                v.s->scenario.simulation.loading.force_n = checked<TimeFunction>(f, "loading.force_n");
            },
            py::return_value_policy::reference_internal)
        .def_property(
            "displacement_m", [](LoadingView& v) -> TimeFunction& { return v.s->scenario.simulation.loading.displacement_m; },
            [](LoadingView& v, const py::object& f) {
                v.s->scenario.simulation.loading.displacement_m = checked<TimeFunction>(f, "loading.displacement_m");
            },
            py::return_value_policy::reference_internal)
        .def_property(
            "longitudinal_force_height_m",
            [](const LoadingView& v) { return v.s->scenario.simulation.loading.longitudinal_force_height_m; },
            [](LoadingView& v, const py::object& x) {
                v.s->scenario.simulation.loading.longitudinal_force_height_m = real_arg(x, "loading.longitudinal_force_height_m");
            });
    // the seat loads and the windup rig (docs/windup.md): None when absent
    optional_time_function(loading, "seat_moment_n_m", &Loading::seat_moment_n_m);
    optional_time_function(loading, "longitudinal_force_n", &Loading::longitudinal_force_n);
    optional_time_function(loading, "seat_rotation_rad", &Loading::seat_rotation_rad);
    py::class_<MeshView>(m, "Mesh", "[mesh]: the node grid and the symmetry")
        .def_property(
            "element_length_m", [](const MeshView& v) { return v.s->scenario.model.mesh.element_length_m; },
            [](MeshView& v, const py::object& x) {
                v.s->scenario.model.mesh.element_length_m = real_arg(x, "mesh.element_length_m");
            })
        .def_property(
            "symmetry", [](const MeshView& v) { return std::string(word_of(v.s->scenario.model.symmetry)); },
            [](MeshView& v, const py::object& text) {
                v.s->scenario.model.symmetry = parse_word<Symmetry>(string_arg(text, "mesh.symmetry"), "mesh.symmetry");
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
            [](ModelView& v, const py::object& p) {  // None: no probe
                v.s->probe = p.is_none() ? nullptr : std::make_shared<ProbeSpec>(checked<ProbeSpec>(p, "probe"));
            });

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
        .def_property("csv_path", getter(&ScenarioOutputs::csv_path), setter(&ScenarioOutputs::csv_path, "outputs.csv_path"))
        .def_property("events_path", getter(&ScenarioOutputs::events_path), setter(&ScenarioOutputs::events_path, "outputs.events_path"))
        .def_property("summary_path", getter(&ScenarioOutputs::summary_path), setter(&ScenarioOutputs::summary_path, "outputs.summary_path"))
        .def_property("pairs_path", getter(&ScenarioOutputs::pairs_path), setter(&ScenarioOutputs::pairs_path, "outputs.pairs_path"))
        .def_property("nodes_path", getter(&ScenarioOutputs::nodes_path), setter(&ScenarioOutputs::nodes_path, "outputs.nodes_path"))
        .def_property("plot_prefix", getter(&ScenarioOutputs::plot_prefix), setter(&ScenarioOutputs::plot_prefix, "outputs.plot_prefix"))
        .def_property("stresses_path", getter(&ScenarioOutputs::stresses_path),
                      setter(&ScenarioOutputs::stresses_path, "outputs.stresses_path"));

    py::class_<PyScenario, ScenarioPtr>(m, "Scenario", "A whole run: the stack, the loading, the integrator, the outputs")
        .def(py::init([] {
            Scenario s;
            s.source = "<python>";
            return make_scenario(s, file_setup(s));
        }))
        .def_static(
            "from_toml",
            [](const py::object& text, const py::object& source) {
                Scenario s = parse_scenario(string_arg(text, "text"), string_arg(source, "source"));
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
                      [](PyScenario& p, const py::object& d) { p.scenario.description = string_arg(d, "description"); })
        .def_property_readonly("source", [](const PyScenario& p) { return p.scenario.source; })
        .def_property_readonly("setup", [](const PyScenario& p) { return p.setup; })
        .def_property_readonly("model", [](const ScenarioPtr& p) { return ModelView{p}; })
        .def_property_readonly("simulation", [](const ScenarioPtr& p) { return OptionsView{p, ""}; })
        .def_property_readonly("outputs", [](PyScenario& p) -> ScenarioOutputs& { return p.scenario.outputs; }, ref);

    m.def(
        "load_scenario",
        [](const py::object& path) {  // a str or an os.PathLike
            const py::object text = py::hasattr(path, "__fspath__") ? py::module_::import("os").attr("fspath")(path) : path;
            Scenario s = load_scenario(string_arg(text, "path"));
            return make_scenario(s, file_setup(s));
        },
        "path"_a);
    m.def(
        "paper_example",
        [](const py::object& case_name, const py::object& elements, const py::object& full) {
            const std::string name = string_arg(case_name, "case");
            const bool full_model = bool_arg(full, "full_model");
            PaperExampleOptions o;
            o.elements_per_half_leaf = static_cast<int>(integer_arg(elements, "elements_per_half_leaf", std::numeric_limits<int>::min(), std::numeric_limits<int>::max()));
            o.symmetry = full_model ? Symmetry::full : Symmetry::half;
            const PaperCase c = parse_paper_case(name, "case");
            Scenario s;
            s.source = std::string("paper_example(") + to_string(c) + ")";
            s.description = std::string("the paper's ") + to_string(c) + " case (Lee & Lim 1992, section 5)";
            s.model = paper_example(c, o);
            // the summary line of `stackbeam simulate --case NAME` (case_setup)
            return make_scenario(s, case_setup(c, o));
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
