#pragma once
/// @file option_table.hpp
/// Every option of SimulationOptions that a user sets, defined once: the member it
/// sets, its key in a scenario file, its command-line flag, its unit and what is
/// allowed. The scenario reader (io/scenario.hpp), the command line and
/// SimulationOptions::validate() all read this one table, so the member, the key,
/// the flag and the error message agree.
///
/// Naming rule (one name per option):
///   member  the path in SimulationOptions, e.g. "cvode.rtol"; InputError::field() of
///           SimulationOptions::validate() is this path;
///   key     "integrator." + member in a scenario file (gravity: "loading." + its member
///           in Loading, the file's [loading] table), e.g. "integrator.cvode.rtol";
///   flag    "--" + the key's last part without its unit suffix (_s, _m, _rad_per_s,
///           _m_per_s2), '_' written '-', e.g. --rtol, --t-end, --max-step; a table's
///           "kind" takes the table's name (integrator.solver.kind: --solver).
/// A flag renamed to follow the rule keeps its old name as an alias (`alias`).
#include <string>
#include <vector>

namespace stackbeam {

struct SimulationOptions;

/// One user option of SimulationOptions.
struct OptionSpec {
    enum class Type {
        real,     ///< a finite number within [lo, hi] (bounds open or closed)
        integer,  ///< an integer within [lo, hi]
        keyword,  ///< one of a set of words (`choices`)
    };
    const char* member;  ///< path in SimulationOptions, e.g. "cvode.rtol"
    const char* key;     ///< key path in a scenario file, e.g. "integrator.cvode.rtol"
    const char* flag;    ///< command-line flag, e.g. "--rtol"
    const char* alias;   ///< an older flag that still works ("" if none)
    const char* unit;    ///< SI unit, "-" dimensionless, "" for a keyword
    const char* help;    ///< what it is, one line
    Type type;
    double lo, hi;              ///< bounds of a real or integer (+-inf: none)
    bool lo_open, hi_open;      ///< true: the bound itself is not allowed
    const char* note;           ///< what special values mean, e.g. "0: no limit" ("" if none)
    const char* choices;        ///< keyword: the allowed words, e.g. "closed-form | cvode | newmark"
    /// real / integer: read and write the member.
    double (*get)(const SimulationOptions&);
    void (*set)(SimulationOptions&, double);
    /// keyword: read the member's word; parse `text` into it (throws InputError naming `field`).
    std::string (*get_word)(const SimulationOptions&);
    void (*set_word)(SimulationOptions&, const std::string& text, const std::string& field);

    /// What is allowed, e.g. "a number in [1e-14, 0.01] [-]" or "one of exact | accelerated | ...".
    std::string allowed() const;
    /// Whether `value` is allowed (real / integer).
    bool allows(double value) const;
    /// The member's current value as text (for --help defaults and messages).
    std::string value_text(const SimulationOptions& options) const;
};

/// The table, in the order of --help.
const std::vector<OptionSpec>& simulation_option_table();
/// The entry whose member is `member` (e.g. "cvode.rtol"), or nullptr.
const OptionSpec* find_option_by_member(const std::string& member);

/// Throws InputError(spec.member, "value V is not allowed: must be ALLOWED") unless
/// spec.allows(value).
void check_option(const OptionSpec& spec, double value);

}  // namespace stackbeam
