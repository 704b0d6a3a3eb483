// stackbeam._core: the C++ library under the Python package stackbeam (python/stackbeam/,
// docs/python.md). The package's Python layer (Result, simulate's keyword options, plot)
// is in __init__.py; this file binds the scenario's data, the runs and the stepper.
//
// Names: a scenario's model is reached by the scenario file's key paths
// (scenario.model.leaves[0].height_m is the key leaves[0].height_m), its integrator by the
// members of SimulationOptions (scenario.simulation.cvode.rtol is integrator.cvode.rtol).
// Threads: a run releases the GIL while it steps; the main thread takes it back about every
// 20 ms to let Python see a pending signal (Ctrl-C: KeyboardInterrupt).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl_bind.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <atomic>
#include <future>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "run.hpp"
#include "stackbeam/errors.hpp"
#include "stackbeam/io/scenario.hpp"
#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/study/sweep.hpp"
#include "stackbeam/study/sweep_output.hpp"
#include "stackbeam/time/option_table.hpp"
#include "stackbeam/time/run_report.hpp"
#include "stackbeam/time/stepper.hpp"
#include "summary.hpp"

namespace py = pybind11;
using namespace pybind11::literals;
using namespace stackbeam;

PYBIND11_MAKE_OPAQUE(std::vector<std::shared_ptr<stackbeam::LeafSpec>>)
PYBIND11_MAKE_OPAQUE(std::vector<std::shared_ptr<stackbeam::InterfaceSpec>>)
PYBIND11_MAKE_OPAQUE(std::vector<std::shared_ptr<stackbeam::ClampSpec>>)
PYBIND11_MAKE_OPAQUE(std::vector<std::shared_ptr<stackbeam::ClipSpec>>)

namespace {

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

// --- words of the file's keywords ---------------------------------------------------------

template <class E>
E parse_word(const std::string& text, const std::string& field, const std::vector<std::pair<const char*, E>>& words) {
    std::string allowed;
    for (const auto& [w, e] : words) {
        if (text == w) return e;
        allowed += (allowed.empty() ? "'" : ", '") + std::string(w) + "'";
    }
    throw InputError(field, "value '" + text + "' is not allowed: must be one of " + allowed);
}
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

SimulationOptions options_with(const PyScenario& ps, const py::dict& overrides) {
    SimulationOptions o = ps.scenario.simulation;
    for (const auto& [k, v] : overrides) set_option(o, k.cast<std::string>(), v);
    return o;
}

// --- results as numpy arrays --------------------------------------------------------------

/// Column j of `rows` (row-major, `cols` wide) as a numpy array.
py::array_t<double> column(const std::vector<double>& rows, std::size_t cols, std::size_t j) {
    const std::size_t n = cols ? rows.size() / cols : 0;
    py::array_t<double> a(static_cast<py::ssize_t>(n));
    auto m = a.mutable_unchecked<1>();
    for (std::size_t i = 0; i < n; ++i) m(static_cast<py::ssize_t>(i)) = rows[i * cols + j];
    return a;
}

py::dict records_dict(const std::vector<StepRecord>& records) {
    const auto names = step_record_columns();
    std::vector<double> rows;
    rows.reserve(records.size() * names.size());
    for (const auto& r : records) {
        const auto v = step_record_values(r);
        rows.insert(rows.end(), v.begin(), v.end());
    }
    py::dict d;
    for (std::size_t j = 0; j < names.size(); ++j) d[py::str(names[j])] = column(rows, names.size(), j);
    return d;
}

py::dict record_dict(const StepRecord& r) {
    const auto names = step_record_columns();
    const auto values = step_record_values(r);
    py::dict d;
    for (std::size_t j = 0; j < names.size(); ++j) d[py::str(names[j])] = values[j];
    return d;
}

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
        py::dict d;
        d["t"] = py::array_t<double>(t.size(), t.data());
        d["pair"] = py::array_t<int>(pair.size(), pair.data());
        d["interface"] = py::array_t<int>(interface_index.size(), interface_index.data());
        d["x"] = py::array_t<double>(x.size(), x.data());
        d["state"] = py::module_::import("numpy").attr("array")(state);
        d["p_n"] = py::array_t<double>(p_n.size(), p_n.data());
        d["p_t"] = py::array_t<double>(p_t.size(), p_t.data());
        d["gap"] = py::array_t<double>(gap.size(), gap.data());
        d["slip"] = py::array_t<double>(slip.size(), slip.data());
        return d;
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
        py::dict d;
        d["t"] = py::array_t<double>(t.size(), t.data());
        d["leaf"] = py::array_t<int>(leaf.size(), leaf.data());
        d["x"] = py::array_t<double>(x.size(), x.data());
        d["w"] = py::array_t<double>(w.size(), w.data());
        d["theta"] = py::array_t<double>(theta.size(), theta.data());
        return d;
    }
};

