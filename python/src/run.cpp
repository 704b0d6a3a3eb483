// simulate's run (_run) and the Stepper: a run steps with the GIL released (bindings.hpp).
#include "bindings.hpp"

namespace stackbeam_py {

/// Whether the calling thread is Python's main thread (the one that receives signals).
bool in_main_thread() {
    const py::object threading = py::module_::import("threading");
    return threading.attr("current_thread")().is(threading.attr("main_thread")());
}

namespace {

// --- the run ------------------------------------------------------------------------------

/// Ctrl-C while a run steps without the GIL. A signal's flag, set by the C-level handler, is
/// seen by Python only with the GIL held (PyErr_CheckSignals runs the Python handler, which
/// raises KeyboardInterrupt). The run's stop check (SimulationOptions::stop_requested, polled
/// by the steppers' inner loops: before every output, and every 64 internal steps of mode
/// cvode, event_driver.hpp) takes the GIL at most every 20 ms of wall time for that; in a
/// thread other than Python's main one PyErr_CheckSignals returns at once. The handler's
/// exception is kept and the stop check answers true: the run ends with RunStopped, and
/// raise_pending() raises the kept exception once the GIL is back.
class SignalPoll {
public:
    SignalPoll() = default;
    SignalPoll(const SignalPoll&) = delete;
    SignalPoll& operator=(const SignalPoll&) = delete;
    ~SignalPoll() {
        if (!type_) return;
        py::gil_scoped_acquire gil;
        Py_XDECREF(type_);
        Py_XDECREF(value_);
        Py_XDECREF(traceback_);
    }
    /// The stop check for SimulationOptions::stop_requested (this must outlive the run).
    std::function<bool()> stop_check() {
        return [this] { return poll(); };
    }
    /// With the GIL: raises the exception a signal's handler raised during the run, if any.
    void raise_pending() {
        if (!type_) return;
        PyErr_Restore(type_, value_, traceback_);  // steals the references
        type_ = value_ = traceback_ = nullptr;
        throw py::error_already_set();
    }

private:
    bool poll() {
        if (type_) return true;
        const auto now = std::chrono::steady_clock::now();
        if (now - last_ < std::chrono::milliseconds(20)) return false;
        last_ = now;
        py::gil_scoped_acquire gil;
        if (PyErr_CheckSignals() == 0) return false;
        PyErr_Fetch(&type_, &value_, &traceback_);
        return type_ != nullptr;
    }
    std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
    PyObject* type_ = nullptr;  ///< the handler's exception (PyErr_Fetch), owned
    PyObject* value_ = nullptr;
    PyObject* traceback_ = nullptr;
};

/// Every leaf's stresses at every record, per leaf as (records x nodes) arrays: Result.stresses.
/// SI units: sigma [Pa] (tension positive), N and V [N], M [N m] (post/stresses.hpp's signs).
struct StressTable {
    struct Leaf {
        int leaf = 0;
        std::vector<double> x, thickness, top, bottom, n, m, v;  // x, thickness: one per node; the rest row by row
    };
    std::vector<double> t;
    std::vector<Leaf> leaves;
    void add(double t_s, const Stresses& s) {
        if (leaves.empty())
            for (const LeafStresses& l : s.leaves) leaves.push_back({l.leaf, l.x_m, l.thickness_m, {}, {}, {}, {}, {}});
        t.push_back(t_s);
        for (std::size_t i = 0; i < s.leaves.size() && i < leaves.size(); ++i) {
            const LeafStresses& l = s.leaves[i];
            Leaf& k = leaves[i];
            k.top.insert(k.top.end(), l.top_stress_pa.begin(), l.top_stress_pa.end());
            k.bottom.insert(k.bottom.end(), l.bottom_stress_pa.begin(), l.bottom_stress_pa.end());
            k.n.insert(k.n.end(), l.axial_force_n.begin(), l.axial_force_n.end());
            k.m.insert(k.m.end(), l.bending_moment_n_m.begin(), l.bending_moment_n_m.end());
            k.v.insert(k.v.end(), l.shear_force_n.begin(), l.shear_force_n.end());
        }
    }
    py::list to_list() const {
        py::list out;
        for (const Leaf& k : leaves) {
            const auto rows = static_cast<py::ssize_t>(t.size()), cols = static_cast<py::ssize_t>(k.x.size());
            auto grid = [&](const std::vector<double>& v) {
                return py::array_t<double>(std::vector<py::ssize_t>{rows, cols}, v.data());
            };
            py::dict d;
            d["leaf"] = k.leaf;
            d["t"] = array_of(t);
            d["x"] = array_of(k.x);
            d["thickness"] = array_of(k.thickness);
            d["sigma_top"] = grid(k.top);
            d["sigma_bottom"] = grid(k.bottom);
            d["N"] = grid(k.n);
            d["M"] = grid(k.m);
            d["V"] = grid(k.v);
            out.append(d);
        }
        return out;
    }
};

/// The pairs, nodes and stresses of a run, kept as the --pairs, --nodes and --stresses columns
/// (the run layer's sink).
struct TableSink : RunSink {
    PairTable pairs;
    NodeTable nodes;
    StressTable stresses;
    void on_pairs(double t_s, const std::vector<PairRecord>& prs) override { pairs.add(t_s, prs); }
    void on_nodes(double t_s, const std::vector<LeafNodes>& leaves) override { nodes.add(t_s, leaves); }
    void on_stresses(double t_s, const Stresses& s) override { stresses.add(t_s, s); }
};

/// simulate(scenario, options, pairs) -> dict(columns, pairs, events, report, summary):
/// the library's run (run_scenario, as the command line: same records, same JSON summary), the
/// GIL released while it steps.
py::dict run(const ScenarioPtr& scenario, const py::dict& overrides, const py::object& pairs_arg, const py::object& nodes_arg,
             const py::object& stresses_arg) {
    RunRequest request;
    request.outputs.stresses = bool_arg(stresses_arg, "stresses");
    request.outputs.pairs = bool_arg(pairs_arg, "pairs");
    request.outputs.nodes = bool_arg(nodes_arg, "nodes");
    // the run's own copy: another thread may change the scenario while this one runs without the GIL
    const auto copy = std::make_shared<PyScenario>(*scenario_arg(scenario, "scenario"));
    copy->synced();
    const std::shared_ptr<const PyScenario> ps = copy;
    SignalPoll signals;  // Ctrl-C: KeyboardInterrupt within about 20 ms of the stop check's polls
    request.options = options_with(*ps, overrides);
    request.stop = signals.stop_check();
    request.setup = ps->setup;
    const Model model = build_checked(*ps, request.options);
    TableSink tables;
    request.sink = &tables;
    RunSummary summary;
    std::chrono::steady_clock::time_point released, reacquired;  // the stepping without the GIL
    {
        py::gil_scoped_release release;
        released = std::chrono::steady_clock::now();
        const System system(model);
        summary = in_scenario(*ps, [&] { return run_scenario(system, request); });
        reacquired = std::chrono::steady_clock::now();
    }
    if (summary.interrupted) signals.raise_pending();  // the stop check saw a signal: its exception

    py::dict out;
    out["columns"] = records_dict(summary.records);
    out["pairs"] = request.outputs.pairs ? py::object(tables.pairs.to_dict()) : py::object(py::none());
    out["nodes"] = request.outputs.nodes ? py::object(tables.nodes.to_dict()) : py::object(py::none());
    out["stresses"] = request.outputs.stresses ? py::object(tables.stresses.to_list()) : py::object(py::none());
    out["events"] = summary.stepper.cvode_stats ? py::object(events_dict(summary.report.events)) : py::object(py::none());
    py::dict report = report_dict(summary.report);
    // when the run held no GIL, on the clock of Python's time.monotonic() (CLOCK_MONOTONIC, as steady_clock)
    report["without_gil_s"] = py::make_tuple(std::chrono::duration<double>(released.time_since_epoch()).count(),
                                            std::chrono::duration<double>(reacquired.time_since_epoch()).count());
    out["report"] = report;
    out["summary"] = summary_json(summary, model);
    return out;
}
/// A stepper for co-simulation: the model, the options and the mode's Stepper, one record at a time.
/// advance() steps without the GIL and polls Ctrl-C as a run does (SignalPoll); after a
/// KeyboardInterrupt the stepper stays at its last record. Past the last record (t_end_s)
/// advance() raises InputError (field "advance") in every mode. One thread at a time: a call
/// while another thread is inside advance() raises RuntimeError instead of racing it.
class PyStepper {
public:
    PyStepper(const ScenarioPtr& scenario, const py::dict& overrides)
        : ps_(synced_copy(scenario_arg(scenario, "scenario"))),
          signals_(std::make_unique<SignalPoll>()),
          options_(with_stop_check(options_with(*ps_, overrides), *signals_)),
          system_(std::make_unique<System>(build_checked(*ps_, options_))),
          stepper_(in_scenario(*ps_, [&] { return make_stepper(*system_, options_); })),
          n_(static_cast<long>(std::ceil(options_.t_end_s / options_.dt_s - 1e-9))),
          cvode_stats_(describe_stepper(*system_, options_).cvode_stats) {}

