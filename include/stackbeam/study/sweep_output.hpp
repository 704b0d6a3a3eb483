#pragma once
/// @file sweep_output.hpp
/// The sweep directory: where a sweep keeps its results, written only when the caller
/// opens one (the CLI's --out-dir). docs/sweep.md, "Outputs" and "Resume".
///
///   DIR/lock               the owner: a sweep holds an advisory lock (flock) on it while the
///                          directory is open and writes who it is (pid, host, start, spec);
///                          a second sweep there is refused naming the holder. The lock dies
///                          with the process (a kill -9 included): nothing to clean up
///   DIR/spec.json          the resolved spec (base scenario text, axes' values, combine):
///                          a later run in DIR must have the same one (else refused, the
///                          difference named), so results of two specs never mix
///   DIR/finished.csv       the journal: a line "# stackbeam sweep journal: spec ID (SOURCE)"
///                          (sweep_spec_id), the header, then one row per finished point in
///                          the order they finished, each appended whole and fsync'ed
///   DIR/points.csv         the table, one row per point in point order (written by finish())
///   DIR/sweep.json         the spec, the program's version, counts, times (finish())
///   DIR/scenarios/point-NNNN.toml   each run point's scenario (`stackbeam simulate --scenario` runs
///                                   it), written by the run that writes the point's row
///   DIR/loops/point-NNNN.csv        each ok point's last loop (t, w, spring force) when it has one
///   DIR/loops/point-NNNN-fancher.csv   Fancher's model fitted to it along the same path
///                                   (t, w, fancher_force_n) when the fit succeeded
///   DIR/series/point-NNNN.csv       each point's records (only with keep_series)
///
/// Resume: opening DIR again reads the journal; its whole rows are the finished points
/// (a row cut by a crash is dropped, its point runs again). Each row's axis values must be
/// its point's (else refused: the journal is another spec's); a damaged row is dropped and
/// named in notes() by its line, the rows after it are kept. Files under scenarios/, loops/,
/// series/ of points without a row are removed when the directory is opened (never reused).
#include <functional>
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
/// The same from the point's axis values.
std::string format_point_row(const std::vector<AxisValue>& values, const PointResult& result);

/// The spec's identity: 16 hex digits of a 64-bit FNV-1a hash of the resolved spec (base
/// scenario text, combine, axes' keys and values), written at the top of the journal. Not
/// a cryptographic hash: it tells specs apart, it does not guard against forgery.
std::string sweep_spec_id(const SweepSpec& spec);

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
    /// Opens (creates) `directory` for `spec` and its `points` and locks it (DIR/lock): a
    /// directory another sweep holds is refused (InputError "--out-dir", naming the holder).
    /// With `restart`, the results of an earlier run there are removed (InputError "--restart"
    /// with the system's reason when a file cannot be); otherwise a directory holding another
    /// spec's results is refused (InputError naming the difference and --restart) and the
    /// finished points are read back. Writes spec.json; a point's scenario is written with
    /// its row (record). Keeps references to `spec` and `points`: they must outlive it.
    SweepDirectory(std::string directory, const SweepSpec& spec, const std::vector<SweepPoint>& points,
                   bool restart, bool keep_series);
    /// The same over points made when asked for (memory bounded by the rows, not the scenarios).
    SweepDirectory(std::string directory, const SweepPoints& points, bool restart, bool keep_series);
    ~SweepDirectory();  ///< releases the lock
    SweepDirectory(const SweepDirectory&) = delete;
    SweepDirectory& operator=(const SweepDirectory&) = delete;

    const std::string& directory() const noexcept { return directory_; }
    /// The points finished in earlier runs (index -> true), for SweepRunOptions::skip.
    const std::vector<bool>& finished() const noexcept { return finished_; }
    int finished_count() const;
    /// The rows finished so far (earlier runs and this one), by point index (unfinished: none).
    const std::vector<PointResult>& results() const noexcept { return results_; }
    /// What opening the directory found and repaired, for the caller to show: damaged
    /// journal rows dropped (by line), a cut last row ("" none).
    const std::vector<std::string>& notes() const noexcept { return notes_; }

    /// Records a finished point: writes its scenario, its loop (and its series with
    /// keep_series) from result.records when it has them, then appends its row to the journal
    /// and syncs it to disk (a row that cannot be written whole is cut back off: the journal
    /// ends on whole rows). The point is result.point when set, else made from its index.
    /// Not thread-safe: call from one thread at a time (run_sweep's callback is).
    void record(const PointResult& result);
    /// Records a row computed elsewhere (another MPI rank), as text from format_point_row.
    void record_row(const std::string& row);

    /// Writes points.csv (every finished point, in point order) and sweep.json.
    void finish(const SweepTotals& totals);

private:
    void open(bool restart);
    void append(const std::string& row);
    std::string directory_;
    const SweepSpec& spec_;
    int count_ = 0;
    std::function<std::vector<AxisValue>(int)> values_at_;
    std::function<SweepPoint(int)> point_at_;
    bool keep_series_;
    int lock_fd_ = -1;
    std::vector<bool> finished_;
    std::vector<PointResult> results_;
    std::vector<std::string> notes_;
};

/// Writes the files of one finished point under `directory`: its scenario (always, over any
/// older file), its loop (and its series with keep_series) from result.records when it is ok
/// and has them; an older loop or series file of the point is removed when there is none now.
/// A run that loads the seat: its windup loop (-windup), and its vertical loop only where the
/// row has that loop's figures (the seat held at a preload has none).
/// Used by SweepDirectory::record, and by a process that runs points for another (MPI ranks).
/// `spec_source` names the spec in the scenario file's first line. Write errors throw
/// std::runtime_error with the system's reason.
void write_point_files(const std::string& directory, const SweepPoint& point, const PointResult& result,
                       bool keep_series, const std::string& spec_source = "");

/// The file of point `index` under DIR's `kind` folder: DIR/kind/point-NNNN<suffix>.ext
/// (the fitted loop: kind "loops", suffix "-fancher").
std::string point_file(const std::string& directory, const std::string& kind, int index, const std::string& ext,
                       const std::string& suffix = "");

}  // namespace stackbeam
