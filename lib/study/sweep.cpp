// Sweeps: the spec file, the points (the base scenario's TOML document edited at the
// axes' key paths, then read by parse_scenario), one point's run, the thread scheduler.
#include "stackbeam/study/sweep.hpp"
#include "spec_toml.hpp"

#include <toml.hpp>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>
#include <optional>
#include <system_error>
#include <thread>

#include "stackbeam/fe/system.hpp"
#include "stackbeam/model/model.hpp"
#include "stackbeam/run/run.hpp"

namespace stackbeam {

namespace {

using Document = toml::basic_value<toml::discard_comments, std::map, std::vector>;

using detail::line_of;

/// One part of a key path: a table key, optionally followed by [i] or [*].
struct PathPart {
    std::string name;
    enum class Index { none, one, all } index = Index::none;
    std::size_t element = 0;
};

/// Splits "a.b[2].c" / "interfaces[*].mu" into parts; throws naming the spec line on bad syntax.
std::vector<PathPart> split_key(const std::string& key, const std::string& location, const std::string& field) {
    auto bad = [&](const std::string& why) {
        throw InputError(field, "value '" + key + "' is not a key path: " + why +
                                    " (table keys joined by '.', an array element as [i] or every element as [*], "
                                    "e.g. interfaces[*].friction_coefficient)",
                         location);
    };
    if (key.empty()) bad("it is empty");
    std::vector<PathPart> parts;
    std::size_t i = 0;
    while (i <= key.size()) {
        PathPart p;
        while (i < key.size() && key[i] != '.' && key[i] != '[') {
            const char c = key[i];
            if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) bad(std::string("character '") + c + "'");
            p.name += c;
            ++i;
        }
        if (p.name.empty()) bad("an empty key part");
        if (i < key.size() && key[i] == '[') {
            const std::size_t close = key.find(']', i);
            if (close == std::string::npos) bad("'[' without ']'");
            const std::string inside = key.substr(i + 1, close - i - 1);
            if (inside == "*") {
                p.index = PathPart::Index::all;
            } else {
                if (inside.empty() || inside.find_first_not_of("0123456789") != std::string::npos)
                    bad("index '[" + inside + "]' is neither a number nor *");
                p.index = PathPart::Index::one;
                // no array in a scenario has a million elements: a longer index is refused by name
                // here, before std::stoul would throw its bare "stoul" on 20 digits
                if (inside.size() > 6) bad("index '[" + inside + "]' is too large (at most 999999)");
                p.element = static_cast<std::size_t>(std::stoul(inside));
            }
            i = close + 1;
        }
        parts.push_back(p);
        if (i == key.size()) break;
        if (key[i] != '.') bad("expected '.' after ']'");
        ++i;
    }
    return parts;
}

Document to_document(const AxisValue& v) {
    if (const auto* d = std::get_if<double>(&v)) return Document(*d);
    if (const auto* n = std::get_if<long long>(&v)) return Document(static_cast<toml::integer>(*n));
    if (const auto* b = std::get_if<bool>(&v)) return Document(*b);
    return Document(std::get<std::string>(v));
}

/// Sets `value` at `parts[k...]` under `node` (a table); creates missing tables and keys
/// (an unknown key is then refused by the scenario reader, naming it). Throws
/// std::invalid_argument with the reason when the path does not fit the document.
void set_at(Document& node, const std::vector<PathPart>& parts, std::size_t k, const Document& value,
            const std::string& done) {
    if (!node.is_table())
        throw std::invalid_argument("'" + done + "' is not a table in the base scenario");
    const PathPart& p = parts[k];
    const std::string here = done.empty() ? p.name : done + "." + p.name;
    auto& table = node.as_table();
    const bool last = k + 1 == parts.size();
    if (p.index == PathPart::Index::none) {
        if (last) {
            table[p.name] = value;
        } else {
            if (table.count(p.name) == 0) table[p.name] = Document(typename Document::table_type{});
            set_at(table[p.name], parts, k + 1, value, here);
        }
        return;
    }
    if (table.count(p.name) == 0 || !table[p.name].is_array())
        throw std::invalid_argument("'" + here + "' is not an array in the base scenario");
    auto& array = table[p.name].as_array();
    auto apply = [&](std::size_t i) {
        if (last) array[i] = value;
        else set_at(array[i], parts, k + 1, value, here + "[" + std::to_string(i) + "]");
    };
    if (p.index == PathPart::Index::all) {
        for (std::size_t i = 0; i < array.size(); ++i) apply(i);
    } else {
        if (p.element >= array.size())
            throw std::invalid_argument("'" + here + "' has " + std::to_string(array.size()) + " element(s) in the base "
                                        "scenario: index " + std::to_string(p.element) + " is out of range");
        apply(p.element);
    }
}

/// Does the scenario key path `field` (concrete indices) lie at or under `key` ([*] matches any index)?
bool key_covers(const std::string& key, const std::string& field) {
    std::size_t i = 0, j = 0;
    while (i < key.size()) {
        if (key.compare(i, 3, "[*]") == 0) {
            if (j >= field.size() || field[j] != '[') return false;
            const std::size_t close = field.find(']', j);
            if (close == std::string::npos) return false;
            i += 3;
            j = close + 1;
            continue;
        }
        if (j >= field.size() || key[i] != field[j]) return false;
        ++i;
        ++j;
    }
    return j == field.size() || field[j] == '.' || field[j] == '[';
}

std::string read_file(const std::string& path, const std::string& field, const std::string& location,
                      const std::string& what) {
    return detail::read_input_file(path, what, field, location);
}

/// Reads one scalar of an axis' values array.
AxisValue axis_value(const toml::value& v, const std::string& field, const std::string& where) {
    switch (v.type()) {
        case toml::value_t::floating: return v.as_floating();
        case toml::value_t::integer: return static_cast<long long>(v.as_integer());
        case toml::value_t::boolean: return v.as_boolean();
        case toml::value_t::string: return v.as_string().str;
        default:
            throw InputError(field, "is not a number, boolean or string: each value of an axis is one scenario value",
                             where);
    }
}

double number_of(const toml::value& v, const std::string& field, const std::string& where) {
    if (v.is_floating()) return v.as_floating();
    if (v.is_integer()) return static_cast<double>(v.as_integer());
    throw InputError(field, "is not a number", where);
}

std::string point_values_text(const SweepSpec& spec, const std::vector<AxisValue>& values) {
    std::string out;
    for (std::size_t a = 0; a < spec.axes.size(); ++a)
        out += (a ? ", " : "") + spec.axes[a].key + " = " + to_string(values[a]);
    return out;
}

/// The message of `e` without its location prefix.
std::string bare_message(const InputError& e) {
    std::string m = e.what();
    if (!e.location().empty() && m.rfind(e.location() + ": ", 0) == 0) m.erase(0, e.location().size() + 2);
    if (m.rfind(e.field() + ": ", 0) == 0) m.erase(0, e.field().size() + 2);
    return m;
}

}  // namespace

