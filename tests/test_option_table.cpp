// The option table (include/stackbeam/time/option_table.hpp): one name per option.
// Checks that every row follows the naming rule (member -> file key -> flag), that
// SimulationOptions::validate() names a bad value by the row's member, that the
// scenario reader names it by the row's key with the file's line, and that the
// defaults are inside every row's range.
#define BOOST_TEST_MODULE option_table
#include <boost/test/unit_test.hpp>

#include <cmath>
#include <limits>
#include <set>
#include <string>

#include "stackbeam/errors.hpp"
#include "stackbeam/io/scenario.hpp"
#include "stackbeam/time/option_table.hpp"
#include "stackbeam/time/simulation.hpp"

using namespace stackbeam;

namespace {

/// The flag the naming rule gives a key: its last part without the unit suffix, '_'
/// written '-'; a table's "kind" takes the table's name.
std::string flag_by_rule(const std::string& key) {
    std::string last = key.substr(key.find_last_of('.') + 1);
    if (last == "kind") {
        const std::string parent = key.substr(0, key.find_last_of('.'));
        last = parent.substr(parent.find_last_of('.') + 1);
    }
    for (const std::string suffix : {"_rad_per_s", "_m_per_s2", "_per_s", "_s", "_m"})
        if (last.size() > suffix.size() && last.compare(last.size() - suffix.size(), suffix.size(), suffix) == 0) {
            last.erase(last.size() - suffix.size());
            break;
        }
    for (char& c : last)
        if (c == '_') c = '-';
    return "--" + last;
}

/// A value outside the row's range (NaN is outside every range).
double outside(const OptionSpec& spec) {
    if (std::isfinite(spec.lo)) return spec.lo_open ? spec.lo : spec.lo - 1.0;
    return std::numeric_limits<double>::quiet_NaN();
}

/// A small valid scenario (two cantilever leaves, mode closed-form) with `extra` lines
/// appended to its [integrator] table (which holds only the mode); line 30 is the first
/// extra line.
std::string scenario_with(const std::string& extra) {
    return "[[leaves]]\nlength_m = 1.0\nheight_m = 0.01\nwidth_m = 0.05\nyoungs_modulus_pa = 2.1e11\n"
           "left_support = \"fixed\"\n\n"
           "[[leaves]]\nlength_m = 0.6\nheight_m = 0.01\nwidth_m = 0.05\nyoungs_modulus_pa = 2.1e11\n"
           "left_support = \"fixed\"\n\n"
           "[[interfaces]]\nlaw = \"frictionless\"\n\n"
           "[rigid_body]\nmass_kg = 5\nx_m = 1.0\n\n"
           "[loading]\nkind = \"initial-conditions\"\n\n"
           "[mesh]\nelement_length_m = 0.1\n\n"
           "[integrator]\nmode = \"closed-form\"\n" + extra;
}

}  // namespace

BOOST_AUTO_TEST_CASE(every_row_follows_the_naming_rule) {
    std::set<std::string> members, keys, flags;
    for (const OptionSpec& spec : simulation_option_table()) {
        const std::string member = spec.member, key = spec.key;
        BOOST_TEST_CONTEXT(member) {
            // the key is the member's path under [integrator] (gravity: under [loading], as in Loading)
            BOOST_TEST((key == "integrator." + member || (member.rfind("loading.", 0) == 0 && key == member)));
            BOOST_TEST(spec.flag == flag_by_rule(key));
            BOOST_TEST(find_option_by_member(member) == &spec);
            BOOST_TEST(members.insert(member).second);  // each name once
            BOOST_TEST(keys.insert(key).second);
            BOOST_TEST(flags.insert(spec.flag).second);
            if (spec.alias[0] != '\0') BOOST_TEST(flags.insert(spec.alias).second);
        }
    }
    BOOST_TEST(find_option_by_member("no_such_member") == nullptr);
}

BOOST_AUTO_TEST_CASE(defaults_are_allowed_and_bad_values_named_by_member) {
    const SimulationOptions defaults;
    BOOST_CHECK_NO_THROW(defaults.validate());
    for (const OptionSpec& spec : simulation_option_table()) {
        if (spec.type == OptionSpec::Type::keyword) continue;
        BOOST_TEST_CONTEXT(spec.member) {
            BOOST_TEST(spec.allows(spec.get(defaults)));
            SimulationOptions bad;
            spec.set(bad, outside(spec));
            try {
                bad.validate();
                BOOST_ERROR("no error");
            } catch (const InputError& e) {
                BOOST_TEST(e.field() == spec.member);
                BOOST_TEST(std::string(e.what()).find("is not allowed: must be " + spec.allowed()) != std::string::npos);
            }
        }
    }
}

BOOST_AUTO_TEST_CASE(scenario_names_a_bad_value_by_key_and_line) {
    const std::string times = "dt_s = 1e-3\nt_end_s = 0.01\n";
    BOOST_CHECK_NO_THROW(parse_scenario(scenario_with(times), "t.toml"));
    for (const OptionSpec& spec : simulation_option_table()) {
        const std::string key = spec.key;
        if (spec.type == OptionSpec::Type::keyword || key.rfind("integrator.", 0) != 0) continue;
        BOOST_TEST_CONTEXT(key) {
            // the key in its table: [integrator] itself, or a sub-table after it
            const std::string table = key.substr(0, key.find_last_of('.'));
            const std::string leaf = key.substr(key.find_last_of('.') + 1);
            const double v = outside(spec);
            const std::string value = std::isnan(v) ? "nan"
                                      : spec.type == OptionSpec::Type::integer
                                          ? std::to_string(static_cast<long long>(v))
                                          : std::to_string(v);
            // the bad key on line 30 ([integrator], with the required times that it is not) or 33
            std::string extra = table == "integrator" ? leaf + " = " + value + "\n" : times;
            if (table == "integrator") {
                if (leaf != "dt_s") extra += "dt_s = 1e-3\n";
                if (leaf != "t_end_s") extra += "t_end_s = 0.01\n";
            } else {
                extra += "[" + table + "]\n" + leaf + " = " + value + "\n";
            }
            const int line = table == "integrator" ? 30 : 33;
            try {
                parse_scenario(scenario_with(extra), "t.toml");
                BOOST_ERROR("no error");
            } catch (const InputError& e) {
                BOOST_TEST(e.field() == key);
                BOOST_TEST(e.location() == "t.toml:" + std::to_string(line) + ":" + std::to_string(leaf.size() + 4));
                BOOST_TEST(std::string(e.what()).find("is not allowed: must be " + spec.allowed()) != std::string::npos);
            }
        }
    }
}
