// sweep (_sweep): `stackbeam sweep` from Python, the points on threads with the GIL released (bindings.hpp).
#include "bindings.hpp"

namespace stackbeam_py {

namespace {

/// The most threads a sweep takes (jobs): more than any machine's cores this module meets, and
/// few enough that the threads' stacks (8 MiB of address space each by default) fit.
constexpr int kMaxSweepJobs = 1024;

/// sweep(spec_path, jobs, out_dir, restart, keep_series) -> dict(columns, axes, figures, ...):
/// the sweep of `stackbeam sweep` (study/sweep.hpp): every point read and checked before any
/// run, the points run on `jobs` threads with the GIL released, the table in point order. With
/// an out_dir the points go through the same results directory as the command line's
/// (journal, resume, points.csv, sweep.json); without one nothing is written.
py::dict sweep(const std::string& spec_path, const py::object& jobs_arg, const std::string& out_dir, bool restart,
               bool keep_series) {
    // None: the machine's cores; a thread the system refuses all the same raises ThreadStartError
    const int jobs = jobs_arg.is_none() ? 0 : static_cast<int>(integer_arg(jobs_arg, "jobs", 1, kMaxSweepJobs));
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
        std::future<int> done;
        try {
            done = std::async(std::launch::async, [&] {
            return run_sweep(points, options, [&](const PointResult& r) {
                PointResult row = r;
                row.records = nullptr;
                if (dir) dir->record(r);
                results[static_cast<std::size_t>(r.index)] = std::move(row);
            });
            });
        } catch (const std::system_error& e) {  // ThreadStartError in Python (errors.cpp)
            throw std::system_error(e.code(), "could not start the sweep's thread");
        }
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

}  // namespace

void bind_sweep(py::module_& m) {
    m.def("_sweep", &sweep, "spec"_a, "jobs"_a, "out_dir"_a, "restart"_a, "keep_series"_a);
    m.attr("MAX_SWEEP_JOBS") = kMaxSweepJobs;
}

}  // namespace stackbeam_py
