// The Python module's shared pieces (python/src/*.cpp): the scenario as Python holds it
// (PyScenario and its views), the option table's conversions, the results as numpy arrays,
// and the bind_* functions each file registers in stackbeam._core (module.cpp).
//
// Names: a scenario's model is reached by the scenario file's key paths
// (scenario.model.leaves[0].height_m is the key leaves[0].height_m), its integrator by the
// members of SimulationOptions (scenario.simulation.cvode.rtol is integrator.cvode.rtol).
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl_bind.h>

#include <algorithm>
#include <limits>
#include <type_traits>
#include <chrono>
#include <cmath>
#include <memory>
#include <atomic>
#include <future>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "stackbeam/errors.hpp"
#include "stackbeam/io/scenario.hpp"
#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/run/run.hpp"
#include "stackbeam/run/summary_json.hpp"
#include "stackbeam/study/sweep.hpp"
#include "stackbeam/study/sweep_output.hpp"
#include "stackbeam/time/option_table.hpp"
#include "stackbeam/time/run_report.hpp"
#include "stackbeam/time/stepper.hpp"

namespace py = pybind11;
using namespace pybind11::literals;
using namespace stackbeam;

PYBIND11_MAKE_OPAQUE(std::vector<std::shared_ptr<stackbeam::LeafSpec>>)
PYBIND11_MAKE_OPAQUE(std::vector<std::shared_ptr<stackbeam::InterfaceSpec>>)
PYBIND11_MAKE_OPAQUE(std::vector<std::shared_ptr<stackbeam::ClampSpec>>)
PYBIND11_MAKE_OPAQUE(std::vector<std::shared_ptr<stackbeam::ClipSpec>>)

namespace stackbeam_py {

using namespace stackbeam;

template <class T>
using Shared = std::vector<std::shared_ptr<T>>;

/// The model's list `from` copied into `to`; InputError naming `name`[i] for an entry that is None.
template <class T>
void pack(const Shared<T>& from, std::vector<T>& to, const std::string& name, const char* type) {
    to.clear();
    for (std::size_t i = 0; i < from.size(); ++i) {
        if (!from[i]) throw InputError(name + "[" + std::to_string(i) + "]", std::string("is None: must be a ") + type);
        to.push_back(*from[i]);
    }
}
template <class T>
Shared<T> unpack(const std::vector<T>& from) {
    Shared<T> to;
    for (const T& x : from) to.push_back(std::make_shared<T>(x));
    return to;
}
template <class T>
Shared<T> deep_copy(const Shared<T>& from) {
    Shared<T> to;
    for (const auto& x : from) to.push_back(x ? std::make_shared<T>(*x) : nullptr);
    return to;
}

/// `v` as a one-dimensional numpy array (a copy).
template <class T>
py::array_t<T> array_of(const std::vector<T>& v) {
    return py::array_t<T>(static_cast<py::ssize_t>(v.size()), v.data());
}

/// A scenario and the first line of its summary ("setup", as the command line writes it).
/// The model's lists and its probe are kept as shared objects, so that a Python reference to
/// an entry (`leaf = s.model.leaves[0]`) stays valid whatever happens to the list (the
/// elements of a std::vector move when it grows); synced() copies them into the scenario.
struct PyScenario {
    Scenario scenario;  ///< its model's leaves, interfaces, clamps, clips and probe: the members below
    std::string setup;
    Shared<LeafSpec> leaves;
    Shared<InterfaceSpec> interfaces;
    Shared<ClampSpec> clamps;
    Shared<ClipSpec> clips;
    std::shared_ptr<ProbeSpec> probe;

    PyScenario(Scenario s, std::string first_line) : scenario(std::move(s)), setup(std::move(first_line)) {
        leaves = unpack(scenario.model.leaves);
        interfaces = unpack(scenario.model.interfaces);
        clamps = unpack(scenario.model.clamps);
        clips = unpack(scenario.model.clips);
        if (scenario.model.probe) probe = std::make_shared<ProbeSpec>(*scenario.model.probe);
    }
    /// A copy shares no entry with the original.
    PyScenario(const PyScenario& o)
        : scenario(o.scenario), setup(o.setup), leaves(deep_copy(o.leaves)), interfaces(deep_copy(o.interfaces)),
          clamps(deep_copy(o.clamps)), clips(deep_copy(o.clips)),
          probe(o.probe ? std::make_shared<ProbeSpec>(*o.probe) : nullptr) {}
    PyScenario& operator=(const PyScenario&) = delete;

