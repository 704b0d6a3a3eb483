// The sweep directory (sweep_output.hpp): the journal of finished points, the table,
// the resolved spec for resume, each point's scenario, loop and series.
#include "stackbeam/study/sweep_output.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "stackbeam/io/csv.hpp"
#include "stackbeam/post/fancher.hpp"
#include "stackbeam/post/hysteresis.hpp"

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
            {"axes", axes}};
}

/// The first difference between two resolved specs, in words ("" if none).
std::string spec_difference(const nlohmann::json& old_spec, const nlohmann::json& now) {
    if (old_spec.value("scenario_text", "") != now["scenario_text"].get<std::string>())
        return "the base scenario's text differs (was " + old_spec.value("scenario_path", std::string("?")) + ", now " +
               now["scenario_path"].get<std::string>() + ")";
    if (old_spec.value("combine", "") != now["combine"].get<std::string>())
        return "combine was '" + old_spec.value("combine", std::string("?")) + "', now '" +
               now["combine"].get<std::string>() + "'";
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

void write_whole(const std::string& path, const std::string& text) {
    const std::string partial = path + ".partial";
    {
        std::ofstream out(partial, std::ios::out | std::ios::trunc | std::ios::binary);
        if (!out) throw std::runtime_error("cannot open '" + partial + "' for writing");
        out << text;
        out.close();
        if (out.fail()) throw std::runtime_error("writing '" + partial + "' failed");
    }
    if (std::rename(partial.c_str(), path.c_str()) != 0)
        throw std::runtime_error("cannot rename '" + partial + "' to '" + path + "'");
}

std::string read_text(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

const char* kJournal = "finished.csv";

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
    std::string row = std::to_string(r.index);
    for (const AxisValue& v : point.values) row += "," + text_cell(to_string(v));
    row += std::string(",") + to_string(r.status) + "," + text_cell(r.message);
    for (double f : r.figures) row += "," + number_cell(f);
    return row + "," + number_cell(r.wall_s);
}

PointResult parse_point_row(const SweepSpec& spec, const std::string& row) {
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
    r.index = std::stoi(index);
    k += spec.axes.size();
    const std::string& status = cells[k++];
    if (status == "ok") r.status = PointStatus::ok;
    else if (status == "failed") r.status = PointStatus::failed;
    else if (status == "input-error") r.status = PointStatus::input_error;
    else throw std::invalid_argument("status '" + status + "' is not ok, failed or input-error");
    r.message = cells[k++];
    for (std::size_t i = 0; i < figures; ++i) r.figures.push_back(parse_cell(cells[k++]));
    r.wall_s = parse_cell(cells[k++]);
    return r;
}

SweepDirectory::SweepDirectory(std::string directory, const SweepSpec& spec, const std::vector<SweepPoint>& points,
                               bool restart, bool keep_series)
    : directory_(std::move(directory)), spec_(spec), points_(points), keep_series_(keep_series) {
    finished_.assign(points.size(), false);
    results_.resize(points.size());
    const fs::path dir(directory_);
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir))
        throw InputError("--out-dir", "cannot create the directory '" + directory_ + "'" + (ec ? ": " + ec.message() : ""));
    const nlohmann::json now = spec_json(spec);
    const fs::path spec_file = dir / "spec.json";
    const fs::path journal = dir / kJournal;
    if (restart) {
        for (const char* f : {"spec.json", kJournal, "points.csv", "sweep.json"}) fs::remove(dir / f, ec);
        for (const char* d : {"scenarios", "loops", "series", "figures"}) fs::remove_all(dir / d, ec);
    } else if (fs::exists(spec_file)) {
        nlohmann::json old_spec;
        try {
            old_spec = nlohmann::json::parse(read_text(spec_file.string()));
        } catch (const std::exception&) {
            throw InputError("--out-dir", "'" + spec_file.string() + "' is not readable JSON: use --restart to start over");
        }
        const std::string diff = spec_difference(old_spec, now);
        if (!diff.empty())
            throw InputError("--out-dir", "'" + directory_ + "' holds the results of another sweep: " + diff +
                                              "; use another directory, or --restart to discard them");
    } else if (fs::exists(journal) || fs::exists(dir / "points.csv")) {
        throw InputError("--out-dir", "'" + directory_ + "' holds sweep results without spec.json: use another "
                                      "directory, or --restart to discard them");
    }
    const std::string header = point_table_header(spec);
    if (fs::exists(journal)) {
        // the finished points: every whole row (a line cut by a crash is dropped, its point runs again)
        std::string text = read_text(journal.string());
        std::size_t start = 0, kept = 0;
        bool first = true;
        while (start < text.size()) {
            const std::size_t end = text.find('\n', start);
            if (end == std::string::npos) break;  // no newline: cut
            const std::string line = text.substr(start, end - start);
            if (first) {
                if (line != header)
                    throw InputError("--out-dir", "'" + journal.string() + "' has other columns than this program "
                                                  "writes (another version?): use --restart to start over");
                first = false;
            } else {
                PointResult r;
                try {
                    r = parse_point_row(spec, line);
                } catch (const std::invalid_argument&) {
                    break;  // a damaged row: the rest runs again
                }
                if (r.index < 0 || r.index >= static_cast<int>(points.size())) break;
                finished_[static_cast<std::size_t>(r.index)] = true;
                results_[static_cast<std::size_t>(r.index)] = r;
            }
            start = end + 1;
            kept = start;
        }
        if (kept < text.size()) {  // drop the damaged tail so that new rows follow whole ones
            fs::resize_file(journal, kept, ec);
            if (ec) throw std::runtime_error("cannot truncate '" + journal.string() + "': " + ec.message());
        }
        if (first) append(header);
    } else {
        write_whole(spec_file.string(), now.dump(2) + "\n");
        append(header);
    }
    if (!fs::exists(spec_file)) write_whole(spec_file.string(), now.dump(2) + "\n");
    fs::create_directories(dir / "scenarios", ec);
    fs::create_directories(dir / "loops", ec);
    if (keep_series_) fs::create_directories(dir / "series", ec);
    for (const SweepPoint& p : points) {
        const std::string file = point_file(directory_, "scenarios", p.index, "toml");
        if (!fs::exists(file))
            write_whole(file, "# point " + std::to_string(p.index) + " of the sweep " + spec.source +
                                  " (stackbeam simulate --scenario FILE --out OUT.csv runs it)\n" + p.scenario_text);
    }
}