std::string round_trip_text(double x) {
    char buffer[40];
    for (int digits = 15; digits <= 17; ++digits) {  // the shortest of %.15g, %.16g, %.17g that reads back as x
        std::snprintf(buffer, sizeof buffer, "%.*g", digits, x);
        if (std::strtod(buffer, nullptr) == x) break;
    }
    return buffer;
}

std::string to_string(const AxisValue& value) {
    if (const auto* d = std::get_if<double>(&value)) return round_trip_text(*d);
    if (const auto* n = std::get_if<long long>(&value)) return std::to_string(*n);
    if (const auto* b = std::get_if<bool>(&value)) return *b ? "true" : "false";
    return std::get<std::string>(value);
}

STACKBEAM_ENUM_WORDS(Combine, {Combine::product, "product"}, {Combine::zip, "zip"})

const char* to_string(Combine combine) { return word_of(combine); }

STACKBEAM_ENUM_WORDS(PointStatus, {PointStatus::ok, "ok"}, {PointStatus::failed, "failed"},
    {PointStatus::input_error, "input-error"})

const char* to_string(PointStatus status) { return word_of(status); }

SweepSpec parse_sweep_spec(const std::string& text, const std::string& source_name) {
    return parse_sweep_spec(text, source_name, [&](const std::string& path, const std::string& location) {
        // the spec named as its own base scenario would be read as a scenario with unknown keys
        std::error_code ec;
        if (std::filesystem::equivalent(path, source_name, ec))
            throw InputError("scenario", "value '" + path + "' is the sweep spec itself: the base scenario is another "
                                         "file (a scenario, docs/model-and-scenarios.md)",
                             location);
        return read_file(path, "scenario", location, "the base scenario file");
    });
}

