#pragma once
/// @file sweep_output.hpp
/// The sweep directory: where a sweep keeps its results, written only when the caller
/// opens one (the CLI's --out-dir). docs/sweep.md, "Outputs" and "Resume".
///
///   DIR/spec.json          the resolved spec (base scenario text, axes' values, combine):
///                          a later run in DIR must have the same one (else refused, the
///                          difference named), so results of two specs never mix
///   DIR/finished.csv       the journal: the header, then one row per finished point in the
///                          order they finished, each appended whole and fsync'ed
///   DIR/points.csv         the table, one row per point in point order (written by finish())
///   DIR/sweep.json         the spec, the program's version, counts, times (finish())
///   DIR/scenarios/point-NNNN.toml   each point's scenario (`stackbeam simulate --scenario` runs it)
///   DIR/loops/point-NNNN.csv        each ok point's last loop (t, w, spring force) when it has one
///   DIR/loops/point-NNNN-fancher.csv   Fancher's model fitted to it along the same path
///                                   (t, w, fancher_force_n) when the fit succeeded
///   DIR/series/point-NNNN.csv       each point's records (only with keep_series)
///
/// Resume: opening DIR again reads the journal; its whole rows are the finished points
/// (a row cut by a crash is dropped, its point runs again).
#include <string>
#include <vector>

#include "stackbeam/study/sweep.hpp"

namespace stackbeam {

/// points.csv's header: point, one column per axis (its key), status, message, the
/// figures (point_figure_columns), wall_time_s.
std::string point_table_header(const SweepSpec& spec);

/// One row of points.csv (no newline): floats as round_trip_text, NaN as an
/// empty cell; the message quoted as CSV wants.
std::string format_point_row(const SweepPoint& point, const PointResult& result);

/// Reads a row written by format_point_row back (figures as printed: the same doubles).
/// Throws std::invalid_argument when the row is not whole.
PointResult parse_point_row(const SweepSpec& spec, const std::string& row);

/// Counts and times of a sweep, for sweep.json.
struct SweepTotals {
    double wall_s = 0.0;  ///< wall time of this invocation [s]
    int jobs = 1;         ///< threads per process
    int processes = 1;    ///< MPI ranks (1 without MPI)
};

class SweepDirectory {
public:
    /// Opens (creates) `directory` for `spec` and its `points`. With `restart`, the results of
    /// an earlier run there are removed; otherwise a directory holding another spec's results
    /// is refused (InputError naming the difference and --restart) and the finished points are
    /// read back. Writes spec.json and every point's scenario. Keeps references to `spec` and
    /// `points`: they must outlive it.
    SweepDirectory(std::string directory, const SweepSpec& spec, const std::vector<SweepPoint>& points,
                   bool restart, bool keep_series);

    const std::string& directory() const noexcept { return directory_; }
    /// The points finished in earlier runs (index -> true), for SweepRunOptions::skip.
    const std::vector<bool>& finished() const noexcept { return finished_; }
    int finished_count() const;
    /// The rows finished so far (earlier runs and this one), by point index (unfinished: none).
    const std::vector<PointResult>& results() const noexcept { return results_; }

    /// Records a finished point: appends its row to the journal and syncs it to disk, writes
    /// its loop (and its series with keep_series) from result.records when it has them.
    /// Not thread-safe: call from one thread at a time (run_sweep's callback is).
    void record(const PointResult& result);
    /// Records a row computed elsewhere (another MPI rank), as text from format_point_row.
    void record_row(const std::string& row);

    /// Writes points.csv (every finished point, in point order) and sweep.json.
    void finish(const SweepTotals& totals);

private:
    void append(const std::string& row);
    std::string directory_;
    const SweepSpec& spec_;
    const std::vector<SweepPoint>& points_;
    bool keep_series_;
    std::vector<bool> finished_;
    std::vector<PointResult> results_;
};

/// Writes the files of one finished point under `directory` (its loop; its series with
/// keep_series) from result.records (nothing when it has none or is not ok). Used by
/// SweepDirectory::record, and by a process that runs points for another (MPI ranks).
void write_point_files(const std::string& directory, const SweepPoint& point, const PointResult& result,
                       bool keep_series);

/// The file of point `index` under DIR's `kind` folder: DIR/kind/point-NNNN<suffix>.ext
/// (the fitted loop: kind "loops", suffix "-fancher").
std::string point_file(const std::string& directory, const std::string& kind, int index, const std::string& ext,
                       const std::string& suffix = "");

}  // namespace stackbeam
