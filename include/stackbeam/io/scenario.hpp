#pragma once
/// @file scenario.hpp
/// Scenario files: a whole run (the stack, the loading, the integrator and the
/// outputs) described in a TOML file, e.g. scenarios/paper_friction.toml. The
/// format is documented in docs/model-and-scenarios.md.
///
/// Every key is checked: an unknown key, a wrong type, a missing required field
/// or a value out of range throws InputError whose field() is the key's path in
/// the file, e.g. "leaves[2].height_m", and whose message gives the value, what is
/// allowed and where it is (file:line:column). The parser prints nothing, and the
/// TOML library it uses is not part of this interface.
#include <map>
#include <string>

#include "stackbeam/errors.hpp"
#include "stackbeam/model/model.hpp"
#include "stackbeam/time/simulation.hpp"

namespace stackbeam {

/// Where a run writes its results. Empty: not given in the file. Relative paths
/// are relative to the working directory (like command-line paths), not to the file.
struct ScenarioOutputs {
    std::string csv_path;     ///< `[outputs] csv_path`: the per-step records (CSV)
    std::string events_path;  ///< `[outputs] events_path`: the event log (mode cvode), optional
    std::string summary_path; ///< `[outputs] summary_path`: the JSON summary, optional
    std::string pairs_path;   ///< `[outputs] pairs_path`: every pair at every output time (CSV), optional
    std::string nodes_path;   ///< `[outputs] nodes_path`: every leaf's nodal displacements at every output time (CSV), optional
    std::string plot_prefix;  ///< `[outputs] plot_prefix`: PNG figures PREFIX_*.png (gnuplot), optional
    std::string stresses_path;  ///< `[outputs] stresses_path`: every leaf's stresses at every output time (CSV), optional
};

/// The words of `[[interfaces]] law` (and of the Python module's Interface.law): coulomb,
/// frictionless (InterfaceLaw::coulomb with friction_coefficient 0), bonded.
enum class InterfaceLawWord { coulomb, frictionless, bonded };
template <>
const std::vector<EnumWord<InterfaceLawWord>>& enum_words<InterfaceLawWord>();

/// A parsed, validated scenario.
struct Scenario {
    std::string source;        ///< the file name (or the name given to parse_scenario)
    std::string description;   ///< free text (`description`), may be empty
    ModelSpec model;           ///< the stack; Model::build(model) succeeds (checked by the parser)
    /// The integrator and the loading (`simulation.loading`, from `[loading]`; the initial
    /// conditions go to model.rigid_body); validate() succeeds (checked by the parser).
    SimulationOptions simulation;
    ScenarioOutputs outputs;
    /// Where each key path of the file is written, "file:line:column" (for rethrow_in_scenario).
    std::map<std::string, std::string> key_locations;
};

/// Parses scenario TOML `text`; `source_name` names it in messages. Builds the
/// model once to validate it (Model::build) and validates the options
/// (SimulationOptions::validate), translating their field names into the file's
/// key paths. Throws InputError on any problem.
Scenario parse_scenario(const std::string& text, const std::string& source_name);

/// Rethrows `e`, an InputError of the library about `scenario`'s model or options found
/// after parsing (when the run starts: a leaf density a mode cannot use, a body on a leaf
/// without stiffness), under the file's key path and with the key's location, as the
/// parser reports its own errors.
[[noreturn]] void rethrow_in_scenario(const Scenario& scenario, const InputError& e);

/// The scenario as TOML text, in the format parse_scenario reads (docs/model-and-scenarios.md):
/// every key written, each number in the shortest form that reads back to the same double,
/// so that parse_scenario(to_toml(s), name) gives the same model, options and outputs (not
/// the key locations, which belong to the text). The scenario is not validated here.
std::string to_toml(const Scenario& scenario);

/// Reads and parses the scenario file at `path`. Throws InputError (field: the
/// path) if it cannot be read, and as parse_scenario otherwise.
Scenario load_scenario(const std::string& path);

}  // namespace stackbeam