/// The stack's geometry for stackbeam.plot's deformed stack: each leaf's axis height in the stack
/// [m] (Model::centroid_heights_m), the stack's height at the seat [m], the seat's x [m], whether
/// the model is the half one (its pairs are then mirrored about the seat).
py::dict stack_geometry(const ScenarioPtr& scenario) {
    PyScenario& ps = *scenario;
    const Model model = build_checked(ps, ps.synced().simulation);
    const double x_r = model.nodes_x()[model.attachment_node()];
    double height = 0.0;
    for (const auto& leaf : model.spec().leaves) height += leaf_thickness_m(leaf, x_r);
    py::dict d;
    py::list heights;
    for (double y : model.centroid_heights_m()) heights.append(y);
    d["axis_height_m"] = heights;
    d["stack_height_m"] = height;
    d["seat_x_m"] = x_r;
    d["half"] = model.spec().symmetry == Symmetry::half;
    d["x_tolerance_m"] = model.x_tolerance_m();
    return d;
}

/// The event log as the --events CSV's columns: t, interface, x, pair, from, to, cause, w, w_dot.
py::dict events_dict(const std::vector<ContactEvent>& events) {
    std::vector<double> t, x, w, w_dot;
    std::vector<int> interface_index, pair;
    std::vector<std::string> from, to, cause;
    for (const auto& e : events) {
        t.push_back(e.t_s);
        interface_index.push_back(e.interface_index);
        x.push_back(e.x_m);
        pair.push_back(e.pair);
        from.push_back(e.from);
        to.push_back(e.to);
        cause.push_back(e.cause);
        w.push_back(e.w_m);
        w_dot.push_back(e.w_dot_m_per_s);
    }
    const py::object array = py::module_::import("numpy").attr("array");
    py::dict d;
    d["t"] = py::array_t<double>(t.size(), t.data());
    d["interface"] = py::array_t<int>(interface_index.size(), interface_index.data());
    d["x"] = py::array_t<double>(x.size(), x.data());
    d["pair"] = py::array_t<int>(pair.size(), pair.data());
    d["from"] = array(from, "dtype"_a = "U8");
    d["to"] = array(to, "dtype"_a = "U8");
    d["cause"] = array(cause, "dtype"_a = "U8");
    d["w"] = py::array_t<double>(w.size(), w.data());
    d["w_dot"] = py::array_t<double>(w_dot.size(), w_dot.data());
    return d;
}

py::dict report_dict(const RunReport& r) {
    py::dict d;
    d["mode"] = to_string(r.mode);
    d["steps"] = r.steps;
    d["contact_iterations"] = r.contact_iterations;
    d["factorizations"] = r.factorizations;
    d["events"] = r.events.size();
    return d;
}

// --- the run ------------------------------------------------------------------------------

/// Whether the calling thread is Python's main thread (the one that receives signals).
bool in_main_thread() {
    const py::object threading = py::module_::import("threading");
    return threading.attr("current_thread")().is(threading.attr("main_thread")());
}

/// Checks for a pending signal about every 20 ms of a run, in the main thread only, with
/// the GIL taken for the check; a signal's Python exception (KeyboardInterrupt) is thrown
/// through the run as error_already_set.
class SignalCheck {
public:
    explicit SignalCheck(bool enabled) : enabled_(enabled), last_(std::chrono::steady_clock::now()) {}
    void operator()() {
        if (!enabled_) return;
        const auto now = std::chrono::steady_clock::now();
        if (now - last_ < std::chrono::milliseconds(20)) return;
        last_ = now;
        py::gil_scoped_acquire gil;
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    }

private:
    bool enabled_;
    std::chrono::steady_clock::time_point last_;
};

