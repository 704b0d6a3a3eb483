// The sweep directory (sweep_output.hpp): the journal of finished points, the table,
// the resolved spec for resume, each point's scenario, loop and series.
#include "stackbeam/study/sweep_output.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <ctime>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <optional>
#include <stdexcept>
#include <tuple>

#include "../io/toml_text.hpp"

#include "stackbeam/io/csv.hpp"
#include "stackbeam/post/fancher.hpp"
#include "stackbeam/post/hysteresis.hpp"
#include "stackbeam/run/loop_figures.hpp"

#ifndef STACKBEAM_VERSION
#define STACKBEAM_VERSION "unknown"
#endif

namespace stackbeam {

namespace fs = std::filesystem;

namespace {

std::string number_cell(double x) {
    if (std::isnan(x)) return "";
    return round_trip_text(x);
}

/// A CSV cell: quoted when it holds a comma, a quote or a line break (quotes doubled,
/// line breaks written as spaces: a row is one line).
std::string text_cell(std::string s) {
    for (char& c : s)
        if (c == '\n' || c == '\r') c = ' ';
    if (s.find_first_of(",\"") == std::string::npos) return s;
    std::string out = "\"";
    for (char c : s) {
        if (c == '"') out += '"';
        out += c;
    }
    return out + "\"";
}

/// Splits one CSV line into cells (quotes as text_cell writes them).
std::vector<std::string> split_row(const std::string& row) {
    std::vector<std::string> cells(1);
    bool quoted = false;
    for (std::size_t i = 0; i < row.size(); ++i) {
        const char c = row[i];
        if (quoted) {
            if (c == '"' && i + 1 < row.size() && row[i + 1] == '"') {
                cells.back() += '"';
                ++i;
            } else if (c == '"') {
                quoted = false;
            } else {
                cells.back() += c;
            }
        } else if (c == '"') {
            quoted = true;
        } else if (c == ',') {
            cells.emplace_back();
        } else {
            cells.back() += c;
        }
    }
    if (quoted) throw std::invalid_argument("an unterminated quote");
    return cells;
}

double parse_cell(const std::string& cell) {
    if (cell.empty()) return std::numeric_limits<double>::quiet_NaN();
    char* end = nullptr;
    const double x = std::strtod(cell.c_str(), &end);
    if (end == cell.c_str() || *end != '\0') throw std::invalid_argument("'" + cell + "' is not a number");
    return x;
}

/// The resolved spec: what must be equal for two runs to share a directory.
nlohmann::json spec_json(const SweepSpec& spec) {
    nlohmann::json axes = nlohmann::json::array();
    for (const SweepAxis& a : spec.axes) {
        nlohmann::json values = nlohmann::json::array();
        for (const AxisValue& v : a.values) values.push_back(to_string(v));
        axes.push_back({{"key", a.key}, {"values", values}});
    }
    return {{"scenario_path", spec.scenario_path},
            {"scenario_text", spec.scenario_text},
            {"combine", to_string(spec.combine)},
            {"axes", axes},
            {"stresses", spec.stresses}};
}

/// The first difference between two resolved specs, in words ("" if none).
std::string spec_difference(const nlohmann::json& old_spec, const nlohmann::json& now) {
    if (old_spec.value("scenario_text", "") != now["scenario_text"].get<std::string>())
        return "the base scenario's text differs (was " + old_spec.value("scenario_path", std::string("?")) + ", now " +
               now["scenario_path"].get<std::string>() + ")";
    if (old_spec.value("combine", "") != now["combine"].get<std::string>())
        return "combine was '" + old_spec.value("combine", std::string("?")) + "', now '" +
               now["combine"].get<std::string>() + "'";
    // a spec.json written before the key (no "stresses") is not compared: its journal's header tells
    if (old_spec.contains("stresses") && old_spec["stresses"] != now["stresses"])
        return "it was begun with [outputs] stresses = " + old_spec["stresses"].dump() + ", the spec now says " +
               now["stresses"].dump() + " (its rows' stress columns would be " +
               (now["stresses"].get<bool>() ? "empty" : "filled") + " where the new rows' are not)";
    const auto& a0 = old_spec.contains("axes") ? old_spec["axes"] : nlohmann::json::array();
    const auto& a1 = now["axes"];
    if (a0.size() != a1.size())
        return "it had " + std::to_string(a0.size()) + " axes, the spec now has " + std::to_string(a1.size());
    for (std::size_t i = 0; i < a1.size(); ++i) {
        if (a0[i].value("key", "") != a1[i]["key"].get<std::string>())
            return "axes[" + std::to_string(i) + "] was key '" + a0[i].value("key", std::string("?")) + "', now '" +
                   a1[i]["key"].get<std::string>() + "'";
        if (a0[i]["values"] != a1[i]["values"])
            return "axes[" + std::to_string(i) + "] (" + a1[i]["key"].get<std::string>() + ") had values " +
                   a0[i]["values"].dump() + ", now " + a1[i]["values"].dump();
    }
    return "";
}

std::string system_reason() { return std::strerror(errno); }

/// Writes all of `text` to `fd`; false with errno set on failure.
bool write_all(int fd, const std::string& text) {
    std::size_t written = 0;
    while (written < text.size()) {
        const ssize_t n = ::write(fd, text.data() + written, text.size() - written);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            if (n == 0) errno = EIO;
            return false;
        }
        written += static_cast<std::size_t>(n);
    }
    return true;
}

/// Writes `text` to PATH.partial, syncs it and renames it to PATH: PATH is the old file or
/// the whole new one. Failures name the file and the system's reason (the partial removed).
void write_whole(const std::string& path, const std::string& text) {
    const std::string partial = path + ".partial";
    const int fd = ::open(partial.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) throw std::runtime_error("cannot open '" + partial + "' for writing: " + system_reason());
    if (!write_all(fd, text) || ::fsync(fd) != 0) {
        const std::string why = system_reason();
        ::close(fd);
        ::unlink(partial.c_str());
        throw std::runtime_error("writing '" + partial + "' failed: " + why);
    }
    if (::close(fd) != 0) {
        const std::string why = system_reason();
        ::unlink(partial.c_str());
        throw std::runtime_error("writing '" + partial + "' failed: " + why);
    }
    if (std::rename(partial.c_str(), path.c_str()) != 0) {
        const std::string why = system_reason();
        ::unlink(partial.c_str());
        throw std::runtime_error("cannot rename '" + partial + "' to '" + path + "': " + why);
    }
}

/// The largest journal read back: 256 MiB (100,000 rows of ~0.4 kB are 40 MB).
constexpr long long max_journal_bytes = 256LL * 1024 * 1024;

std::string read_text(const std::string& path) {
    return detail::read_input_file(path, "the sweep file", "--out-dir", "", max_journal_bytes);
}

const char* kJournal = "finished.csv";
const char* kJournalId = "# stackbeam sweep journal: spec ";

/// A row's axis cell as format_point_row writes the value (text_cell, unquoted by split_row).
std::string axis_cell(const AxisValue& v) {
    std::string s = to_string(v);
    for (char& c : s)
        if (c == '\n' || c == '\r') c = ' ';
    return s;
}

/// Why a journal's header `old` is not this program's `now`, in words: written before the stress
/// columns (decision 061) or the windup columns (decision 068), or the first column that differs.
std::string header_difference(const std::string& old, const std::string& now) {
    const std::vector<std::string> a = split_row(old), b = split_row(now);
    // the columns later versions added, oldest first: an older header is this one without the last groups
    struct Added {
        const char* name;
        std::vector<std::string> columns;
    };
    const std::vector<Added> added = {
        {"stress", {"stress_max_abs_pa", "fatigue_least_safety_factor"}},
        {"windup",
         {"windup_stiffness_n_m_per_rad", "windup_loop_area_j", "windup_loss_factor", "longitudinal_compliance_m_per_n",
          "tangent_vertical_rate_n_per_m"}}};
    std::vector<std::string> without = b;
    std::string missing;  // "the stress columns A and B and the windup columns C, D and E"
    for (auto group = added.rbegin(); group != added.rend(); ++group) {
        for (const std::string& c : group->columns) without.erase(std::remove(without.begin(), without.end(), c), without.end());
        std::string list = std::string("the ") + group->name + " columns ";
        for (std::size_t i = 0; i < group->columns.size(); ++i)
            list += (i == 0 ? "" : i + 1 == group->columns.size() ? " and " : ", ") + group->columns[i];
        missing = missing.empty() ? list : list + " and " + missing;
        if (a == without) return "was written before the points table had " + missing + " (an older stackbeam)";
    }
    for (std::size_t i = 0; i < std::max(a.size(), b.size()); ++i)
        if (i >= a.size() || i >= b.size() || a[i] != b[i])
            return "has other columns than this program writes (another version?): column " + std::to_string(i + 1) +
                   " is '" + (i < a.size() ? a[i] : std::string("(none)")) + "', this program writes '" +
                   (i < b.size() ? b[i] : std::string("(none)")) + "'";
    return "has other columns than this program writes";
}

/// parse_point_row that also hands back the axis cells.
PointResult parse_row(const SweepSpec& spec, const std::string& row, std::vector<std::string>* axis_cells);

/// The index of a per-point file's name "point-NNNN..." (-1 if it is not one).
long long point_index_of(const std::string& name) {
    if (name.rfind("point-", 0) != 0) return -1;
    std::size_t i = 6, digits = 0;
    long long index = 0;
    while (i < name.size() && std::isdigit(static_cast<unsigned char>(name[i])) && digits < 12) {
        index = index * 10 + (name[i] - '0');
        ++i;
        ++digits;
    }
    return digits == 0 ? -1 : index;
}

}  // namespace