namespace {

/// The base scenario (`scenario`, read by `read_scenario`), `description` and `combine`.
void read_sweep_settings(const toml::table& top, const std::string& source_name, const ScenarioReader& read_scenario,
                         SweepSpec& spec) {
    if (top.count("description")) {
        const auto& d = top.at("description");
        if (!d.is_string()) throw InputError("description", "must be a string", line_of(source_name, d));
        spec.description = d.as_string().str;
    }
    if (!top.count("scenario"))
        throw InputError("scenario", "is required: the base scenario file (relative to the spec file)", source_name);
    const auto& sc = top.at("scenario");
    spec.scenario_location = line_of(source_name, sc);
    if (!sc.is_string() || sc.as_string().str.empty())
        throw InputError("scenario", "must be a file name (a string): the base scenario, relative to the spec file",
                         spec.scenario_location);
    spec.scenario_path = detail::beside_spec(sc.as_string().str, source_name);
    spec.scenario_text = read_scenario(spec.scenario_path, spec.scenario_location);
    if (top.count("combine")) {
        const auto& c = top.at("combine");
        const std::string word = c.is_string() ? c.as_string().str : "";
        if (const auto combine = find_word<Combine>(word)) spec.combine = *combine;
        else
            throw InputError("combine", "value '" + (c.is_string() ? word : toml::format(c)) +
                                            "' is not allowed: must be 'product' (every combination) or 'zip' (the "
                                            "i-th values together)",
                             line_of(source_name, c));
    }
}

/// The [outputs] table: directory and stresses.
void read_sweep_outputs(const toml::value& o, const std::string& source_name, SweepSpec& spec) {
    if (!o.is_table()) throw InputError("outputs", "must be a table", line_of(source_name, o));
    for (const auto& kv : o.as_table()) {
        if (kv.first == "stresses") {
            if (!kv.second.is_boolean())
                throw InputError("outputs.stresses", "value " + toml::format(kv.second) +
                                                         " is not allowed: must be true or false",
                                 line_of(source_name, kv.second));
            spec.stresses = kv.second.as_boolean();
            continue;
        }
        if (kv.first != "directory")
            throw InputError("outputs." + kv.first, "unknown key: [outputs] has directory and stresses",
                             line_of(source_name, kv.second));
        if (!kv.second.is_string() || kv.second.as_string().str.empty())
            throw InputError("outputs.directory", "must be a directory name (a string)", line_of(source_name, kv.second));
        spec.output_directory = kv.second.as_string().str;
    }
}

/// An axis' key (`base` = "axes[a]"): a key path, not under [outputs], not an axis already.
void read_axis_key(const toml::table& tab, const std::string& base, const std::string& where,
                   const std::string& source_name, const std::vector<SweepAxis>& earlier, SweepAxis& axis) {
    if (!tab.count("key") || !tab.at("key").is_string())
        throw InputError(base + ".key", "is required: the scenario key path (a string)", where);
    axis.key = tab.at("key").as_string().str;
    axis.location = line_of(source_name, tab.at("key"));
    split_key(axis.key, axis.location, base + ".key");
    if (axis.key.rfind("outputs", 0) == 0 && (axis.key.size() == 7 || axis.key[7] == '.'))
        throw InputError(base + ".key", "value '" + axis.key + "': [outputs] cannot be an axis (the sweep writes its own)",
                         axis.location);
    for (const auto& other : earlier)
        if (other.key == axis.key)
            throw InputError(base + ".key", "value '" + axis.key + "' is an axis already (" + other.location + ")",
                             axis.location);
}

/// An axis' values given as a list, `values = [...]`.
void read_listed_values(const toml::table& tab, const std::string& base, const std::string& source_name,
                        SweepAxis& axis) {
    const auto& v = tab.at("values");
    const std::string vw = line_of(source_name, v);
    if (!v.is_array()) throw InputError(base + ".values", "must be an array of values", vw);
    const auto& arr = v.as_array();
    if (arr.empty())
        throw InputError(base + ".values", "is empty: an axis needs at least one value (axis " + axis.key + ")", vw);
    for (std::size_t i = 0; i < arr.size(); ++i)
        axis.values.push_back(axis_value(arr[i], base + ".values[" + std::to_string(i) + "]", vw));
}

/// An axis' values given as a range, `from`, `to`, `count` and `spacing` (linear or log): the
/// ends exactly as written, integers when both ends are and the step is whole.
void read_ranged_values(const toml::table& tab, const std::string& base, const std::string& where,
                        const std::string& source_name, SweepAxis& axis) {
    for (const char* k : {"from", "to", "count"})
        if (!tab.count(k))
            throw InputError(base + "." + k, "is required with from/to/count (axis " + axis.key + ")", where);
    const double from = number_of(tab.at("from"), base + ".from", line_of(source_name, tab.at("from")));
    const double to = number_of(tab.at("to"), base + ".to", line_of(source_name, tab.at("to")));
    const auto& c = tab.at("count");
    const std::string cw = line_of(source_name, c);
    if (!c.is_integer() || c.as_integer() < 1 || c.as_integer() > 1000000)
        throw InputError(base + ".count",
                         "value " + toml::format(c) + " is not allowed: must be an integer from 1 to 1000000 "
                         "(axis " + axis.key + ")",
                         cw);
    const int count = static_cast<int>(c.as_integer());
    bool log = false;
    if (tab.count("spacing")) {
        const auto& s = tab.at("spacing");
        const std::string word = s.is_string() ? s.as_string().str : toml::format(s);
        if (word == "log") log = true;
        else if (word != "linear")
            throw InputError(base + ".spacing", "value '" + word + "' is not allowed: must be 'linear' or 'log'",
                             line_of(source_name, s));
    }
    if (!std::isfinite(from) || !std::isfinite(to))
        throw InputError(base + ".from", "from and to must be finite (axis " + axis.key + ")", where);
    if (log && !(from > 0.0 && to > 0.0))
        throw InputError(base + ".from", "spacing 'log' needs from > 0 and to > 0 (axis " + axis.key + ")", where);
    if (count == 1 && from != to)
        throw InputError(base + ".count", "value 1 needs from = to (one value)", cw);
    const bool integers = !log && tab.at("from").is_integer() && tab.at("to").is_integer() && count > 1 &&
                          (static_cast<long long>(to - from)) % (count - 1) == 0;
    for (int i = 0; i < count; ++i) {
        const double f = count == 1 ? 0.0 : static_cast<double>(i) / (count - 1);
        double x = log ? std::exp(std::log(from) + f * (std::log(to) - std::log(from))) : from + f * (to - from);
        if (i == 0) x = from;
        if (i == count - 1) x = to;  // the ends exactly as written
        if (integers) axis.values.push_back(static_cast<long long>(std::llround(x)));
        else axis.values.push_back(x);
    }
}

/// One [[axes]] table (`base` = "axes[a]"): its key, and its values listed or ranged.
SweepAxis read_axis(const toml::value& t, const std::string& base, const std::string& source_name,
                    const std::vector<SweepAxis>& earlier) {
    const std::string where = line_of(source_name, t);
    SweepAxis axis;
    const auto& tab = t.as_table();
    for (const auto& kv : tab)
        if (kv.first != "key" && kv.first != "values" && kv.first != "from" && kv.first != "to" &&
            kv.first != "count" && kv.first != "spacing")
            throw InputError(base + "." + kv.first, "unknown key: an axis has key, and values or from, to, count, spacing",
                             line_of(source_name, kv.second));
    read_axis_key(tab, base, where, source_name, earlier, axis);
    const bool listed = tab.count("values") > 0;
    const bool ranged = tab.count("from") || tab.count("to") || tab.count("count") || tab.count("spacing");
    if (listed == ranged)
        throw InputError(base, "give either values = [...] or from, to and count (and spacing), not " +
                                   std::string(listed ? "both" : "neither"),
                         where);
    if (listed) read_listed_values(tab, base, source_name, axis);
    else read_ranged_values(tab, base, where, source_name, axis);
    return axis;
}

}  // namespace

