#pragma once
/// @file sweep.hpp
/// Characterisation maps: one base scenario run at many points, each point the base
/// with some keys set to other values (the axes). The user's guide is docs/sweep.md.
///
///   SweepSpec spec = load_sweep_spec("map.toml");        // InputError: spec file:line, key
///   std::vector<SweepPoint> points = expand_points(spec); // every point's scenario, validated
///   SweepRunOptions run;                                  // jobs = the machine's cores
///   run_sweep(points, run, [](const PointResult& r) { ... });  // one call per finished point
///
/// A spec is plain data: the base scenario's TOML text, the axes (a scenario key path and
/// its values) and how they combine (the Cartesian product, or zip). A point's scenario is
/// the base document with each axis key set to the point's value, then read by
/// parse_scenario (io/scenario.hpp): any scenario key can be an axis, and every point is
/// checked as a scenario file is, before any run.
///
/// Threads: run_sweep runs points on `jobs` threads of its own; the library keeps no
/// mutable state shared between runs (docs/decisions/022-sweeps.md; a ThreadSanitizer
/// test guards it). The library prints nothing and writes no file here; the sweep
/// directory (points.csv, resume) is study/sweep_output.hpp.
#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "stackbeam/errors.hpp"
#include "stackbeam/io/scenario.hpp"
#include "stackbeam/time/simulation.hpp"
#include "stackbeam/words.hpp"