    py::dict advance() {
        Busy busy(busy_, "advance");
        if (stepper_->record_index() >= n_)
            throw InputError("advance", "the run has reached t_end_s = " + format_value(options_.t_end_s) + " s (record " +
                                            std::to_string(n_) + ", the last): make a stepper with a later t_end_s");
        const StepRecord* r = nullptr;
        bool stopped = false;
        {
            py::gil_scoped_release release;
            try {
                r = &stepper_->advance();
            } catch (const RunStopped&) {  // the stop check saw a signal: its exception below, with the GIL
                stopped = true;
            }
        }
        if (stopped) signals_->raise_pending();
        return record_dict(*r);
    }
    py::dict current() const {
        idle("current");
        return record_dict(stepper_->current());
    }
    long record_index() const {
        idle("record_index");
        return stepper_->record_index();
    }
    long records() const { return n_ + 1; }
    double dt_s() const { return options_.dt_s; }
    py::dict pairs() const {
        idle("pairs");
        return at_current<PairTable>(stepper_->pairs());
    }
    py::dict nodes() const {
        idle("nodes");
        return at_current<NodeTable>(stepper_->nodes());
    }
    py::dict report() const {
        idle("report");
        const RunReport r = stepper_->report();
        py::dict d = report_dict(r);
        if (cvode_stats_) d["event_log"] = events_dict(r.events);
        return d;
    }

private:
    /// The table (PairTable, NodeTable) of `rows` at the current record, without its t column.
    template <class Table, class Rows>
    py::dict at_current(const Rows& rows) const {
        Table t;
        t.add(stepper_->current().t_s, rows);
        py::dict d = t.to_dict();
        d.attr("pop")("t");
        return d;
    }
    /// Marks the stepper busy for advance()'s time; RuntimeError if another thread is inside it.
    struct Busy {
        Busy(std::atomic<bool>& flag, const char* what) : flag_(flag) {
            if (flag_.exchange(true)) throw std::runtime_error(std::string("Stepper.") + what + ": another thread is inside advance()");
        }
        ~Busy() { flag_ = false; }
        std::atomic<bool>& flag_;
    };
    void idle(const char* what) const {
        if (busy_) throw std::runtime_error(std::string("Stepper.") + what + ": another thread is inside advance()");
    }
    static std::shared_ptr<PyScenario> synced_copy(const ScenarioPtr& scenario) {
        auto copy = std::make_shared<PyScenario>(*scenario);
        copy->synced();
        return copy;
    }
    static SimulationOptions with_stop_check(SimulationOptions o, SignalPoll& signals) {
        o.stop_requested = signals.stop_check();
        return o;
    }
    std::shared_ptr<PyScenario> ps_;  ///< the scenario as it was made from (for the errors' key paths)
    std::unique_ptr<SignalPoll> signals_;  ///< before the stepper: its stop check points here
    SimulationOptions options_;
    std::unique_ptr<System> system_;
    std::unique_ptr<Stepper> stepper_;
    long n_;
    bool cvode_stats_;  ///< the stepper keeps an event log (its registry row)
    std::atomic<bool> busy_{false};
};

}  // namespace

void bind_run(py::module_& m) {
    m.def("_run", &run, "scenario"_a, "options"_a, "pairs"_a, "nodes"_a, "stresses"_a);
    m.def(
        "_stack_geometry", [](const ScenarioPtr& scenario) { return stack_geometry(scenario_arg(scenario, "scenario")); },
        "scenario"_a);
    m.def("step_record_columns", &step_record_columns);

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

}  // namespace stackbeam_py