/// simulate(scenario, options, pairs) -> dict(columns, pairs, events, report, summary):
/// the run of the command line (same records, same JSON summary), the GIL released while it steps.
py::dict run(const ScenarioPtr& scenario, const py::dict& overrides, bool want_pairs, bool want_nodes) {
    // the run's own copy: another thread may change the scenario while this one runs without the GIL
    const auto copy = std::make_shared<PyScenario>(*scenario);
    copy->synced();
    const std::shared_ptr<const PyScenario> ps = copy;
    const SimulationOptions options = options_with(*ps, overrides);
    const Model model = build_checked(*ps, options);
    const auto t0 = std::chrono::steady_clock::now();
    cli::RunResult result;
    PairTable pairs;
    NodeTable nodes;
    SignalCheck check(in_main_thread());
    std::chrono::steady_clock::time_point released, reacquired;  // the stepping without the GIL
    {
        py::gil_scoped_release release;
        released = std::chrono::steady_clock::now();
        const System system(model);
        in_scenario(*ps, [&] {
            choose_contact_path(system, options);  // as the command line: a path the solver cannot take
            PairObserver on_pairs;
            if (want_pairs) on_pairs = [&](double t, const std::vector<PairRecord>& prs) { pairs.add(t, prs); };
            NodeObserver on_nodes;
            if (want_nodes) on_nodes = [&](double t, const std::vector<LeafNodes>& leaves) { nodes.add(t, leaves); };
            result.records = simulate(
                system, options,
                [&](const StepRecord& r) {
                    check();
                    result.stats.add(r);
                },
                &result.report, on_pairs, on_nodes);
            return 0;
        });
        reacquired = std::chrono::steady_clock::now();
    }
    result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    cli::RunRequest request;
    request.spec = ps->scenario.model;
    request.options = options;
    request.setup = ps->setup;
    const cli::LoopFigures loop = cli::loop_figures(request, result);

    py::dict out;
    out["columns"] = records_dict(result.records);
    out["pairs"] = want_pairs ? py::object(pairs.to_dict()) : py::object(py::none());
    out["nodes"] = want_nodes ? py::object(nodes.to_dict()) : py::object(py::none());
    out["events"] = options.mode == Mode::cvode ? py::object(events_dict(result.report.events)) : py::object(py::none());
    py::dict report = report_dict(result.report);
    // when the run held no GIL, on the clock of Python's time.monotonic() (CLOCK_MONOTONIC, as steady_clock)
    report["without_gil_s"] = py::make_tuple(std::chrono::duration<double>(released.time_since_epoch()).count(),
                                            std::chrono::duration<double>(reacquired.time_since_epoch()).count());
    out["report"] = report;
    out["summary"] = cli::json_summary(request, model, result, loop);
    return out;
}

