// fit (_fit): `stackbeam fit` from Python (study/fit.hpp), the runs on threads with the GIL released.
#include "bindings.hpp"

#include "stackbeam/study/fit.hpp"

namespace stackbeam_py {

namespace {

/// fit(spec_path, jobs) -> dict: the fitted values, their standard errors and identifiability,
/// the correlation, the warnings, the loops (numpy arrays), the history. Writes no file.
py::dict fit(const std::string& spec_path, const py::object& jobs_arg) {
    const int jobs = jobs_arg.is_none() ? 0 : static_cast<int>(integer_arg(jobs_arg, "jobs", 1, 1024));
    const FitSpec spec = load_fit_spec(spec_path);
    FitResult r;
    {
        py::gil_scoped_release release;
        FitOptions options;
        options.jobs = jobs;
        r = stackbeam::fit(spec, options);
    }
    auto array = [](const std::vector<double>& v) { return py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data()); };
    py::list parameters;
    for (const FitParameterResult& p : r.parameters) {
        py::dict d;
        d["key"] = p.key;
        d["value"] = p.value;
        d["standard_error"] = p.standard_error;
        d["lower"] = p.lower;
        d["upper"] = p.upper;
        d["at_bound"] = p.at_bound;
        d["identifiable"] = p.identifiable;
        d["note"] = p.note;
        parameters.append(d);
    }
    py::list loops;
    for (const FitLoopResult& l : r.loops) {
        py::dict d;
        d["name"] = l.name;
        d["w_m"] = array(l.w_m);
        d["measured_force_n"] = array(l.measured_force_n);
        d["fitted_force_n"] = array(l.fitted_force_n);
        d["branch"] = py::array_t<int>(static_cast<py::ssize_t>(l.branch.size()), l.branch.data());
        d["measured_area_j"] = l.measured_area_j;
        d["fitted_area_j"] = l.fitted_area_j;
        d["rms_force_error_n"] = l.rms_force_error_n;
        loops.append(d);
    }
    py::list history;
    for (const FitIteration& it : r.history) {
        py::dict d;
        d["start"] = it.start;
        d["iteration"] = it.iteration;
        d["cost"] = it.cost;
        d["values"] = it.values;
        d["runs"] = it.runs;
        d["accepted"] = it.accepted;
        history.append(d);
    }
    py::dict out;
    out["parameters"] = parameters;
    out["correlation"] = r.correlation;
    out["warnings"] = r.warnings;
    out["cost"] = r.cost;
    out["residual_count"] = r.residual_count;
    out["runs"] = r.runs;
    out["iterations"] = r.iterations;
    out["converged"] = r.converged;
    out["termination"] = r.termination;
    out["loops"] = loops;
    out["history"] = history;
    out["fitted_scenario"] = r.fitted_scenario_text;
    return out;
}

}  // namespace

void bind_fit(py::module_& m) {
    m.def("_fit", &fit, py::arg("spec"), py::arg("jobs") = py::none(),
          "The fit of `stackbeam fit SPEC` (docs/calibration.md) as a dict; use stackbeam.fit");
}

}  // namespace stackbeam_py