std::string point_file(const std::string& directory, const std::string& kind, int index, const std::string& ext,
                       const std::string& suffix) {
    char name[40];
    std::snprintf(name, sizeof name, "point-%04d", index);
    return (fs::path(directory) / kind / (name + suffix + "." + ext)).string();
}

std::string point_table_header(const SweepSpec& spec) {
    std::string h = "point";
    for (const SweepAxis& a : spec.axes) h += "," + text_cell(a.key);
    h += ",status,message";
    for (const std::string& c : point_figure_columns()) h += "," + c;
    return h + ",wall_time_s";
}

std::string format_point_row(const SweepPoint& point, const PointResult& r) {
    return format_point_row(point.values, r);
}

std::string format_point_row(const std::vector<AxisValue>& values, const PointResult& r) {
    std::string row = std::to_string(r.index);
    for (const AxisValue& v : values) row += "," + text_cell(to_string(v));
    row += std::string(",") + to_string(r.status) + "," + text_cell(r.message);
    for (double f : r.figures) row += "," + number_cell(f);
    return row + "," + number_cell(r.wall_s);
}

std::string sweep_spec_id(const SweepSpec& spec) {
    nlohmann::json values = spec_json(spec);
    values.erase("stresses");  // the id of the points' values, as before the key (a journal's first line)
    const std::string text = values.dump();
    std::uint64_t h = 14695981039346656037ULL;  // FNV-1a, 64 bits
    for (unsigned char c : text) {
        h ^= c;
        h *= 1099511628211ULL;
    }
    char id[17];
    std::snprintf(id, sizeof id, "%016llx", static_cast<unsigned long long>(h));
    return id;
}