namespace stackbeam {

/// One value of an axis as the spec gives it: a TOML number, integer, boolean or string.
using AxisValue = std::variant<double, long long, bool, std::string>;

/// The value as a table cell: a float as round_trip_text, an integer, true/false, or the
/// string as is.
std::string to_string(const AxisValue& value);

/// `x` in the fewest significant digits (15, 16 or 17, %g) that read back as the same
/// double: 0.1 is "0.1", and equal text is an equal double (tables compare figure for figure).
std::string round_trip_text(double x);

/// One axis: a scenario key and the values it takes.
struct SweepAxis {
    /// The key path in the scenario file: table keys joined by '.', an array element by
    /// [i] (0-based) or every element by [*]: "loading.displacement_m.amplitude",
    /// "interfaces[*].friction_coefficient", "leaves[2].height_m".
    std::string key;
    std::vector<AxisValue> values;  ///< in order; a float range (from/to/count) is expanded here
    std::string location;           ///< where the axis is written, "spec.toml:LINE" ("" for a spec made in code)
};

/// How the axes combine into points.
enum class Combine {
    product,  ///< every combination; the last axis varies fastest
    zip,      ///< the i-th value of every axis together (axes of equal length)
};
template <>
const std::vector<EnumWord<Combine>>& enum_words<Combine>();  ///< the spec's combine: product, zip
const char* to_string(Combine combine);

/// A sweep: the base scenario, the axes, how they combine.
struct SweepSpec {
    std::string source;              ///< the spec file's name (or the name given to parse_sweep_spec)
    std::string description;         ///< free text (`description`)
    std::string scenario_path;       ///< the base scenario's path as resolved (relative to the spec file)
    std::string scenario_text;       ///< its TOML text
    std::string scenario_location;   ///< where `scenario` is written, "spec.toml:LINE"
    std::vector<SweepAxis> axes;
    Combine combine = Combine::product;
    std::string output_directory;    ///< `[outputs] directory` ("" not given), relative to the working directory
    /// `[outputs] stresses = true`: every point's run feeds a StressMonitor (RunOutputs::stresses),
    /// for the stress columns of point_figure_columns() (NaN without; in the massless modes a solve per record)
    bool stresses = false;
};

/// Parses sweep spec TOML `text` (docs/sweep.md); `source_name` names it in messages and
/// relative scenario paths are relative to its directory. Reads the base scenario file.
/// Throws InputError naming "source:line", the key and what is allowed. Does not expand
/// the points (expand_points).
SweepSpec parse_sweep_spec(const std::string& text, const std::string& source_name);

/// Supplies the base scenario's TOML text for its resolved path (SweepSpec::scenario_path);
/// throws InputError("scenario", ..., location) when it has none.
using ScenarioReader = std::function<std::string(const std::string& path, const std::string& location)>;

/// parse_sweep_spec with the base scenario's text from `read_scenario` instead of the file
/// system: a program holding its scenarios in memory, and the spec reader's fuzz target
/// (fuzz/fuzz_sweep_spec.cpp), which must not read files the fuzzed text names.
SweepSpec parse_sweep_spec(const std::string& text, const std::string& source_name, const ScenarioReader& read_scenario);

/// Reads and parses the spec file at `path`.
SweepSpec load_sweep_spec(const std::string& path);

/// One point of a sweep: its values and its scenario, validated.
struct SweepPoint {
    int index = 0;                    ///< 0-based, in the order of the table
    std::vector<AxisValue> values;    ///< one per axis
    std::string scenario_text;        ///< the point's scenario file (the base with the values set; no [outputs])
    Scenario scenario;                ///< parse_scenario(scenario_text): Model::build and validate() succeed
    bool stresses = false;            ///< SweepSpec::stresses: the run makes the stress columns
};

/// The most points one sweep may have (docs/sweep.md, "Limits"). A sweep directory keeps
/// one row per point in memory (~0.3 kB) and checking a point before the run takes ~1 ms
/// (the rig scenario, docs/decisions/051), so 100,000 points cost ~30 MB and ~2 min of
/// checking (shown as progress) before the first run; a larger map is several specs. A
/// spec with more points is refused by parse_sweep_spec / point_count, with its size.
constexpr long long max_sweep_points = 100000;

/// The points of a spec made one at a time, when asked for: memory does not grow with
/// the number of points. point(i) is expand_points(spec)[i], figure for figure. Keeps a
/// reference to `spec` (it must outlive this); const member functions may be called from
/// several threads at once.
class SweepPoints {
public:
    /// Reads the base scenario's TOML and the axes' key paths; throws InputError as
    /// expand_points for a bad base document, key path, empty axis, unequal zip or a spec
    /// of more than max_sweep_points points.
    explicit SweepPoints(const SweepSpec& spec);
    int size() const noexcept { return count_; }
    const SweepSpec& spec() const noexcept { return *spec_; }
    /// Point i's axis values (cheap: no scenario is made).
    std::vector<AxisValue> values(int index) const;
    /// Point i, its scenario parsed and validated; throws InputError as expand_points.
    SweepPoint point(int index) const;
    /// Makes and checks every point in turn, keeping none (the check before any run);
    /// `progress` (may be empty) is called after each with the number checked.
    void check_all(const std::function<void(int checked)>& progress = {}) const;

private:
    struct Impl;
    const SweepSpec* spec_;
    int count_;
    std::shared_ptr<const Impl> impl_;
};

/// Every point of `spec` in table order, each scenario parsed and validated. Throws
/// InputError on the first bad one: "spec.toml:LINE: point N (key = value, ...): <key>:
/// <what is wrong>", naming the axis whose key or value is wrong (and its line) when the
/// error is about an axis key; an empty axis and a zip of unequal axes are refused first.
std::vector<SweepPoint> expand_points(const SweepSpec& spec);

/// The number of points `spec` has (the product of the axes' lengths, or their common
/// length for zip); throws InputError as expand_points for an empty axis or unequal zip.
int point_count(const SweepSpec& spec);

/// A point's status in the table.
enum class PointStatus {
    ok,           ///< ran to the end
    failed,       ///< a solver failure (SolverError): the message says where
    input_error,  ///< refused when its run started (an option the mode cannot take)
};
template <>
const std::vector<EnumWord<PointStatus>>& enum_words<PointStatus>();  ///< the table's status: ok, failed, input-error
const char* to_string(PointStatus status);

/// The per-point figures, the columns of points.csv after point, the axes, status and
/// message: names (with units) in the order of PointResult::figures.
const std::vector<std::string>& point_figure_columns();

/// The figures of one finished run, in the order of point_figure_columns(); NaN where a
/// figure does not exist (no periodic loading: no loop). The place to add a figure: its
/// name in point_figure_columns(), its value here. `note` says why the loop figures are
/// missing ("" if they are there).
std::vector<double> point_figures(const std::vector<StepRecord>& records, const SimulationOptions& options,
                                  std::string& note);

/// What one point gave.
struct PointResult {
    int index = 0;
    PointStatus status = PointStatus::ok;
    std::string message;             ///< failure message, or why the loop figures are empty ("" none)
    std::vector<double> figures;     ///< point_figure_columns() order; NaN where none (all NaN when not ok)
    double wall_s = 0.0;             ///< the point's wall time [s]
    /// The point's records (only during the on_point_done call that reports it; empty after
    /// a row is read back from a file)
    const std::vector<StepRecord>* records = nullptr;
    /// The point run (only during the on_point_done call, as records)
    const SweepPoint* point = nullptr;
};

/// Thrown by run_point when `stop` was set during the run (the point is not finished).
struct SweepStopped : std::runtime_error {
    SweepStopped() : std::runtime_error("sweep stopped") {}
};

/// Runs one point as `stackbeam simulate --scenario` runs its scenario file (the same
/// model, options and results, figure for figure) and computes its figures. A SolverError
/// or an InputError at the start of the run is returned as a failed / input-error row.
/// `stop` (may be null) is polled at every record: when set, throws SweepStopped. Calls
/// `with_records` (if set) with the records (and result.point) before they are dropped.
PointResult run_point(const SweepPoint& point, const std::atomic<bool>* stop = nullptr,
                      const std::function<void(const PointResult&)>& with_records = {});

/// How run_sweep runs the points.
struct SweepRunOptions {
    int jobs = 0;  ///< threads; 0: the machine's (std::thread::hardware_concurrency)
    /// Points not to run (finished in an earlier run: resume); index -> true. Empty: none.
    std::vector<bool> skip;
    /// Set from outside (a signal handler's flag) to stop: no point starts after it, the points
    /// in flight are abandoned (run_point's SweepStopped), run_sweep returns.
    const std::atomic<bool>* stop = nullptr;
    /// Hands out the next point to run (-1: none left); shared by all threads and called
    /// under a lock. Unset: the points in order, skipping `skip`. Set by a distributed
    /// runner (MPI) that shares the points with other processes.
    std::function<int()> next_point;
};

/// Called once per finished point, one call at a time (under a lock), from the worker threads.
using PointCallback = std::function<void(const PointResult&)>;

/// Runs `points` on opts.jobs threads; `on_point_done` gets every finished point's result
/// (records valid during the call). Returns the number of points run (stop: fewer). An
/// exception thrown by the callback stops the sweep and is rethrown here.
int run_sweep(const std::vector<SweepPoint>& points, const SweepRunOptions& opts, const PointCallback& on_point_done);

/// run_sweep over points made when they start (SweepPoints::point): memory bounded
/// whatever the number of points. The same rows, figure for figure.
int run_sweep(const SweepPoints& points, const SweepRunOptions& opts, const PointCallback& on_point_done);

}  // namespace stackbeam