SweepSpec parse_sweep_spec(const std::string& text, const std::string& source_name, const ScenarioReader& read_scenario) {
    SweepSpec spec;
    spec.source = source_name;
    const toml::value root = detail::parse_spec_toml(text, source_name);
    const auto& top = root.as_table();
    for (const auto& kv : top)
        if (kv.first != "scenario" && kv.first != "description" && kv.first != "combine" && kv.first != "axes" &&
            kv.first != "outputs")
            throw InputError(kv.first, "unknown key: a sweep spec has scenario, description, combine, [[axes]], [outputs]",
                             line_of(source_name, kv.second));
    read_sweep_settings(top, source_name, read_scenario, spec);
    if (top.count("outputs")) read_sweep_outputs(top.at("outputs"), source_name, spec);
    const auto& axes = detail::required_tables(top, "axes", "key and values", source_name);
    std::size_t total_values = 0;
    for (std::size_t a = 0; a < axes.size(); ++a) {
        const std::string base = "axes[" + std::to_string(a) + "]";
        SweepAxis axis = read_axis(detail::table_element(axes, a, "axes", source_name), base, source_name, spec.axes);
        // the values themselves are held: many long axes (a zip of them) must not exhaust memory
        // before point_count's limit is checked
        total_values += axis.values.size();
        if (total_values > 10000000)
            throw InputError(base, "more than 10 million values over the axes (axis " + axis.key + ")",
                             line_of(source_name, axes[a]));
        spec.axes.push_back(std::move(axis));
    }
    point_count(spec);  // empty axis, unequal zip
    return spec;
}

SweepSpec load_sweep_spec(const std::string& path) {
    return parse_sweep_spec(read_file(path, "spec", path, "the sweep spec file"), path);
}