PointResult parse_point_row(const SweepSpec& spec, const std::string& row) { return parse_row(spec, row, nullptr); }

namespace {

PointResult parse_row(const SweepSpec& spec, const std::string& row, std::vector<std::string>* axis_cells) {
    const auto cells = split_row(row);
    const std::size_t figures = point_figure_columns().size();
    const std::size_t expected = 1 + spec.axes.size() + 2 + figures + 1;
    if (cells.size() != expected)
        throw std::invalid_argument("has " + std::to_string(cells.size()) + " cells, a row has " + std::to_string(expected));
    PointResult r;
    std::size_t k = 0;
    const std::string& index = cells[k++];
    if (index.empty() || index.find_first_not_of("0123456789") != std::string::npos)
        throw std::invalid_argument("point '" + index + "' is not an index");
    if (index.size() > 9) throw std::invalid_argument("point '" + index + "' is not an index");
    r.index = std::stoi(index);
    if (axis_cells) axis_cells->assign(cells.begin() + 1, cells.begin() + 1 + static_cast<std::ptrdiff_t>(spec.axes.size()));
    k += spec.axes.size();
    const std::string& status = cells[k++];
    if (const auto s = find_word<PointStatus>(status)) r.status = *s;
    else throw std::invalid_argument("status '" + status + "' is not " + word_list<PointStatus>("", ", ", " or "));
    r.message = cells[k++];
    for (std::size_t i = 0; i < figures; ++i) r.figures.push_back(parse_cell(cells[k++]));
    r.wall_s = parse_cell(cells[k++]);
    return r;
}

/// Throws when a row's axis cells are not point `index`'s values: `where` names the row.
void check_row_values(const SweepSpec& spec, const std::vector<AxisValue>& values, const std::vector<std::string>& cells,
                      int index, const std::string& where) {
    for (std::size_t a = 0; a < spec.axes.size(); ++a)
        if (cells[a] != axis_cell(values[a]))
            throw InputError("--out-dir", where + ": the row of point " + std::to_string(index) + " has " +
                                              spec.axes[a].key + " = " + cells[a] + ", but point " +
                                              std::to_string(index) + " of this spec has " + spec.axes[a].key + " = " +
                                              axis_cell(values[a]) +
                                              ": the journal holds another spec's results (never reused); use "
                                              "another directory, or --restart to discard them");
}

}  // namespace

