#pragma once
// The TOML steps the study spec readers share (internal to the library): the sweep spec
// (sweep.cpp) and the fit spec (fit_spec.cpp) parse their file, name a value's line and
// find files relative to the spec the same way.
#include <toml.hpp>

#include <exception>
#include <sstream>
#include <string>

#include "../io/toml_text.hpp"
#include "stackbeam/errors.hpp"

namespace stackbeam::detail {

/// "source:line" of a value of the spec, the location of an InputError.
inline std::string line_of(const std::string& source, const toml::value& v) {
    return source + ":" + std::to_string(v.location().line());
}

/// The folder part of `path` with its trailing '/' ("" for a bare file name).
inline std::string directory_of(const std::string& path) {
    const auto cut = path.find_last_of('/');
    return cut == std::string::npos ? std::string() : path.substr(0, cut + 1);
}

/// `name` as written in the spec file `source_name`: an absolute path as it is, a relative
/// one relative to the spec's folder.
inline std::string beside_spec(const std::string& name, const std::string& source_name) {
    return name[0] == '/' ? name : directory_of(source_name) + name;
}

/// The spec text parsed as TOML; a text the parser does not survive (check_toml_text) or
/// does not accept is refused as InputError("spec", ..., source_name).
inline toml::value parse_spec_toml(const std::string& text, const std::string& source_name) {
    check_toml_text(text, source_name);
    try {
        std::istringstream in(text);
        return toml::parse(in, source_name);
    } catch (const std::exception& e) {
        throw InputError("spec", std::string("is not a valid TOML file: ") + e.what(), source_name);
    }
}

}  // namespace stackbeam::detail

namespace stackbeam::detail {

/// The non-empty array of tables `[[key]]` of the spec's top table; refused naming `key` and
/// what each table holds (`contents`, e.g. "key, lower, upper") when missing or empty.
inline const toml::array& required_tables(const toml::table& top, const std::string& key, const std::string& contents,
                                          const std::string& source_name) {
    if (!top.count(key) || !top.at(key).is_array() || top.at(key).as_array().empty())
        throw InputError(key, "at least one [[" + key + "]] table is required (" + contents + ")",
                         top.count(key) ? line_of(source_name, top.at(key)) : source_name);
    return top.at(key).as_array();
}

/// Element `i` of the array of tables `[[key]]`, refused naming "key[i]" when it is not a table.
inline const toml::value& table_element(const toml::array& tables, std::size_t i, const std::string& key,
                                        const std::string& source_name) {
    const toml::value& t = tables[i];
    if (!t.is_table())
        throw InputError(key + "[" + std::to_string(i) + "]", "must be a table ([[" + key + "]])", line_of(source_name, t));
    return t;
}

}  // namespace stackbeam::detail