int point_count(const SweepSpec& spec) {
    if (spec.axes.empty()) throw InputError("axes", "at least one axis is required", spec.source);
    long long n = spec.combine == Combine::zip ? -1 : 1;
    double product = 1.0;  // the product's size for the message (exact below 2^53)
    for (std::size_t a = 0; a < spec.axes.size(); ++a) {
        const SweepAxis& axis = spec.axes[a];
        const std::string field = "axes[" + std::to_string(a) + "]";
        const std::string where = axis.location.empty() ? spec.source : axis.location;
        if (axis.values.empty())
            throw InputError(field + ".values", "is empty: an axis needs at least one value (axis " + axis.key + ")", where);
        const long long len = static_cast<long long>(axis.values.size());
        if (spec.combine == Combine::zip) {
            if (n >= 0 && len != n)
                throw InputError(field + ".values",
                                 "has " + std::to_string(len) + " values, axes[0] (" + spec.axes[0].key + ") has " +
                                     std::to_string(n) + ": combine = 'zip' needs axes of equal length",
                                 where);
            n = len;
        } else {
            product *= static_cast<double>(len);
            n *= len;
            if (n > max_sweep_points) n = max_sweep_points + 1;  // refused below; no overflow however many axes
        }
    }
    if (n > max_sweep_points) {
        std::string sizes;
        for (const SweepAxis& axis : spec.axes)
            sizes += (sizes.empty() ? "" : spec.combine == Combine::zip ? ", " : " x ") + std::to_string(axis.values.size());
        throw InputError("axes", "the spec has " +
                                     (spec.combine == Combine::zip ? std::to_string(n) : format_value(product)) +
                                     " points (" + to_string(spec.combine) + " of " + sizes +
                                     " values): at most " + std::to_string(max_sweep_points) +
                                     " points in one sweep; split it into several specs",
                         spec.source);
    }
    return static_cast<int>(n);
}

struct SweepPoints::Impl {
    Document base;                          // the base scenario without [outputs]
    std::vector<std::vector<PathPart>> paths;  // each axis' key, split
};

SweepPoints::SweepPoints(const SweepSpec& spec) : spec_(&spec), count_(point_count(spec)) {
    auto impl = std::make_shared<Impl>();
    try {
        detail::check_toml_text(spec.scenario_text, spec.scenario_path);
        std::istringstream in(spec.scenario_text);
        impl->base = toml::parse<toml::discard_comments, std::map>(in, spec.scenario_path);
    } catch (const std::exception& e) {
        throw InputError("scenario", "the base scenario '" + spec.scenario_path + "' is not a valid TOML file: " + e.what(),
                         spec.scenario_location.empty() ? spec.source : spec.scenario_location);
    }
    if (impl->base.is_table()) impl->base.as_table().erase("outputs");  // the sweep writes its own
    for (std::size_t a = 0; a < spec.axes.size(); ++a)
        impl->paths.push_back(split_key(spec.axes[a].key, spec.axes[a].location, "axes[" + std::to_string(a) + "].key"));
    impl_ = std::move(impl);
}

std::vector<AxisValue> SweepPoints::values(int i) const {
    const SweepSpec& spec = *spec_;
    if (i < 0 || i >= count_) throw std::out_of_range("sweep point " + std::to_string(i) + " of " + std::to_string(count_));
    std::vector<AxisValue> values(spec.axes.size());
    // product: the last axis varies fastest
    int rest = i;
    for (std::size_t a = spec.axes.size(); a-- > 0;) {
        const auto& vals = spec.axes[a].values;
        const int len = static_cast<int>(vals.size());
        values[a] = spec.combine == Combine::zip ? vals[static_cast<std::size_t>(i)] : vals[static_cast<std::size_t>(rest % len)];
        if (spec.combine == Combine::product) rest /= len;
    }
    return values;
}

SweepPoint SweepPoints::point(int i) const {
    const SweepSpec& spec = *spec_;
    SweepPoint point;
    point.index = i;
    point.stresses = spec.stresses;
    point.values = values(i);
    const std::string at_point = "at point " + std::to_string(i) + " (" + point_values_text(spec, point.values) + ")";
    Document doc = impl_->base;
    for (std::size_t a = 0; a < spec.axes.size(); ++a) {
        try {
            set_at(doc, impl_->paths[a], 0, to_document(point.values[a]), "");
        } catch (const std::invalid_argument& e) {
            throw InputError(spec.axes[a].key, at_point + ": " + e.what() + " (axis " + std::to_string(a) + ")",
                             spec.axes[a].location.empty() ? spec.source : spec.axes[a].location);
        }
    }
    point.scenario_text = toml::format(doc, 0, std::numeric_limits<double>::max_digits10);
    const std::string name = spec.scenario_path + " at point " + std::to_string(i);
    try {
        point.scenario = parse_scenario(point.scenario_text, name);
    } catch (const InputError& e) {
        for (std::size_t a = 0; a < spec.axes.size(); ++a)
            if (key_covers(spec.axes[a].key, e.field()))
                throw InputError(e.field(), at_point + ": " + bare_message(e) + " (axis " + spec.axes[a].key + ")",
                                 spec.axes[a].location.empty() ? spec.source : spec.axes[a].location);
        throw InputError(e.field(), at_point + ": " + bare_message(e) + " (a key of the base scenario " +
                                        spec.scenario_path + ", with the point's values)",
                         spec.scenario_location.empty() ? spec.source : spec.scenario_location);
    }
    return point;
}