namespace {
/// Runs `open`; when it throws (a directory refused), closes the lock it may have taken first:
/// the destructor does not run for an object whose constructor threw, and a process that goes on
/// (Python) would hold the lock on the directory until it ends.
template <class Open>
void release_on_throw(int& lock_fd, Open&& open) {
    try {
        open();
    } catch (...) {
        if (lock_fd >= 0) ::close(lock_fd);
        lock_fd = -1;
        throw;
    }
}

/// Creates `directory` (and its parents) if it is not there.
void create_sweep_directory(const std::string& directory) {
    std::error_code ec;
    fs::create_directories(fs::path(directory), ec);
    if (ec || !fs::is_directory(fs::path(directory)))
        throw InputError("--out-dir", "cannot create the directory '" + directory + "'" + (ec ? ": " + ec.message() : ""));
}

/// Takes the owner's advisory lock on DIR/lock (held while `lock_fd` is open, or until the
/// process dies) and writes who holds it; a directory another sweep holds is refused naming
/// that holder. `lock_fd` is the lock file's descriptor (-1 when refused before it was locked).
void lock_sweep_directory(const std::string& directory, const std::string& spec_source, int& lock_fd) {
    const std::string lock_path = (fs::path(directory) / "lock").string();
    lock_fd = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (lock_fd < 0)
        throw InputError("--out-dir", "cannot open the lock file '" + lock_path + "': " + system_reason());
    if (::flock(lock_fd, LOCK_EX | LOCK_NB) != 0) {
        const std::string why = errno == EWOULDBLOCK ? "" : system_reason();
        std::string holder;
        char buffer[1024];
        const ssize_t n = ::pread(lock_fd, buffer, sizeof buffer - 1, 0);
        if (n > 0) holder.assign(buffer, static_cast<std::size_t>(n));
        while (!holder.empty() && (holder.back() == '\n' || holder.back() == ' ')) holder.pop_back();
        ::close(lock_fd);
        lock_fd = -1;
        if (!why.empty()) throw InputError("--out-dir", "cannot lock '" + lock_path + "': " + why);
        throw InputError("--out-dir", "'" + directory + "' is in use by another sweep (" +
                                          (holder.empty() ? std::string("its holder has not written its name yet") : holder) +
                                          "): wait for it to end or stop it, or use another directory");
    }
    char host[256] = "?";
    ::gethostname(host, sizeof host - 1);
    host[sizeof host - 1] = '\0';
    char when[32] = "?";
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    if (::gmtime_r(&now, &utc)) std::strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", &utc);
    const std::string me = "pid " + std::to_string(::getpid()) + " on " + host + ", started " + when + ", spec " +
                           spec_source + "\n";
    if (::ftruncate(lock_fd, 0) != 0 || ::pwrite(lock_fd, me.data(), me.size(), 0) != static_cast<ssize_t>(me.size()))
        throw InputError("--out-dir", "cannot write the lock file '" + lock_path + "': " + system_reason());
}

/// --restart: deletes the results of the sweep in `dir` (the lock stays).
void discard_results(const fs::path& dir) {
    auto remove = [&](const fs::path& path, bool tree) {
        std::error_code rec;
        if (tree) fs::remove_all(path, rec);
        else fs::remove(path, rec);
        if (rec)
            throw InputError("--restart", "cannot delete '" + path.string() + "': " + rec.message() +
                                              " (nothing was run; the old results are still there)");
    };
    for (const char* f : {kJournal, "spec.json", "points.csv", "sweep.json"}) remove(dir / f, false);
    for (const char* d : {"scenarios", "loops", "series", "figures"}) remove(dir / d, true);
}

/// Refuses a directory that holds another sweep's results: its spec.json differs from `now`,
/// or it has results without a spec.json.
void check_same_sweep(const std::string& directory, const nlohmann::json& now) {
    const fs::path dir(directory);
    const fs::path spec_file = dir / "spec.json";
    if (fs::exists(spec_file)) {
        nlohmann::json old_spec;
        try {
            old_spec = nlohmann::json::parse(read_text(spec_file.string()));
        } catch (const std::exception&) {
            throw InputError("--out-dir", "'" + spec_file.string() + "' is not readable JSON: use --restart to start over");
        }
        const std::string diff = spec_difference(old_spec, now);
        if (!diff.empty())
            throw InputError("--out-dir", "'" + directory + "' holds the results of another sweep: " + diff +
                                              "; use another directory, or --restart to discard them");
    } else if (fs::exists(dir / kJournal) || fs::exists(dir / "points.csv")) {
        throw InputError("--out-dir", "'" + directory + "' holds sweep results without spec.json: use another "
                                      "directory, or --restart to discard them");
    }
}

/// A new journal's first two lines: the id line naming the spec, and the points table's header.
std::string journal_start(const SweepSpec& spec) {
    return kJournalId + sweep_spec_id(spec) + " (" + spec.source + ")\n" + point_table_header(spec) + "\n";
}

/// What a journal read back holds: the finished points' rows, and the journal's text to keep
/// when it must be repaired (a damaged or cut row dropped, an older version's id line added).
struct JournalReplay {
    std::vector<bool> finished;
    std::vector<PointResult> results;
    std::vector<std::string> notes;
    bool repaired = false;
    std::string kept;
};

/// Reads the journal `path` back: every whole row whose values are its point's (values_at) is a
/// finished point; a damaged row is dropped (named by line) and the rows after it kept; a line
/// cut by a crash is dropped. A journal of another spec, or with other columns, is refused.
JournalReplay replay_journal(const std::string& path, const SweepSpec& spec, int count,
                             const std::function<std::vector<AxisValue>(int)>& values_at) {
    JournalReplay replay;
    replay.finished.assign(static_cast<std::size_t>(count), false);
    replay.results.resize(static_cast<std::size_t>(count));
    const std::string header = point_table_header(spec);
    const std::string text = read_text(path);
    replay.kept = journal_start(spec);
    bool header_seen = false;
    std::size_t start = 0;
    for (long line_no = 1; start < text.size(); ++line_no) {
        const std::size_t end = text.find('\n', start);
        const std::string at_line = path + " line " + std::to_string(line_no);
        if (end == std::string::npos) {  // no newline: cut by a crash
            replay.notes.push_back(at_line +
                                   ": a row cut short (the run was stopped while writing it) was dropped; its point runs again");
            replay.repaired = true;
            break;
        }
        const std::string line = text.substr(start, end - start);
        start = end + 1;
        if (!header_seen) {
            if (line.rfind(kJournalId, 0) == 0) {
                if (line_no != 1 || line.rfind(kJournalId + sweep_spec_id(spec), 0) != 0)
                    throw InputError("--out-dir", at_line + " says '" + line + "', this spec is " + sweep_spec_id(spec) +
                                                      " (" + spec.source +
                                                      "): the journal holds another spec's results; use another "
                                                      "directory, or --restart to discard them");
                continue;
            }
            if (line != header)
                throw InputError("--out-dir", "'" + path + "' " + header_difference(line, header) +
                                                  ": its rows cannot be resumed; use --restart to discard them and "
                                                  "run every point again, or another --out-dir");
            header_seen = true;
            if (line_no == 1) replay.repaired = true;  // a journal of an older version: its id line is added
            continue;
        }
        PointResult r;
        std::vector<std::string> cells;
        try {
            r = parse_row(spec, line, &cells);
            if (r.index < 0 || r.index >= count)
                throw std::invalid_argument("point " + std::to_string(r.index) + " does not exist (the spec has " +
                                            std::to_string(count) + ")");
        } catch (const std::invalid_argument& e) {
            replay.notes.push_back(at_line + ": a damaged row was dropped (" + e.what() +
                                   "); the rows after it are kept, its point runs again");
            replay.repaired = true;
            continue;
        }
        check_row_values(spec, values_at(r.index), cells, r.index, at_line);
        replay.finished[static_cast<std::size_t>(r.index)] = true;
        replay.results[static_cast<std::size_t>(r.index)] = r;
        replay.kept += line + "\n";
    }
    if (!header_seen) replay.repaired = true;  // empty, or only the id line
    return replay;
}

/// Removes the per-point files of points without a row (another run's: never reused), then
/// makes the per-point folders this run writes.
void prepare_point_folders(const fs::path& dir, const std::vector<bool>& finished, bool keep_series) {
    std::error_code ec;
    for (const char* kind : {"scenarios", "loops", "series"}) {
        const fs::path folder = dir / kind;
        if (!fs::is_directory(folder, ec)) continue;
        for (const auto& entry : fs::directory_iterator(folder, ec)) {
            const long long index = point_index_of(entry.path().filename().string());
            if (index >= 0 && index < static_cast<long long>(finished.size()) && finished[static_cast<std::size_t>(index)])
                continue;
            std::error_code rec;
            fs::remove(entry.path(), rec);
            if (rec)
                throw InputError("--out-dir", "cannot delete the stale file '" + entry.path().string() +
                                                  "' (no row of this sweep owns it): " + rec.message());
        }
    }
    std::vector<const char*> kinds = {"scenarios", "loops"};
    if (keep_series) kinds.push_back("series");
    for (const char* kind : kinds) {
        fs::create_directories(dir / kind, ec);
        if (ec) throw InputError("--out-dir", "cannot create '" + (dir / kind).string() + "': " + ec.message());
    }
}
}  // namespace