/// sweep(spec_path, jobs, out_dir, restart, keep_series) -> dict(columns, axes, figures, ...):
/// the sweep of `stackbeam sweep` (study/sweep.hpp): every point read and checked before any
/// run, the points run on `jobs` threads with the GIL released, the table in point order. With
/// an out_dir the points go through the same results directory as the command line's
/// (journal, resume, points.csv, sweep.json); without one nothing is written.
py::dict sweep(const std::string& spec_path, int jobs, const std::string& out_dir, bool restart, bool keep_series) {
    const auto t0 = std::chrono::steady_clock::now();
    const SweepSpec spec = load_sweep_spec(spec_path);
    const std::vector<SweepPoint> points = expand_points(spec);
    std::optional<SweepDirectory> dir;
    if (!out_dir.empty()) dir.emplace(out_dir, spec, points, restart, keep_series);
    std::vector<std::optional<PointResult>> results(points.size());
    if (dir)
        for (std::size_t i = 0; i < points.size(); ++i)
            if (dir->finished()[i]) results[i] = dir->results()[i];

    SweepRunOptions options;
    options.jobs = jobs > 0 ? jobs : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
    if (dir) options.skip = dir->finished();
    std::atomic<bool> stop{false};
    options.stop = &stop;
    const bool main_thread = in_main_thread();
    {
        py::gil_scoped_release release;
        // the points run on a thread of their own; this one waits, and (Python's main thread)
        // takes the GIL about every 20 ms to see Ctrl-C, which stops the sweep (points in flight
        // are dropped, the finished ones stay in out_dir's journal)
        auto done = std::async(std::launch::async, [&] {
            return run_sweep(points, options, [&](const PointResult& r) {
                PointResult row = r;
                row.records = nullptr;
                if (dir) dir->record(r);
                results[static_cast<std::size_t>(r.index)] = std::move(row);
            });
        });
        while (done.wait_for(std::chrono::milliseconds(20)) != std::future_status::ready) {
            if (!main_thread) continue;
            py::gil_scoped_acquire gil;
            if (PyErr_CheckSignals() != 0) {
                stop = true;
                {
                    py::gil_scoped_release again;
                    done.wait();
                }
                throw py::error_already_set();
            }
        }
        done.get();  // rethrows what stopped the sweep (not a point's failure: those are rows)
    }
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (dir) {
        SweepTotals totals;
        totals.wall_s = wall_s;
        totals.jobs = options.jobs;
        dir->finish(totals);
    }

    const std::size_t n = points.size();
    py::dict columns;
    py::array_t<long long> index(static_cast<py::ssize_t>(n));
    for (std::size_t i = 0; i < n; ++i) index.mutable_at(static_cast<py::ssize_t>(i)) = points[i].index;
    columns["point"] = index;
    py::list axes;
    for (std::size_t a = 0; a < spec.axes.size(); ++a) {
        py::list values;
        for (const SweepPoint& p : points) values.append(py::cast(p.values[a]));
        columns[py::str(spec.axes[a].key)] = py::module_::import("numpy").attr("array")(values);
        axes.append(spec.axes[a].key);
    }
    py::list status, message;
    for (const auto& r : results) {
        status.append(r ? to_string(r->status) : "");
        message.append(r ? r->message : "");
    }
    columns["status"] = py::module_::import("numpy").attr("array")(status, "dtype"_a = "object");
    columns["message"] = py::module_::import("numpy").attr("array")(message, "dtype"_a = "object");
    const auto& names = point_figure_columns();
    for (std::size_t j = 0; j < names.size(); ++j) {
        py::array_t<double> col(static_cast<py::ssize_t>(n));
        for (std::size_t i = 0; i < n; ++i)
            col.mutable_at(static_cast<py::ssize_t>(i)) =
                results[i] && j < results[i]->figures.size() ? results[i]->figures[j] : std::nan("");
        columns[py::str(names[j])] = col;
    }
    py::array_t<double> wall(static_cast<py::ssize_t>(n));
    for (std::size_t i = 0; i < n; ++i)
        wall.mutable_at(static_cast<py::ssize_t>(i)) = results[i] ? results[i]->wall_s : std::nan("");
    columns["wall_time_s"] = wall;

    py::dict out;
    out["columns"] = columns;
    out["axes"] = axes;
    out["figures"] = names;
    out["scenario_path"] = spec.scenario_path;
    out["wall_time_s"] = wall_s;
    out["jobs"] = options.jobs;
    return out;
}

/// A stepper for co-simulation: the model, the options and the mode's Stepper, one record at a time.
class PyStepper {
public:
    PyStepper(const ScenarioPtr& scenario, const py::dict& overrides)
        : ps_(synced_copy(scenario)),
          options_(options_with(*ps_, overrides)),
          system_(std::make_unique<System>(build_checked(*ps_, options_))),
          stepper_(in_scenario(*ps_, [&] { return make_stepper(*system_, options_); })),
          n_(static_cast<long>(std::ceil(options_.t_end_s / options_.dt_s - 1e-9))) {}