void SweepPoints::check_all(const std::function<void(int checked)>& progress) const {
    for (int i = 0; i < count_; ++i) {
        point(i);  // built, checked and dropped: memory does not grow with the count
        if (progress) progress(i + 1);
    }
}

std::vector<SweepPoint> expand_points(const SweepSpec& spec) {
    const SweepPoints generator(spec);
    std::vector<SweepPoint> points;
    points.reserve(static_cast<std::size_t>(generator.size()));
    for (int i = 0; i < generator.size(); ++i) points.push_back(generator.point(i));
    return points;
}

const std::vector<std::string>& point_figure_columns() {
    static const std::vector<std::string> columns = {
        "loop_area_j",   "friction_work_j", "secant_stiffness_n_per_m", "dynamic_rate_n_per_m",
        "loss_factor",   "equivalent_damping_ratio", "force_min_n",     "force_max_n",
        "w_min_m",       "w_max_m",
        // Fancher's model fitted to the last loop (post/fancher.hpp), as simulate's summary "fancher"
        "fancher_upper_rate_n_per_m", "fancher_upper_offset_n", "fancher_lower_rate_n_per_m",
        "fancher_lower_offset_n", "fancher_beta_m", "fancher_rms_error_relative",
        "energy_balance_error_j",
        // the stresses ([outputs] stresses = true, RunOutputs::stresses): the largest |fibre stress| of
        // any leaf over the run [Pa] and the least fatigue safety factor over the leaves with a material
        "stress_max_abs_pa", "fatigue_least_safety_factor",
        // the windup figures (run/loop_figures.hpp, simulate's summary "windup"): k_theta, the windup
        // loop's area and loss factor, the seat's longitudinal compliance; NaN where the run has none
        "windup_stiffness_n_m_per_rad", "windup_loop_area_j", "windup_loss_factor",
        "longitudinal_compliance_m_per_n", "tangent_vertical_rate_n_per_m",
    };
    return columns;
}

namespace {

/// The point figures (point_figure_columns) of a run's loop figures and its largest |energy
/// balance error| [J] (NaN for a run without records), as simulate's summary
/// ("hysteresis", "fancher", "balance_error_max_abs").
std::vector<double> figures_of(const LoopFigures& loop, long records, double max_abs_balance_j, std::string& note) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    std::vector<double> f(point_figure_columns().size(), nan);
    note = loop.note;
    if (const auto& m = loop.metrics) {
        f[0] = m->loop_area_j;
        f[1] = m->dissipated_j;
        f[2] = m->secant_stiffness_n_per_m;
        f[3] = m->dynamic_rate_n_per_m;
        f[4] = m->loss_factor;
        f[5] = m->equivalent_damping_ratio;
        f[6] = m->force_min_n;
        f[7] = m->force_max_n;
        f[8] = m->w_min_m;
        f[9] = m->w_max_m;
    }
    if (const auto& fit = loop.fancher) {
        f[10] = fit->parameters.upper_rate_n_per_m;
        f[11] = fit->parameters.upper_offset_n;
        f[12] = fit->parameters.lower_rate_n_per_m;
        f[13] = fit->parameters.lower_offset_n;
        f[14] = fit->parameters.beta_m;
        f[15] = fit->rms_error_relative;
    } else if (!loop.fancher_note.empty()) {
        note = "no Fancher fit: " + loop.fancher_note;
    }
    f[16] = records > 0 ? max_abs_balance_j : nan;
    return f;
}

/// The windup columns (point_figure_columns 19 to 23) from a run's windup figures; NaN where none
/// (the tangent vertical rate: only from run_scenario, which keeps the last record's contact state).
void add_windup_figures(const std::optional<WindupFigures>& windup, std::vector<double>& f) {
    if (!windup) return;
    if (const auto& m = windup->windup) {
        f[19] = m->secant_stiffness_n_per_m;
        f[20] = m->loop_area_j;
        f[21] = m->loss_factor;
    }
    f[22] = windup->longitudinal_compliance_m_per_n;
    if (windup->tangent) f[23] = windup->tangent->vertical_rate_n_per_m;
}