SweepDirectory::SweepDirectory(std::string directory, const SweepSpec& spec, const std::vector<SweepPoint>& points,
                               bool restart, bool keep_series)
    : directory_(std::move(directory)), spec_(spec), count_(static_cast<int>(points.size())), keep_series_(keep_series) {
    values_at_ = [&points](int i) { return points.at(static_cast<std::size_t>(i)).values; };
    point_at_ = [&points](int i) { return points.at(static_cast<std::size_t>(i)); };
    release_on_throw(lock_fd_, [&] { open(restart); });
}

SweepDirectory::SweepDirectory(std::string directory, const SweepPoints& points, bool restart, bool keep_series)
    : directory_(std::move(directory)), spec_(points.spec()), count_(points.size()), keep_series_(keep_series) {
    values_at_ = [&points](int i) { return points.values(i); };
    point_at_ = [&points](int i) { return points.point(i); };
    release_on_throw(lock_fd_, [&] { open(restart); });
}

SweepDirectory::~SweepDirectory() {
    if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the flock
}

void SweepDirectory::open(bool restart) {
    finished_.assign(static_cast<std::size_t>(count_), false);
    results_.resize(static_cast<std::size_t>(count_));
    const fs::path dir(directory_);
    create_sweep_directory(directory_);
    lock_sweep_directory(directory_, spec_.source, lock_fd_);
    const nlohmann::json now = spec_json(spec_);
    const fs::path spec_file = dir / "spec.json";
    const fs::path journal = dir / kJournal;
    if (restart) discard_results(dir);
    else check_same_sweep(directory_, now);
    if (fs::exists(journal)) {
        JournalReplay replay = replay_journal(journal.string(), spec_, count_, values_at_);
        finished_ = std::move(replay.finished);
        results_ = std::move(replay.results);
        notes_.insert(notes_.end(), replay.notes.begin(), replay.notes.end());
        // a repaired journal is replaced whole (renamed over), so that new rows follow whole ones
        if (replay.repaired) write_whole(journal.string(), replay.kept);
    } else {
        write_whole(spec_file.string(), now.dump(2) + "\n");
        write_whole(journal.string(), journal_start(spec_));
    }
    if (!fs::exists(spec_file)) write_whole(spec_file.string(), now.dump(2) + "\n");
    prepare_point_folders(dir, finished_, keep_series_);
}

