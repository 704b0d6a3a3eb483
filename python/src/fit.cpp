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
    py::list parameters, loops, history;
    for (const FitParameterResult& p : r.parameters)
        parameters.append(py::dict("key"_a = p.key, "value"_a = p.value, "standard_error"_a = p.standard_error,
                                   "lower"_a = p.lower, "upper"_a = p.upper, "at_bound"_a = p.at_bound,
                                   "identifiable"_a = p.identifiable, "note"_a = p.note));
    for (const FitLoopResult& l : r.loops)
        loops.append(py::dict("name"_a = l.name, "w_m"_a = array_of(l.w_m), "measured_force_n"_a = array_of(l.measured_force_n),
                              "fitted_force_n"_a = array_of(l.fitted_force_n), "branch"_a = array_of(l.branch),
                              "measured_area_j"_a = l.measured_area_j, "fitted_area_j"_a = l.fitted_area_j,
                              "rms_force_error_n"_a = l.rms_force_error_n));
    for (const FitIteration& it : r.history)
        history.append(py::dict("start"_a = it.start, "iteration"_a = it.iteration, "cost"_a = it.cost,
                                "values"_a = it.values, "runs"_a = it.runs, "accepted"_a = it.accepted));
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