int SweepDirectory::finished_count() const {
    int n = 0;
    for (bool f : finished_) n += f ? 1 : 0;
    return n;
}

void SweepDirectory::append(const std::string& row) {
    const std::string path = (fs::path(directory_) / kJournal).string();
    const int fd = ::open(path.c_str(), O_WRONLY | O_APPEND | O_CREAT, 0644);
    if (fd < 0) throw std::runtime_error("cannot open '" + path + "': " + std::strerror(errno));
    const std::string line = row + "\n";
    std::size_t written = 0;
    while (written < line.size()) {
        const ssize_t n = ::write(fd, line.data() + written, line.size() - written);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            ::close(fd);
            throw std::runtime_error("writing '" + path + "' failed: " + std::strerror(errno));
        }
        written += static_cast<std::size_t>(n);
    }
    const bool synced = ::fsync(fd) == 0;
    ::close(fd);
    if (!synced) throw std::runtime_error("fsync of '" + path + "' failed: " + std::strerror(errno));
}

void write_point_files(const std::string& directory, const SweepPoint& point, const PointResult& r, bool keep_series) {
    if (r.records && r.status == PointStatus::ok) {
        const auto& records = *r.records;
        const double period = point.scenario.simulation.loading.period_s();
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
                const auto& columns = point_figure_columns();
                auto figure = [&](const char* name) {
                    const auto i = std::find(columns.begin(), columns.end(), name) - columns.begin();
                    return static_cast<std::size_t>(i) < r.figures.size() ? r.figures[static_cast<std::size_t>(i)]
                                                                           : std::nan("");
                };
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
        if (keep_series) {
            std::ostringstream series;
            write_csv_header(series);
            for (const StepRecord& s : records) write_csv_row(series, s);
            write_whole(point_file(directory, "series", r.index, "csv"), series.str());
        }
    }
}

void SweepDirectory::record(const PointResult& r) {
    const SweepPoint& point = points_.at(static_cast<std::size_t>(r.index));
    write_point_files(directory_, point, r, keep_series_);
    append(format_point_row(point, r));  // last: a point is finished once its row is on disk
    finished_[static_cast<std::size_t>(r.index)] = true;
    results_[static_cast<std::size_t>(r.index)] = r;
    results_[static_cast<std::size_t>(r.index)].records = nullptr;
}

void SweepDirectory::record_row(const std::string& row) {
    const PointResult r = parse_point_row(spec_, row);
    if (r.index < 0 || r.index >= static_cast<int>(points_.size()))
        throw std::invalid_argument("row of point " + std::to_string(r.index) + ": no such point");
    append(row);
    finished_[static_cast<std::size_t>(r.index)] = true;
    results_[static_cast<std::size_t>(r.index)] = r;
}

void SweepDirectory::finish(const SweepTotals& totals) {
    std::string table = point_table_header(spec_) + "\n";
    int ok = 0, failed = 0, input = 0, missing = 0;
    double point_wall = 0.0;
    for (std::size_t i = 0; i < points_.size(); ++i) {
        if (!finished_[i]) {
            ++missing;
            continue;
        }
        const PointResult& r = results_[i];
        table += format_point_row(points_[i], r) + "\n";
        point_wall += r.wall_s;
        (r.status == PointStatus::ok ? ok : r.status == PointStatus::failed ? failed : input) += 1;
    }
    write_whole((fs::path(directory_) / "points.csv").string(), table);
    nlohmann::json j;
    j["program"] = {{"name", "stackbeam"}, {"version", STACKBEAM_VERSION}};
    j["spec"] = spec_json(spec_);
    j["spec"]["source"] = spec_.source;
    j["spec"]["description"] = spec_.description;
    j["counts"] = {{"points", points_.size()}, {"ok", ok}, {"failed", failed}, {"input_error", input}, {"not_run", missing}};
    j["complete"] = missing == 0;
    j["wall_time_s"] = totals.wall_s;
    j["points_wall_time_s"] = point_wall;
    j["jobs"] = totals.jobs;
    j["processes"] = totals.processes;
    j["columns"] = split_row(point_table_header(spec_));
    write_whole((fs::path(directory_) / "sweep.json").string(), j.dump(2) + "\n");
}

}  // namespace stackbeam