int SweepDirectory::finished_count() const {
    int n = 0;
    for (bool f : finished_) n += f ? 1 : 0;
    return n;
}

void SweepDirectory::append(const std::string& row) {
    const std::string path = (fs::path(directory_) / kJournal).string();
    const int fd = ::open(path.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) throw std::runtime_error("cannot open '" + path + "': " + std::strerror(errno));
    struct stat before {};
    const bool sized = ::fstat(fd, &before) == 0;
    if (!write_all(fd, row + "\n")) {
        // a row written in part (a full disk) is cut back off: the journal ends on whole rows
        const std::string why = system_reason();
        if (sized) (void)::ftruncate(fd, before.st_size);
        ::close(fd);
        throw std::runtime_error("writing '" + path + "' failed: " + why);
    }
    const bool synced = ::fsync(fd) == 0;
    ::close(fd);
    if (!synced) throw std::runtime_error("fsync of '" + path + "' failed: " + std::strerror(errno));
}

void write_point_files(const std::string& directory, const SweepPoint& point, const PointResult& r, bool keep_series,
                       const std::string& spec_source) {
    write_whole(point_file(directory, "scenarios", r.index, "toml"),
                "# point " + std::to_string(r.index) + " of the sweep " + (spec_source.empty() ? "" : spec_source + " ") +
                    "(stackbeam simulate --scenario FILE --out OUT.csv runs it)\n" + point.scenario_text);
    // an older run's files of this point go first: those written below are this row's
    for (const auto& [kind, ext, suffix] : {std::tuple<const char*, const char*, const char*>{"loops", "csv", ""},
                                            {"loops", "csv", "-fancher"}, {"loops", "csv", "-windup"},
                                            {"series", "csv", ""}}) {
        std::error_code ec;
        fs::remove(point_file(directory, kind, r.index, ext, suffix), ec);
    }
    if (r.records && r.status == PointStatus::ok) {
        const auto& records = *r.records;
        const auto& columns = point_figure_columns();
        auto figure = [&](const char* name) {
            const auto i = std::find(columns.begin(), columns.end(), name) - columns.begin();
            return static_cast<std::size_t>(i) < r.figures.size() ? r.figures[static_cast<std::size_t>(i)] : std::nan("");
        };
        const Loading& loading = point.scenario.simulation.loading;
        // a run that loads the seat has a vertical loop file only where its row has the vertical loop
        // (a seat held at a preload has none: w constant, the file a vertical line in the sweep's figure)
        const bool vertical_loop = !loads_the_seat(loading) || !std::isnan(figure("secant_stiffness_n_per_m"));
        const double period = vertical_loop ? loading.period_s() : 0.0;
        if (period > 0.0) {
            try {
                const auto cycle = last_cycle(records, period);
                std::ostringstream loop;
                loop << "t_s,w_m,spring_force_n\n";
                std::vector<double> t, w;
                for (const StepRecord& s : records)
                    if (s.t_s >= cycle.first && s.t_s <= cycle.second) {
                        loop << number_cell(s.t_s) << ',' << number_cell(s.w_m) << ',' << number_cell(s.spring_force_n)
                             << '\n';
                        t.push_back(s.t_s);
                        w.push_back(s.w_m);
                    }
                write_whole(point_file(directory, "loops", r.index, "csv"), loop.str());
                // the fitted Fancher loop along the same path, from the row's parameters: the
                // model in its periodic state, as fit_fancher_loop's model_force_n
                FancherParameters p;
                p.upper_rate_n_per_m = figure("fancher_upper_rate_n_per_m");
                p.upper_offset_n = figure("fancher_upper_offset_n");
                p.lower_rate_n_per_m = figure("fancher_lower_rate_n_per_m");
                p.lower_offset_n = figure("fancher_lower_offset_n");
                p.beta_m = figure("fancher_beta_m");
                if (!std::isnan(p.beta_m) && w.size() >= 2) {
                    const std::vector<double> model = fancher_force(p, w, fancher_periodic_start_force(p, w));
                    std::ostringstream fitted;
                    fitted << "t_s,w_m,fancher_force_n\n";
                    for (std::size_t i = 0; i < w.size(); ++i)
                        fitted << number_cell(t[i]) << ',' << number_cell(w[i]) << ',' << number_cell(model[i]) << '\n';
                    write_whole(point_file(directory, "loops", r.index, "csv", "-fancher"), fitted.str());
                }
            } catch (const InputError&) {
                // no whole cycle: the row's message says so, no loop file
            }
        }
        // a windup run: its windup loop's last cycle (windup_figures' cycle), the moment against the rotation
        const double windup_period = loads_the_seat(loading) ? windup_period_s(loading) : 0.0;
        if (windup_period > 0.0) {
            try {
                const auto cycle = last_cycle(records, windup_period);
                std::ostringstream loop;
                loop << "t_s,seat_rotation_rad,seat_moment_n_m\n";
                for (const StepRecord& s : records)
                    if (s.t_s >= cycle.first && s.t_s <= cycle.second)
                        loop << number_cell(s.t_s) << ',' << number_cell(s.seat_rotation_rad) << ','
                             << number_cell(s.seat_moment_n_m) << '\n';
                write_whole(point_file(directory, "loops", r.index, "csv", "-windup"), loop.str());
            } catch (const InputError&) {
                // no whole cycle: no windup loop file
            }
        }
        if (keep_series) {
            std::ostringstream series;
            write_csv_header(series);
            for (const StepRecord& s : records) write_csv_row(series, s);
            write_whole(point_file(directory, "series", r.index, "csv"), series.str());
        }
    }
}