    py::dict advance() {
        const StepRecord* r = nullptr;
        {
            py::gil_scoped_release release;
            r = &stepper_->advance();
        }
        return record_dict(*r);
    }
    py::dict current() const { return record_dict(stepper_->current()); }
    long record_index() const { return stepper_->record_index(); }
    long records() const { return n_ + 1; }
    double dt_s() const { return options_.dt_s; }
    py::dict pairs() const {
        PairTable t;
        t.add(stepper_->current().t_s, stepper_->pairs());
        py::dict d = t.to_dict();
        d.attr("pop")("t");
        return d;
    }
    py::dict nodes() const {
        NodeTable t;
        t.add(stepper_->current().t_s, stepper_->nodes());
        py::dict d = t.to_dict();
        d.attr("pop")("t");
        return d;
    }
    py::dict report() const {
        const RunReport r = stepper_->report();
        py::dict d = report_dict(r);
        if (r.mode == Mode::cvode) d["event_log"] = events_dict(r.events);
        return d;
    }

private:
    static std::shared_ptr<PyScenario> synced_copy(const ScenarioPtr& scenario) {
        auto copy = std::make_shared<PyScenario>(*scenario);
        copy->synced();
        return copy;
    }
    std::shared_ptr<PyScenario> ps_;  ///< the scenario as it was made from (for the errors' key paths)
    SimulationOptions options_;
    std::unique_ptr<System> system_;
    std::unique_ptr<Stepper> stepper_;
    long n_;
};

ScenarioPtr make_scenario(Scenario s, std::string setup) { return std::make_shared<PyScenario>(std::move(s), std::move(setup)); }

/// The command line's summary line for a scenario file.
std::string file_setup(const Scenario& s) {
    return "scenario " + s.source + (s.description.empty() ? "" : " (" + s.description + ")") + "\n";
}

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

PYBIND11_MODULE(_core, m) {
    m.doc() = "stackbeam's C++ core; use the package stackbeam (docs/python.md)";

    // numpy's C API now, while the import holds the GIL on one thread: pybind11 2.10 looks it up
    // in a function-local static on the first array made, importing numpy inside the static's
    // guard, and two runs finishing at once on two threads deadlocked there (one thread holding
    // the guard and waiting for the GIL, the other holding the GIL and waiting for the guard)
    py::array_t<double> first_array(0);
    (void)first_array;

    // --- exceptions: InputError(ValueError) with .field and .location; SolverError(RuntimeError)
    static py::exception<InputError> input_error(m, "InputError", PyExc_ValueError);
    static py::exception<SolverError> solver_error(m, "SolverError", PyExc_RuntimeError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const InputError& e) {
            py::object exc = py::handle(input_error.ptr())(e.what());
            exc.attr("field") = e.field();
            exc.attr("location") = e.location();
            PyErr_SetObject(input_error.ptr(), exc.ptr());
        } catch (const SolverError& e) {
            py::object exc = py::handle(solver_error.ptr())(e.what());
            exc.attr("step") = e.step();
            exc.attr("time_s") = e.time_s();
            exc.attr("residual") = e.residual();
            PyErr_SetObject(solver_error.ptr(), exc.ptr());
        }
    });

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

    m.def("_run", &run, "scenario"_a, "options"_a, "pairs"_a, "nodes"_a);
    m.def("_stack_geometry", &stack_geometry, "scenario"_a);
    m.def("_sweep", &sweep, "spec"_a, "jobs"_a, "out_dir"_a, "restart"_a, "keep_series"_a);
    m.def("step_record_columns", &step_record_columns);
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

    py::class_<PyStepper>(m, "Stepper", "One record at a time (make_stepper): co-simulation from Python")
        .def(py::init<const ScenarioPtr&, const py::dict&>())
        .def("advance", &PyStepper::advance, "Advances to the next record time; returns its record (CSV columns)")
        .def_property_readonly("current", &PyStepper::current)
        .def_property_readonly("record_index", &PyStepper::record_index)
        .def_property_readonly("records", &PyStepper::records, "records of the whole run to t_end_s (the first: t = 0)")
        .def_property_readonly("dt_s", &PyStepper::dt_s)
        .def("pairs", &PyStepper::pairs, "Every contact pair at the current record (the --pairs columns but t)")
        .def("nodes", &PyStepper::nodes, "Every leaf's nodes at the current record (the --nodes columns but t)")
        .def("report", &PyStepper::report);
}