    /// The scenario with the model's lists and probe as they are now.
    Scenario& synced() {
        pack(leaves, scenario.model.leaves, "leaves", "Leaf");
        pack(interfaces, scenario.model.interfaces, "interfaces", "Interface");
        pack(clamps, scenario.model.clamps, "clamps", "Clamp");
        pack(clips, scenario.model.clips, "clips", "Clip");
        scenario.model.probe = probe ? std::optional<ProbeSpec>(*probe) : std::nullopt;
        return scenario;
    }
};
using ScenarioPtr = std::shared_ptr<PyScenario>;

/// Views that reach into a scenario (they keep it alive): the file's tables whose keys the
/// C++ structs split differently ([loading], [mesh]) and the integrator's options.
struct ModelView { ScenarioPtr s; };
struct LoadingView { ScenarioPtr s; };
struct MeshView { ScenarioPtr s; };
struct OptionsView {
    ScenarioPtr s;
    std::string prefix;  ///< "" or "cvode." etc.
};

/// `text` as a word of E's table (stackbeam/words.hpp); InputError naming `field` with the
/// allowed words otherwise.
template <class E>
E parse_word(const std::string& text, const std::string& field) {
    if (const auto value = find_word<E>(text)) return *value;
    throw InputError(field, "value '" + text + "' is not allowed: must be one of " + word_list<E>("'"));
}

// --- Python values checked (checks.cpp) ------------------------------------------------------
//
// Every value a user gives the module (an attribute set, an argument) goes through these: a
// wrong type (None, a bool where a number is wanted, a string, another class) raises
// InputTypeError (Python: stackbeam.InputTypeError, an InputError and a TypeError), a value no
// C++ number holds (an int beyond a double's range, 10**400; beyond an int's) InputError; both
// name the attribute or argument, the value and what is allowed.

/// A value of the wrong type: stackbeam.InputTypeError, both InputError and TypeError.
class InputTypeError : public InputError {
public:
    using InputError::InputError;
};

/// repr(value), cut to 60 characters (a huge int's digits).
std::string value_repr(const py::handle& value);
/// `value` as a real number: a float or an int (numpy's too), not a bool.
double real_arg(const py::handle& value, const std::string& name);
/// `value` as an integer in [lo, hi]: an int (numpy's too), not a bool, not a float.
long long integer_arg(const py::handle& value, const std::string& name, long long lo, long long hi);
/// `value` as a bool: True or False (numpy's too), not 0 / 1 / None.
bool bool_arg(const py::handle& value, const std::string& name);
/// `value` as a string: a str.
std::string string_arg(const py::handle& value, const std::string& name);
/// The scenario argument: a Scenario, not None.
const ScenarioPtr& scenario_arg(const ScenarioPtr& scenario, const std::string& name);

template <class T>
struct is_vector : std::false_type {};
template <class E>
struct is_vector<std::vector<E>> : std::true_type {};

/// `value` as T (double, int, std::string, a std::vector of those, a bound class) for `name`.
template <class T>
T checked(const py::handle& value, const std::string& name) {
    if constexpr (std::is_same_v<T, double>) {
        return real_arg(value, name);
    } else if constexpr (std::is_same_v<T, int>) {
        return static_cast<int>(integer_arg(value, name, std::numeric_limits<int>::min(), std::numeric_limits<int>::max()));
    } else if constexpr (std::is_same_v<T, std::string>) {
        return string_arg(value, name);
    } else if constexpr (is_vector<T>::value) {
        if (py::isinstance<py::str>(value) || (!py::isinstance<py::sequence>(value) && !py::hasattr(value, "__array__")))
            throw InputTypeError(name, "value " + value_repr(value) + " is not allowed: must be a list of values");
        T out;
        std::size_t i = 0;
        for (const py::handle item : value)
            out.push_back(checked<typename T::value_type>(item, name + "[" + std::to_string(i++) + "]"));
        return out;
    } else {
        if (value.is_none() || !py::isinstance<T>(value))
            throw InputTypeError(name, "value " + value_repr(value) + " is not allowed: must be a stackbeam." +
                                           py::type::of<T>().attr("__name__").template cast<std::string>());
        return value.template cast<T>();
    }
}

/// The getter and the setter of a read-write attribute for `member` (def_property), the value
/// set checked by `checked` as the field `label` (e.g. "Leaf.height_m").
template <class C, class T>
auto getter(T C::*member) {
    return [member](const C& c) -> const T& { return c.*member; };
}
template <class C, class T>
auto setter(T C::*member, std::string label) {
    return [member, label](C& c, const py::object& value) { c.*member = checked<T>(value, label); };
}

// --- options by member name (scenario.cpp) --------------------------------------------------

/// Sets the option `member` of `o` from a Python value, checked by its row of the option
/// table; InputError naming the member otherwise.
void set_option(SimulationOptions& o, const std::string& member, const py::handle& value);
py::object get_option(const SimulationOptions& o, const OptionSpec& spec);
/// The sub-tables of the options under `prefix` ("cvode", "solver", ...) and its own members.
std::vector<std::string> option_names(const std::string& prefix);
/// The scenario's options with `overrides` ({member: value}) set over them.
SimulationOptions options_with(const PyScenario& ps, const py::dict& overrides);

// --- validation and errors (scenario.cpp) ---------------------------------------------------

/// Checks a scenario as the file reader does, with `options` for its integrator; returns the
/// built model. A model's error names the scenario key (with its file:line:column when the
/// scenario came from a file), an option's error names the member.
Model build_checked(const PyScenario& ps, const SimulationOptions& options);

/// Runs `f` and turns an InputError about the model found once a run starts into the
/// scenario's key path, as build_checked.
template <class F>
auto in_scenario(const PyScenario& ps, F&& f) {
    try {
        return f();
    } catch (const InputError& e) {
        if (!e.location().empty() || find_option_by_member(e.field())) throw;
        rethrow_in_scenario(ps.scenario, e);
    }
}

ScenarioPtr make_scenario(Scenario s, std::string setup);
/// The command line's summary line for a scenario file.
std::string file_setup(const Scenario& s);

// --- results as numpy arrays (results.cpp) --------------------------------------------------

/// Column j of `rows` (row-major, `cols` wide) as a numpy array.
py::array_t<double> column(const std::vector<double>& rows, std::size_t cols, std::size_t j);
py::dict records_dict(const std::vector<StepRecord>& records);
py::dict record_dict(const StepRecord& r);
/// Pairs at record times, as the --pairs CSV's columns: t, pair, interface, x, state, p_n, p_t, gap, slip.
struct PairTable {
    std::vector<double> t, x, p_n, p_t, gap, slip;
    std::vector<int> pair, interface_index;
    std::vector<std::string> state;
    void add(double t_s, const std::vector<PairRecord>& prs) {
        for (const auto& p : prs) {
            t.push_back(t_s);
            pair.push_back(p.pair);
            interface_index.push_back(p.interface_index);
            x.push_back(p.x_m);
            state.push_back(to_string(p.state));
            p_n.push_back(p.p_n_n);
            p_t.push_back(p.p_t_n);
            gap.push_back(p.gap_m);
            slip.push_back(p.slip_m);
        }
    }
    py::dict to_dict() const {
        return py::dict("t"_a = array_of(t), "pair"_a = array_of(pair), "interface"_a = array_of(interface_index),
                        "x"_a = array_of(x), "state"_a = py::module_::import("numpy").attr("array")(state),
                        "p_n"_a = array_of(p_n), "p_t"_a = array_of(p_t), "gap"_a = array_of(gap),
                        "slip"_a = array_of(slip));
    }
};

/// Every leaf's nodes at record times, as the --nodes CSV's columns: t, leaf, x, w, theta.
struct NodeTable {
    std::vector<double> t, x, w, theta;
    std::vector<int> leaf;
    void add(double t_s, const std::vector<LeafNodes>& leaves) {
        for (const auto& l : leaves)
            for (std::size_t j = 0; j < l.x_m.size(); ++j) {
                t.push_back(t_s);
                leaf.push_back(l.leaf);
                x.push_back(l.x_m[j]);
                w.push_back(l.w_m[j]);
                theta.push_back(l.theta_rad[j]);
            }
    }
    py::dict to_dict() const {
        return py::dict("t"_a = array_of(t), "leaf"_a = array_of(leaf), "x"_a = array_of(x), "w"_a = array_of(w),
                        "theta"_a = array_of(theta));
    }
};

/// The stack's geometry for stackbeam.plot's deformed stack: each leaf's axis height in the stack
/// The stack's geometry for stackbeam.plot's deformed stack (results.cpp).
py::dict stack_geometry(const ScenarioPtr& scenario);
/// The event log as the --events CSV's columns: t, interface, x, pair, from, to, cause, w, w_dot.
py::dict events_dict(const std::vector<ContactEvent>& events);
py::dict report_dict(const RunReport& r);

/// Whether the calling thread is Python's main thread (the one that receives signals; run.cpp).
bool in_main_thread();

// --- what each file registers in the module ---------------------------------------------------

void bind_errors(py::module_& m);    ///< errors.cpp: InputError, SolverError
void bind_scenario(py::module_& m);  ///< scenario.cpp: Scenario, its model's entries, the options
void bind_run(py::module_& m);       ///< run.cpp: _run, _stack_geometry, Stepper
void bind_sweep(py::module_& m);     ///< sweep.cpp: _sweep
void bind_fit(py::module_& m);       ///< fit.cpp: _fit

}  // namespace stackbeam_py
