// Calibration spec (docs/calibration.md): the TOML file, the measured loops' CSV files, the
// check of the bounds against the scenario (each bound made into a scenario by the sweep's
// key-path editing, SweepPoints).
#include "stackbeam/study/fit.hpp"
#include "fit_trial.hpp"
#include "spec_toml.hpp"

#include <toml.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

namespace stackbeam {

namespace {

using detail::line_of;

double number_of(const toml::value& v, const std::string& field, const std::string& where) {
    if (v.is_floating()) return v.as_floating();
    if (v.is_integer()) return static_cast<double>(v.as_integer());
    throw InputError(field, "value " + toml::format(v) + " is not a number", where);
}

std::string string_of(const toml::value& v, const std::string& field, const std::string& where) {
    if (!v.is_string() || v.as_string().str.empty()) throw InputError(field, "must be a non-empty string", where);
    return v.as_string().str;
}

void only_keys(const toml::value& table, const std::vector<std::string>& allowed, const std::string& prefix,
               const std::string& source) {
    for (const auto& kv : table.as_table())
        if (std::find(allowed.begin(), allowed.end(), kv.first) == allowed.end()) {
            std::string list;
            for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
            throw InputError(prefix + kv.first, "unknown key: allowed here: " + list, line_of(source, kv.second));
        }
}

std::vector<std::string> split_csv_line(const std::string& line) {
    std::vector<std::string> cells;
    std::string cell;
    std::istringstream in(line);
    while (std::getline(in, cell, ',')) {
        const auto b = cell.find_first_not_of(" \t\r\"");
        const auto e = cell.find_last_not_of(" \t\r\"");
        cells.push_back(b == std::string::npos ? std::string() : cell.substr(b, e - b + 1));
    }
    if (!line.empty() && line.back() == ',') cells.emplace_back();
    return cells;
}

}  // namespace

SweepSpec detail::trial_sweep(const FitSpec& spec, const std::vector<std::vector<double>>& values, const MeasuredLoop* loop) {
    SweepSpec s;
    s.source = spec.source;
    s.scenario_path = spec.scenario_path;
    s.scenario_text = spec.scenario_text;
    s.scenario_location = spec.scenario_location;
    s.combine = Combine::zip;
    for (std::size_t j = 0; j < spec.parameters.size(); ++j) {
        SweepAxis axis{spec.parameters[j].key, {}, spec.parameters[j].location};
        for (const auto& v : values) axis.values.emplace_back(v.at(j));
        s.axes.push_back(std::move(axis));
    }
    if (loop)
        for (const auto& [key, value] : loop->settings)
            s.axes.push_back({key, std::vector<AxisValue>(values.size(), value), loop->location});
    return s;
}

void read_loop_csv(const std::string& text, MeasuredLoop& loop, double closure_tolerance, const std::string& field) {
    std::istringstream in(text);
    std::string line;
    int line_no = 0;
    std::vector<std::string> header;
    while (header.empty() && std::getline(in, line)) {
        ++line_no;
        if (line.find_first_not_of(" \t\r") == std::string::npos || line[line.find_first_not_of(" \t")] == '#') continue;
        header = split_csv_line(line);
    }
    const std::string file = loop.csv_path.empty() ? field : loop.csv_path;
    if (header.empty()) throw InputError(field + ".csv", "file '" + file + "' has no header line (column names)", loop.location);
    auto column = [&](const std::string& name, const std::string& key) {
        const auto it = std::find(header.begin(), header.end(), name);
        if (it == header.end()) {
            std::string list;
            for (const auto& h : header) list += (list.empty() ? "" : ", ") + h;
            throw InputError(field + "." + key, "value '" + name + "' is not a column of '" + file + "' (its columns: " +
                                                    list + ")",
                             loop.location);
        }
        return static_cast<std::size_t>(it - header.begin());
    };
    const std::size_t cw = column(loop.displacement_column, "displacement_column");
    const std::size_t cf = column(loop.force_column, "force_column");
    loop.w_m.clear();
    loop.force_n.clear();
    while (std::getline(in, line)) {
        ++line_no;
        if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
        const auto cells = split_csv_line(line);
        auto cell = [&](std::size_t c, const std::string& name) {
            const std::string where = file + ":" + std::to_string(line_no);
            if (c >= cells.size())
                throw InputError(field + ".csv", where + ": column '" + name + "' is missing (" +
                                                     std::to_string(cells.size()) + " cells on the line)",
                                 loop.location);
            const std::string& t = cells[c];
            char* end = nullptr;
            const double x = std::strtod(t.c_str(), &end);
            if (t.empty() || end != t.c_str() + t.size() || !std::isfinite(x))
                throw InputError(field + ".csv", where + ": column '" + name + "' value '" + t +
                                                     "' is not a finite number",
                                 loop.location);
            return x;
        };
        loop.w_m.push_back(cell(cw, loop.displacement_column));
        loop.force_n.push_back(cell(cf, loop.force_column));
    }
    const std::size_t n = loop.w_m.size();
    if (n < 8)
        throw InputError(field + ".csv", "file '" + file + "' has " + std::to_string(n) +
                                             " data rows: a loop needs at least 8 samples (one closed cycle)",
                         loop.location);
    const auto [wmin, wmax] = std::minmax_element(loop.w_m.begin(), loop.w_m.end());
    const auto [fmin, fmax] = std::minmax_element(loop.force_n.begin(), loop.force_n.end());
    const double stroke = *wmax - *wmin, range = *fmax - *fmin;
    if (!(stroke > 0.0))
        throw InputError(field + "." + loop.displacement_column, "the displacement of '" + file + "' does not move: no loop",
                         loop.location);
    const double dw = std::abs(loop.w_m.back() - loop.w_m.front()), df = std::abs(loop.force_n.back() - loop.force_n.front());
    if (dw > closure_tolerance * stroke || df > closure_tolerance * std::max(range, 1e-300))
        throw InputError(field + ".csv",
                         "the loop in '" + file + "' does not close: from its first sample to its last w moves " +
                             format_value(dw) + " m (stroke " + format_value(stroke) + " m) and F " + format_value(df) +
                             " N (range " + format_value(range) + " N); allowed: closure_tolerance = " +
                             format_value(closure_tolerance) + " of each. Give one whole cycle.",
                         loop.location);
}

namespace {

/// The top-level settings: description, the base scenario (read), starts, max_iterations,
/// difference_step, closure_tolerance.
void read_fit_settings(const toml::table& top, const std::string& source_name, FitSpec& spec) {
    if (top.count("description")) spec.description = string_of(top.at("description"), "description", line_of(source_name, top.at("description")));
    if (!top.count("scenario"))
        throw InputError("scenario", "is required: the base scenario file (relative to the spec file)", source_name);
    spec.scenario_location = line_of(source_name, top.at("scenario"));
    const std::string name = string_of(top.at("scenario"), "scenario", spec.scenario_location);
    spec.scenario_path = detail::beside_spec(name, source_name);
    spec.scenario_text = detail::read_input_file(spec.scenario_path, "the base scenario file", "scenario", spec.scenario_location);
    auto integer = [&](const char* key, int lo, int hi, int& out) {
        if (!top.count(key)) return;
        const auto& v = top.at(key);
        if (!v.is_integer() || v.as_integer() < lo || v.as_integer() > hi)
            throw InputError(key, "value " + toml::format(v) + " is not allowed: an integer from " + std::to_string(lo) +
                                      " to " + std::to_string(hi),
                             line_of(source_name, v));
        out = static_cast<int>(v.as_integer());
    };
    integer("starts", 1, 100, spec.starts);
    integer("max_iterations", 1, 1000, spec.max_iterations);
    auto fraction = [&](const char* key, double lo, double hi, double& out) {
        if (!top.count(key)) return;
        const auto& v = top.at(key);
        const double x = number_of(v, key, line_of(source_name, v));
        if (!(x > lo && x <= hi))
            throw InputError(key, "value " + format_value(x) + " is not allowed: must be > " + format_value(lo) +
                                      " and <= " + format_value(hi),
                             line_of(source_name, v));
        out = x;
    };
    fraction("difference_step", 0.0, 0.1, spec.difference_step);
    fraction("closure_tolerance", 0.0, 1.0, spec.closure_tolerance);
}

/// One [[parameters]] table (`base` = "parameters[j]"): key, lower, upper, start; a key fitted
/// twice is refused.
FitParameter read_fit_parameter(const toml::value& t, const std::string& base, const std::string& source_name,
                                const std::vector<FitParameter>& earlier) {
    const std::string where = line_of(source_name, t);
    only_keys(t, {"key", "lower", "upper", "start"}, base + ".", source_name);
    const auto& tab = t.as_table();
    FitParameter p;
    for (const char* k : {"key", "lower", "upper"})
        if (!tab.count(k)) throw InputError(base + "." + k, "is required (key, lower, upper; start optional)", where);
    p.key = string_of(tab.at("key"), base + ".key", line_of(source_name, tab.at("key")));
    p.location = line_of(source_name, tab.at("key"));
    for (const auto& other : earlier)
        if (other.key == p.key)
            throw InputError(base + ".key", "value '" + p.key + "' is a parameter already (" + other.location + ")",
                             p.location);
    p.lower = number_of(tab.at("lower"), base + ".lower", line_of(source_name, tab.at("lower")));
    p.upper = number_of(tab.at("upper"), base + ".upper", line_of(source_name, tab.at("upper")));
    if (!std::isfinite(p.lower) || !std::isfinite(p.upper) || !(p.upper > p.lower))
        throw InputError(base + ".upper", "bounds [" + format_value(p.lower) + ", " + format_value(p.upper) +
                                              "] are not allowed: finite, with upper > lower",
                         line_of(source_name, tab.at("upper")));
    if (tab.count("start")) {
        p.start = number_of(tab.at("start"), base + ".start", line_of(source_name, tab.at("start")));
        if (!(p.start >= p.lower && p.start <= p.upper))
            throw InputError(base + ".start", "value " + format_value(p.start) + " is not allowed: must lie in [" +
                                                  format_value(p.lower) + ", " + format_value(p.upper) + "]",
                             line_of(source_name, tab.at("start")));
    }
    return p;
}

/// A loop's `set` table: the scenario values its run holds fixed (none a fitted parameter).
void read_loop_settings(const toml::value& s, const std::string& base, const std::string& source_name,
                        const std::vector<FitParameter>& parameters, MeasuredLoop& loop) {
    if (!s.is_table()) throw InputError(base + ".set", "must be a table of scenario keys and values", line_of(source_name, s));
    for (const auto& kv : s.as_table()) {
        const std::string f = base + ".set." + kv.first, w = line_of(source_name, kv.second);
        AxisValue v;
        if (kv.second.is_floating()) v = kv.second.as_floating();
        else if (kv.second.is_integer()) v = static_cast<long long>(kv.second.as_integer());
        else if (kv.second.is_boolean()) v = kv.second.as_boolean();
        else if (kv.second.is_string()) v = kv.second.as_string().str;
        else throw InputError(f, "is not a number, boolean or string (one scenario value)", w);
        for (const auto& p : parameters)
            if (p.key == kv.first)
                throw InputError(f, "is a fitted parameter (" + p.location + "): a loop cannot set it", w);
        loop.settings.emplace_back(kv.first, v);
    }
}

/// One [[loops]] table (`base` = "loops[l]"): its keys, then its CSV file read and checked.
MeasuredLoop read_measured_loop(const toml::value& t, const std::string& base, const std::string& source_name,
                                const FitSpec& spec) {
    const std::string where = line_of(source_name, t);
    only_keys(t, {"name", "csv", "displacement_column", "force_column", "weight", "set"}, base + ".", source_name);
    const auto& tab = t.as_table();
    MeasuredLoop loop;
    loop.name = base;
    loop.location = where;
    for (const char* k : {"csv", "displacement_column", "force_column"})
        if (!tab.count(k)) throw InputError(base + "." + k, "is required (csv, displacement_column, force_column)", where);
    if (tab.count("name")) loop.name = string_of(tab.at("name"), base + ".name", line_of(source_name, tab.at("name")));
    const std::string csv = string_of(tab.at("csv"), base + ".csv", line_of(source_name, tab.at("csv")));
    loop.csv_path = detail::beside_spec(csv, source_name);
    loop.displacement_column = string_of(tab.at("displacement_column"), base + ".displacement_column", where);
    loop.force_column = string_of(tab.at("force_column"), base + ".force_column", where);
    if (tab.count("weight")) {
        loop.weight = number_of(tab.at("weight"), base + ".weight", line_of(source_name, tab.at("weight")));
        if (!(loop.weight > 0.0 && std::isfinite(loop.weight)))
            throw InputError(base + ".weight", "value " + format_value(loop.weight) + " is not allowed: must be > 0",
                             line_of(source_name, tab.at("weight")));
    }
    if (tab.count("set")) read_loop_settings(tab.at("set"), base, source_name, spec.parameters, loop);
    const std::string csv_text = detail::read_input_file(loop.csv_path, "the measured loop's CSV file", base + ".csv",
                                                         line_of(source_name, tab.at("csv")));
    read_loop_csv(csv_text, loop, spec.closure_tolerance, base);
    return loop;
}

/// The [objective] table: the weights of the figures; not all of them 0.
void read_objective(const toml::value& o, const std::string& source_name, FitWeights& weights) {
    if (!o.is_table()) throw InputError("objective", "must be a table of weights", line_of(source_name, o));
    only_keys(o, {"force", "loop_area", "secant_stiffness", "dynamic_rate"}, "objective.", source_name);
    auto weight = [&](const char* key, double& out) {
        if (!o.as_table().count(key)) return;
        const auto& v = o.as_table().at(key);
        out = number_of(v, std::string("objective.") + key, line_of(source_name, v));
        if (!(out >= 0.0 && std::isfinite(out)))
            throw InputError(std::string("objective.") + key, "value " + format_value(out) + " is not allowed: a weight >= 0",
                             line_of(source_name, v));
    };
    weight("force", weights.force);
    weight("loop_area", weights.loop_area);
    weight("secant_stiffness", weights.secant_stiffness);
    weight("dynamic_rate", weights.dynamic_rate);
    if (weights.force + weights.loop_area + weights.secant_stiffness + weights.dynamic_rate <= 0.0)
        throw InputError("objective", "every weight is 0: nothing to fit", line_of(source_name, o));
}

/// Every bound must make a scenario the reader accepts (the other parameters at their starts),
/// with each loop's settings.
void check_bounds(const FitSpec& spec) {
    for (std::size_t j = 0; j < spec.parameters.size(); ++j) {
        std::vector<double> values;
        for (const auto& p : spec.parameters) values.push_back(std::isnan(p.start) ? 0.5 * (p.lower + p.upper) : p.start);
        for (const double bound : {spec.parameters[j].lower, spec.parameters[j].upper}) {
            values[j] = bound;
            try {
                for (const auto& loop : spec.loops) {
                    const SweepSpec sweep = detail::trial_sweep(spec, {values}, &loop);  // SweepPoints keeps a reference
                    SweepPoints(sweep).point(0);
                }
            } catch (const InputError& e) {
                throw InputError("parameters[" + std::to_string(j) + "]",
                                 "the scenario refuses the bound " + format_value(bound) + " of " + spec.parameters[j].key +
                                     ": " + e.what(),
                                 spec.parameters[j].location);
            }
        }
    }
}

}  // namespace

FitSpec parse_fit_spec(const std::string& text, const std::string& source_name) {
    FitSpec spec;
    spec.source = source_name;
    const toml::value root = detail::parse_spec_toml(text, source_name);
    only_keys(root, {"scenario", "description", "starts", "max_iterations", "difference_step", "closure_tolerance",
                     "parameters", "loops", "objective", "outputs"},
              "", source_name);
    const auto& top = root.as_table();
    read_fit_settings(top, source_name, spec);
    const auto& params = detail::required_tables(top, "parameters", "key, lower, upper", source_name);
    for (std::size_t j = 0; j < params.size(); ++j)
        spec.parameters.push_back(read_fit_parameter(detail::table_element(params, j, "parameters", source_name),
                                                     "parameters[" + std::to_string(j) + "]", source_name,
                                                     spec.parameters));
    const auto& loops = detail::required_tables(top, "loops", "csv, displacement_column, force_column", source_name);
    for (std::size_t l = 0; l < loops.size(); ++l)
        spec.loops.push_back(read_measured_loop(detail::table_element(loops, l, "loops", source_name),
                                                "loops[" + std::to_string(l) + "]", source_name, spec));
    if (top.count("objective")) read_objective(top.at("objective"), source_name, spec.weights);
    if (top.count("outputs")) {
        const auto& o = top.at("outputs");
        if (!o.is_table()) throw InputError("outputs", "must be a table", line_of(source_name, o));
        only_keys(o, {"directory"}, "outputs.", source_name);
        if (o.as_table().count("directory"))
            spec.output_directory = string_of(o.as_table().at("directory"), "outputs.directory", line_of(source_name, o));
    }
    check_bounds(spec);
    return spec;
}

FitSpec load_fit_spec(const std::string& path) {
    return parse_fit_spec(detail::read_input_file(path, "the fit spec file", "spec", path), path);
}

}  // namespace stackbeam
