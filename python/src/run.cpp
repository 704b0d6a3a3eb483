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
}  // namespace

void bind_run(py::module_& m) {
    m.def("_run", &run, "scenario"_a, "options"_a, "pairs"_a, "nodes"_a);
    m.def("_stack_geometry", &stack_geometry, "scenario"_a);
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