void SweepDirectory::record(const PointResult& r) {
    if (r.index < 0 || r.index >= count_) throw std::invalid_argument("record: no point " + std::to_string(r.index));
    std::optional<SweepPoint> made;
    if (!r.point) made = point_at_(r.index);
    const SweepPoint& point = r.point ? *r.point : *made;
    write_point_files(directory_, point, r, keep_series_, spec_.source);
    append(format_point_row(point, r));  // last: a point is finished once its row is on disk
    finished_[static_cast<std::size_t>(r.index)] = true;
    results_[static_cast<std::size_t>(r.index)] = r;
    results_[static_cast<std::size_t>(r.index)].records = nullptr;
}

void SweepDirectory::record_row(const std::string& row) {
    std::vector<std::string> cells;
    const PointResult r = parse_row(spec_, row, &cells);
    if (r.index < 0 || r.index >= count_)
        throw std::invalid_argument("row of point " + std::to_string(r.index) + ": no such point");
    check_row_values(spec_, values_at_(r.index), cells, r.index, "a row sent by another process");
    append(row);
    finished_[static_cast<std::size_t>(r.index)] = true;
    results_[static_cast<std::size_t>(r.index)] = r;
}

void SweepDirectory::finish(const SweepTotals& totals) {
    std::string table = point_table_header(spec_) + "\n";
    int ok = 0, failed = 0, input = 0, missing = 0;
    double point_wall = 0.0;
    for (std::size_t i = 0; i < finished_.size(); ++i) {
        if (!finished_[i]) {
            ++missing;
            continue;
        }
        const PointResult& r = results_[i];
        table += format_point_row(values_at_(static_cast<int>(i)), r) + "\n";
        point_wall += r.wall_s;
        (r.status == PointStatus::ok ? ok : r.status == PointStatus::failed ? failed : input) += 1;
    }
    write_whole((fs::path(directory_) / "points.csv").string(), table);
    nlohmann::json j;
    j["program"] = {{"name", "stackbeam"}, {"version", STACKBEAM_VERSION}};
    j["spec"] = spec_json(spec_);
    j["spec"]["source"] = spec_.source;
    j["spec"]["description"] = spec_.description;
    j["counts"] = {{"points", count_}, {"ok", ok}, {"failed", failed}, {"input_error", input}, {"not_run", missing}};
    j["complete"] = missing == 0;
    j["wall_time_s"] = totals.wall_s;
    j["points_wall_time_s"] = point_wall;
    j["jobs"] = totals.jobs;
    j["processes"] = totals.processes;
    j["columns"] = split_row(point_table_header(spec_));
    write_whole((fs::path(directory_) / "sweep.json").string(), j.dump(2) + "\n");
}

}  // namespace stackbeam