/// The message of a run that loads the seat (decision 076): why each of its empty figures is empty,
/// the windup's first (the windup loop; the longitudinal compliance where a longitudinal force acts;
/// the tangent vertical rate), then the vertical loop's: none where the vertical loading is not
/// periodic (the seat held at a preload: w makes no loop), else `vertical_note` (figures_of's).
std::string windup_message(const WindupFigures& windup, const Loading& loading, const LoopFigures& loop,
                           const std::string& vertical_note) {
    std::string message;
    auto add = [&message](const std::string& part) { message += (message.empty() ? "" : "; ") + part; };
    if (!windup.windup) add("no windup loop: " + windup.windup_note);
    if (loading.longitudinal_force_n && !windup.longitudinal) add("no longitudinal compliance: " + windup.longitudinal_note);
    if (!windup.tangent) add("no tangent vertical rate: " + windup.tangent_note);
    if (!loop.metrics)
        add("no vertical loop: " +
            (vertical_period_s(loading) > 0.0 ? loop.note : std::string("the vertical loading is not periodic")));
    else if (!vertical_note.empty())
        add(vertical_note);  // the Fancher fit's
    return message;
}

/// The stress columns (point_figure_columns 17, 18) from a run's stress figures; NaN where none
/// (not asked, or no leaf with a material whose endurance limit gives a safety factor).
void add_stress_figures(const std::optional<RunStresses>& stresses, std::vector<double>& f) {
    if (!stresses) return;
    double largest = 0.0, least = std::numeric_limits<double>::quiet_NaN();
    for (const LeafExtremes& e : stresses->summary.extremes)
        largest = std::max({largest, std::abs(e.tension.stress_pa), std::abs(e.compression.stress_pa)});
    for (const LeafFatigueResult& r : stresses->summary.fatigue)
        if (r.has_material && r.fatigue.has_safety_factor && !(r.fatigue.least_safety_factor >= least))
            least = r.fatigue.least_safety_factor;
    f[17] = largest;
    f[18] = least;
}

}  // namespace

std::vector<double> point_figures(const std::vector<StepRecord>& records, const SimulationOptions& options,
                                  std::string& note) {
    // the loop figures of simulate's summary, from the same function (run/loop_figures.hpp)
    double balance = 0.0;
    for (const StepRecord& r : records) balance = std::max(balance, std::abs(r.energy_balance_error_j));
    const LoopFigures loop = loop_figures(records, options.loading.period_s());
    std::vector<double> f = figures_of(loop, static_cast<long>(records.size()), balance, note);
    if (loads_the_seat(options.loading)) {
        WindupFigures windup = windup_figures(records, options.loading, loop);
        windup.tangent_note = "from the records alone (point_figures): the seat's tangent stiffness needs the "
                              "System and the last record's contact state (run_point has them)";
        add_windup_figures(windup, f);
        note = windup_message(windup, options.loading, loop, note);
    }
    return f;
}

PointResult run_point(const SweepPoint& point, const std::atomic<bool>* stop,
                      const std::function<void(const PointResult&)>& with_records) {
    const auto t0 = std::chrono::steady_clock::now();
    PointResult result;
    result.index = point.index;
    result.figures.assign(point_figure_columns().size(), std::numeric_limits<double>::quiet_NaN());
    std::vector<StepRecord> records;
    std::vector<std::string> adjustments;  // Model::adjustments() (close clamps merged): told last in the message
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
    try {
        // the library's run, as `stackbeam simulate --scenario` (run/run.hpp): build, system, run
        const Model model = Model::build(point.scenario.model);
        adjustments = model.adjustments();
        const System system(model);
        RunRequest run;
        run.options = point.scenario.simulation;
        // the stop flag before each record and inside an output interval (mode cvode polls it every 64 steps)
        if (stop) run.stop = [stop] { return stop->load(std::memory_order_relaxed); };
        run.outputs.stresses = point.stresses;  // only when asked: a solve per record in the massless modes
        RunSummary summary = run_scenario(system, run);
        if (summary.interrupted) throw SweepStopped();
        records = std::move(summary.records);
        result.figures = figures_of(summary.loop, summary.stats.records, summary.stats.max_abs_balance_j, result.message);
        add_stress_figures(summary.stresses, result.figures);
        add_windup_figures(summary.windup, result.figures);
        if (summary.windup)
            result.message = windup_message(*summary.windup, run.options.loading, summary.loop, result.message);
    } catch (const SolverError& e) {
        result.status = PointStatus::failed;
        result.message = "solver failure at step " + std::to_string(e.step()) + " (t = " + format_value(e.time_s()) +
                         " s, residual " + format_value(e.residual()) + "): " + e.what();
    } catch (const InputError& e) {
        result.status = PointStatus::input_error;
        result.message = e.what();
    } catch (const SweepStopped&) {
        throw;
    } catch (const std::exception& e) {  // any other failure of this run (e.g. out of memory)
        result.status = PointStatus::failed;
        result.message = e.what();
    }
    for (const std::string& note : adjustments) result.message += (result.message.empty() ? "" : "; ") + note;
    result.wall_s = elapsed();
    if (with_records) {
        result.records = &records;
        result.point = &point;
        with_records(result);
        result.records = nullptr;
        result.point = nullptr;
    }
    return result;
}

