// A run's results as numpy arrays: records, events, report, the stack's geometry (bindings.hpp).
#include "bindings.hpp"

namespace stackbeam_py {

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
    return py::dict("t"_a = array_of(t), "interface"_a = array_of(interface_index), "x"_a = array_of(x),
                    "pair"_a = array_of(pair), "from"_a = array(from, "dtype"_a = "U8"), "to"_a = array(to, "dtype"_a = "U8"),
                    "cause"_a = array(cause, "dtype"_a = "U8"), "w"_a = array_of(w), "w_dot"_a = array_of(w_dot));
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

}  // namespace stackbeam_py