namespace {

/// run_sweep over `count` points, point i given by point_at(i) (a stored point, or one made now).
template <class PointAt>
int run_sweep_with(std::size_t count, const PointAt& point_at, const SweepRunOptions& opts,
                   const PointCallback& on_point_done) {
    int jobs = opts.jobs > 0 ? opts.jobs : static_cast<int>(std::thread::hardware_concurrency());
    if (jobs < 1) jobs = 1;
    std::mutex hand_out, report;
    std::size_t next = 0;
    int run = 0;
    std::atomic<bool> failed{false};
    std::exception_ptr error;
    auto stopped = [&] { return failed || (opts.stop && opts.stop->load()); };
    auto take = [&]() -> int {
        std::lock_guard<std::mutex> lock(hand_out);
        if (stopped()) return -1;
        if (opts.next_point) return opts.next_point();
        while (next < count && next < opts.skip.size() && opts.skip[next]) ++next;
        return next < count ? static_cast<int>(next++) : -1;
    };
    std::atomic<bool> abort{false};  // opts.stop, or a callback's exception
    auto worker = [&] {
        for (int i; (i = take()) >= 0;) {
            try {
                run_point(point_at(i), &abort, [&](const PointResult& r) {
                    std::lock_guard<std::mutex> lock(report);
                    if (failed) return;
                    try {
                        on_point_done(r);
                        ++run;
                    } catch (...) {
                        failed = true;
                        error = std::current_exception();
                        abort = true;
                    }
                });
            } catch (const SweepStopped&) {
                return;
            } catch (...) {  // not a point's failure (run_point returns those): stop the sweep
                std::lock_guard<std::mutex> lock(report);
                if (!failed) error = std::current_exception();
                failed = true;
                abort = true;
                return;
            }
        }
    };
    // a watcher turns the caller's stop flag into `abort`, which the runs poll
    std::atomic<bool> done{false};
    // a thread the system refuses (std::system_error: the process's thread or memory limit,
    // e.g. `ulimit -u` / `ulimit -v`) stops the threads started and throws std::system_error
    // naming the thread and the jobs asked for, never std::terminate on a joinable thread
    auto refused = [&](const std::system_error& e, const std::string& which) {
        return std::system_error(e.code(), "could not start " + which + " (jobs = " + std::to_string(jobs) +
                                               "): the system's thread or memory limit; give fewer jobs");
    };
    std::vector<std::thread> threads;
    threads.reserve(static_cast<std::size_t>(jobs));  // no allocation between the starts below
    std::thread watcher;
    try {
        watcher = std::thread([&] {
            while (!done.load()) {
                if (opts.stop && opts.stop->load()) abort = true;
                std::this_thread::sleep_for(std::chrono::milliseconds(20));
            }
        });
    } catch (const std::system_error& e) {
        throw refused(e, "the sweep's watcher thread");
    }
    std::optional<std::system_error> start_error;
    for (int j = 1; j < jobs && !start_error; ++j) try {
            threads.emplace_back(worker);
        } catch (const std::system_error& e) {
            start_error.emplace(refused(e, "the sweep's thread " + std::to_string(j + 1) + " of " + std::to_string(jobs)));
            std::lock_guard<std::mutex> lock(hand_out);
            failed = true;  // no more points handed out; the points in flight stop at their next check
            abort = true;
        }
    if (!start_error) worker();
    for (auto& t : threads) t.join();
    done = true;
    watcher.join();
    if (start_error) throw *start_error;
    if (error) std::rethrow_exception(error);
    return run;
}

}  // namespace

int run_sweep(const std::vector<SweepPoint>& points, const SweepRunOptions& opts, const PointCallback& on_point_done) {
    return run_sweep_with(
        points.size(), [&](int i) -> const SweepPoint& { return points.at(static_cast<std::size_t>(i)); }, opts,
        on_point_done);
}

int run_sweep(const SweepPoints& points, const SweepRunOptions& opts, const PointCallback& on_point_done) {
    return run_sweep_with(
        static_cast<std::size_t>(points.size()), [&](int i) { return points.point(i); }, opts, on_point_done);
}

}  // namespace stackbeam
