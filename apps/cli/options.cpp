// `stackbeam simulate`'s arguments -> ModelSpec + SimulationOptions + output files.
#include "options.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>

#include "stackbeam/errors.hpp"
#include "stackbeam/io/scenario.hpp"
#include "stackbeam/run/run.hpp"
#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/time/option_table.hpp"

namespace stackbeam::cli {

namespace {

/// Refuses an output file that cannot be written, before any run: a directory, or a file
/// in a folder that does not exist or cannot be written (the system's reason). `name`: the
/// flag, or the scenario key that gave the path.
void check_output_file(const std::string& name, const std::string& path) {
    if (path.empty()) return;
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
        throw ArgumentError(name + ": value '" + path + "' is a directory: give a file name");
    const auto cut = path.find_last_of('/');
    const std::string folder = cut == std::string::npos ? "." : cut == 0 ? "/" : path.substr(0, cut);
    if (::stat(folder.c_str(), &st) != 0)
        throw ArgumentError(name + ": value '" + path + "': its folder '" + folder + "' cannot be used: " +
                            std::strerror(errno));
    if (!S_ISDIR(st.st_mode))
        throw ArgumentError(name + ": value '" + path + "': '" + folder + "' is not a directory");
    if (::access(folder.c_str(), W_OK | X_OK) != 0)
        throw ArgumentError(name + ": value '" + path + "': cannot write in '" + folder + "': " + std::strerror(errno));
}

/// Parses all of `text` as a number for `spec` given as `flag`, or throws naming the flag,
/// the text as written and what the option table allows.
double parse_number(const OptionSpec& spec, const std::string& flag, const std::string& text) {
    const std::string allowed = "must be " + spec.allowed();
    const char* begin = text.c_str();
    char* end = nullptr;
    errno = 0;
    const double value = std::strtod(begin, &end);
    if (text.empty() || end == begin || *end != '\0')
        throw ArgumentError(flag + ": value '" + text + "' is not a number: " + allowed);
    if (errno == ERANGE && std::isfinite(value) && value != 0.0 && std::abs(value) < 1.0)  // a denormal
        throw ArgumentError(flag + ": value '" + text + "' is out of range: " + allowed);
    if (spec.type == OptionSpec::Type::integer && std::isfinite(value) && value != std::floor(value))
        throw ArgumentError(flag + ": value '" + text + "' is not an integer: " + allowed);
    if (!spec.allows(value)) throw ArgumentError(flag + ": value '" + text + "' is not allowed: " + allowed);
    return value;
}

/// --elements: an integer >= 1.
int parse_count(const std::string& flag, const std::string& text) {
    const std::string allowed = "must be an integer >= 1";
    const char* begin = text.c_str();
    char* end = nullptr;
    errno = 0;
    const long value = std::strtol(begin, &end, 10);
    if (text.empty() || end == begin || *end != '\0')
        throw ArgumentError(flag + ": value '" + text + "' is not an integer: " + allowed);
    if (errno == ERANGE || value < 1 || value > std::numeric_limits<int>::max())
        throw ArgumentError(flag + ": value '" + text + "' is not allowed: " + allowed);
    return static_cast<int>(value);
}

/// --beam-density: a finite density >= 0 [kg/m^3] (0: massless leaves, the paper).
double parse_density(const std::string& text) {
    const char* begin = text.c_str();
    char* end = nullptr;
    const double value = std::strtod(begin, &end);
    if (text.empty() || end == begin || *end != '\0' || !std::isfinite(value) || value < 0.0)
        throw ArgumentError("--beam-density: value '" + text +
                            "' is not allowed: must be a finite number >= 0 [kg/m^3] (0: massless leaves, the paper)");
    return value;
}

/// --interface: the contact law of every interface, "rigid" | "elastic".
InterfaceContact parse_interface(const std::string& text) {
    try {
        return parse_interface_contact(text, "--interface");
    } catch (const InputError& e) {
        throw ArgumentError(e.what());  // "--interface: value 'x' is not allowed: must be 'rigid' or 'elastic'"
    }
}

/// Sets every interface's contact law (--interface) over the case's or the file's. With rigid,
/// a layer stiffness the file gives is unused and dropped (it needs contact = elastic).
void apply_interface(const std::optional<InterfaceContact>& contact, ModelSpec& spec) {
    if (!contact) return;
    for (auto& f : spec.interfaces) {
        f.contact = *contact;
        if (*contact == InterfaceContact::rigid) f.normal_stiffness_pa_per_m = f.tangential_stiffness_pa_per_m = 0.0;
    }
}

/// The flag of `spec` the user gave ("" if neither its name nor its alias).
std::string given_flag(const SimulateArgs& a, const OptionSpec& spec) {
    if (a.given.count(spec.flag)) return spec.flag;
    if (spec.alias[0] != '\0' && a.given.count(spec.alias)) return spec.alias;
    return "";
}

/// Sets every option of the table given on the command line over `options`.
void apply_given(const SimulateArgs& a, SimulationOptions& options) {
    for (const OptionSpec& spec : simulation_option_table()) {
        const std::string flag = given_flag(a, spec);
        if (flag.empty()) continue;
        const std::string& text = a.table_text.at(flag);
        if (spec.type == OptionSpec::Type::keyword) spec.set_word(options, text, flag);  // InputError names the flag
        else spec.set(options, parse_number(spec, flag, text));
    }
}

/// Runs options.validate(); an InputError about an option is reported under the flag the
/// user gave for it, else (a value from the scenario file) under its key and line in the file.
void validate(const SimulateArgs& a, const SimulationOptions& options, const Scenario* scenario) {
    try {
        options.validate();
    } catch (const InputError& e) {
        const OptionSpec* spec = find_option_by_member(e.field());
        const std::string flag = spec ? given_flag(a, *spec) : "";
        if (flag.empty() && scenario) rethrow_in_scenario(*scenario, e);
        if (!spec) throw;
        const std::string prefix = e.field() + ": ";
        std::string message = e.what();
        if (message.rfind(prefix, 0) == 0) message.erase(0, prefix.size());
        throw ArgumentError((flag.empty() ? std::string(spec->flag) : flag) + ": " + message);
    }
}

}  // namespace

CLI::App* add_simulate_command(CLI::App& app, SimulateArgs& a) {
    CLI::App& sim = *app.add_subcommand("simulate", "Simulate the paper example or a scenario and write one CSV row per time step");
    sim.footer("One name per option: a flag is its scenario key's last part without the unit suffix, '_' written '-'\n"
               "(integrator.cvode.max_step_s: --max-step; integrator.solver.kind: --solver); the key is the member's\n"
               "path in SimulationOptions under [integrator]. Renamed flags keep their old name: --tol (--tolerance).\n"
               "Errors name the flag as given, or the file's key with file:line:column.");
    CLI::Option* case_opt =
        sim.add_option("--case", a.case_name, "the paper example: bonded | friction | frictionless")->type_name("CASE");
    CLI::Option* scenario_opt =
        sim.add_option("--scenario", a.scenario,
                       "a scenario file (TOML, docs/model-and-scenarios.md) instead of --case; options given here "
                       "override its values")
            ->type_name("FILE.toml")
            ->excludes(case_opt);
    // The integrator's options: one row of the library's table each (option_table.hpp).
    const SimulationOptions defaults;
    for (const OptionSpec& spec : simulation_option_table()) {
        std::string help = std::string(spec.help) + "; " + spec.allowed() + "; file key " + spec.key +
                           " (default " + spec.value_text(defaults) + ")";
        const std::string type = spec.type == OptionSpec::Type::keyword ? "WORD"
                                 : spec.type == OptionSpec::Type::integer ? "N"
                                                                          : "X";
        CLI::Option* main = sim.add_option(spec.flag, a.table_text[spec.flag], help)->type_name(type);
        if (spec.alias[0] != '\0')
            sim.add_option(spec.alias, a.table_text[spec.alias], std::string("the old name of ") + spec.flag)
                ->type_name(type)
                ->excludes(main);
    }
    sim.add_option("--elements", a.elements,
                   "--case: elements per half leaf (default " +
                       std::to_string(PaperExampleOptions{}.elements_per_half_leaf) + ")")
        ->type_name("N")
        ->excludes(scenario_opt);
    sim.add_flag("--full-model", a.full_model, "--case: mesh the whole spring instead of the symmetric half")
        ->excludes(scenario_opt);
    sim.add_option("--beam-density", a.beam_density,
                   "density of every leaf [kg/m^3] (file key leaves[i].density_kg_per_m3): 0 = massless leaves (the "
                   "paper), > 0 = leaves with mass (mode newmark; mode cvode) (default: the case's or the file's, "
                   "0 in the paper cases)")
        ->type_name("KG_PER_M3");
    sim.add_option("--interface", a.interface,
                   "contact law of every interface: rigid (surface points node to node, the paper) | elastic (an "
                   "elastic layer of the leaves' own through-thickness stiffness; docs/model-and-scenarios.md, "
                   "\"Elastic interfaces\"); file key interfaces[i].contact (default: the case's or the file's, rigid)")
        ->type_name("LAW");
    sim.add_option("--out", a.out,
                   "output CSV file (written as FILE.partial, renamed when complete); required unless the scenario names "
                   "one (file key outputs.csv_path)")
        ->type_name("FILE.csv");
    sim.add_option("--events", a.events, "cvode: write the event log to this CSV (file key outputs.events_path)")
        ->type_name("FILE.csv");
    sim.add_option("--summary", a.summary, "write a JSON summary (file key outputs.summary_path)")->type_name("FILE");
    sim.add_option("--pairs", a.pairs, "write every contact pair at every output time (file key outputs.pairs_path)")
        ->type_name("FILE");
    sim.add_option("--nodes", a.nodes,
                   "write every leaf's nodal displacements (t, leaf, x, w, theta; the half model mirrored to whole "
                   "leaves) at every output time (file key outputs.nodes_path)")
        ->type_name("FILE.csv");
    sim.add_option("--stresses", a.stresses,
                   "write every leaf's stresses and resultants (t, leaf, x, sigma_top, sigma_bottom [Pa], axial_force, "
                   "shear_force [N], bending_moment [N m]; whole leaves) at every output time; the summary then has "
                   "the largest stress per leaf (file key outputs.stresses_path)")
        ->type_name("FILE.csv");
    sim.add_option("--plot", a.plot, "draw PNG figures with gnuplot: PREFIX_*.png (file key outputs.plot_prefix)")
        ->type_name("PREFIX");
    sim.add_option("--stack-color", a.stack_color,
                   "with --plot: what colours the deformed stack (PREFIX_stack.png): state (every pair by its state: "
                   "stick, slip, open) | stress (each leaf a band coloured by its stress [MPa], tension positive, the "
                   "fibres' at its edges; the run then computes the stresses, as --stresses does) (default state)")
        ->type_name("WORD");
    sim.add_flag("--quiet", a.quiet, "no progress line on the terminal");
    return &sim;
}

SimulateRequest make_request(const SimulateArgs& a) {
    SimulateRequest r;
    static_cast<OutputPaths&>(r) = a;  // the files as given; the scenario's fill those not given below
    r.quiet = a.quiet;
    const bool density_given = a.given.count("--beam-density") > 0;
    std::optional<InterfaceContact> contact;  // --interface, checked before the file is read
    if (a.given.count("--interface") > 0) contact = parse_interface(a.interface);
    if (!a.scenario.empty()) {
        // A scenario file; options given on the command line override its values.
        r.scenario = load_scenario(a.scenario);
        const Scenario& scenario = *r.scenario;
        r.spec = scenario.model;
        r.options = scenario.simulation;
        apply_given(a, r.options);
        if (r.out.empty()) r.out = scenario.outputs.csv_path;
        if (r.out.empty())
            throw ArgumentError("--out: an output file name is required (none given, and " + a.scenario +
                                " has no outputs.csv_path)");
        if (r.events.empty()) r.events = scenario.outputs.events_path;
        if (r.summary.empty()) r.summary = scenario.outputs.summary_path;
        if (r.pairs.empty()) r.pairs = scenario.outputs.pairs_path;
        if (r.nodes.empty()) r.nodes = scenario.outputs.nodes_path;
        if (r.plot.empty()) r.plot = scenario.outputs.plot_prefix;
        if (r.stresses.empty()) r.stresses = scenario.outputs.stresses_path;
        if (density_given)
            for (auto& leaf : r.spec.leaves) leaf.density_kg_per_m3 = parse_density(a.beam_density);
        apply_interface(contact, r.spec);
        r.setup = scenario_setup(a.scenario, scenario.description);
    } else {
        if (a.case_name.empty()) throw ArgumentError("--case or --scenario: one of them is required");
        const PaperCase pcase = parse_paper_case(a.case_name, "--case");
        apply_given(a, r.options);  // over the library's defaults
        PaperExampleOptions example;
        if (!a.elements.empty()) example.elements_per_half_leaf = parse_count("--elements", a.elements);
        example.symmetry = a.full_model ? Symmetry::full : Symmetry::half;
        if (r.out.empty()) throw ArgumentError("--out: an output file name is required");
        r.spec = paper_example(pcase, example);
        if (density_given)
            for (auto& leaf : r.spec.leaves) leaf.density_kg_per_m3 = parse_density(a.beam_density);
        apply_interface(contact, r.spec);
        r.setup = case_setup(pcase, example);
    }
    // what the modes' steppers take: the registry's rows (run/run.hpp), before the system is built
    auto has = [&](StepperFeature f) {
        const auto modes = modes_with(f);
        return std::find(modes.begin(), modes.end(), r.options.mode) != modes.end();
    };
    if (density_given && parse_density(a.beam_density) > 0.0 && !has(StepperFeature::massive_leaves))
        throw ArgumentError("--beam-density: value '" + a.beam_density + "' needs --mode " +
                            mode_list(modes_with(StepperFeature::massive_leaves), " or ") + ": mode " +
                            to_string(r.options.mode) + " treats the leaves as massless, the paper");
    if (!r.events.empty() && !has(StepperFeature::event_log)) {
        const std::string modes = mode_list(modes_with(StepperFeature::event_log), " or ");
        throw ArgumentError((a.events.empty() ? "outputs.events_path (file " + a.scenario + ")" : std::string("--events")) +
                            ": value '" + r.events + "': the event log exists in mode " + modes + " only (mode " +
                            std::string(to_string(r.options.mode)) + "): remove it, or use mode " + modes);
    }
    if (!r.nodes.empty()) {  // the nodes' rows would overwrite (or interleave with) another output
        const std::string what = a.nodes.empty() ? "outputs.nodes_path (file " + a.scenario + ")" : std::string("--nodes");
        for (const auto& [other, file] : {std::pair<const char*, const std::string*>{"--out", &r.out},
                                          {"--pairs", &r.pairs}, {"--events", &r.events}, {"--summary", &r.summary}})
            if (*file == r.nodes)
                throw ArgumentError(what + ": value '" + r.nodes + "' is also the " + other +
                                    " file: give the nodal displacements a file of their own");
    }
    if (!r.stresses.empty()) {  // the stresses' rows would overwrite (or interleave with) another output
        const std::string what =
            a.stresses.empty() ? "outputs.stresses_path (file " + a.scenario + ")" : std::string("--stresses");
        for (const auto& [other, file] : {std::pair<const char*, const std::string*>{"--out", &r.out}, {"--pairs", &r.pairs},
                                          {"--nodes", &r.nodes}, {"--events", &r.events}, {"--summary", &r.summary}})
            if (*file == r.stresses)
                throw ArgumentError(what + ": value '" + r.stresses + "' is also the " + other +
                                    " file: give the stresses a file of their own");
    }
    // every output checked before the run: a bad path is found in a moment, not after the simulation
    auto name = [&](const std::string& flag, const std::string& given, const char* key) {
        return given.empty() && !a.scenario.empty() ? std::string("outputs.") + key + " (file " + a.scenario + ")" : flag;
    };
    check_output_file(name("--out", a.out, "csv_path"), r.out);
    check_output_file(name("--events", a.events, "events_path"), r.events);
    check_output_file(name("--summary", a.summary, "summary_path"), r.summary);
    check_output_file(name("--pairs", a.pairs, "pairs_path"), r.pairs);
    check_output_file(name("--nodes", a.nodes, "nodes_path"), r.nodes);
    check_output_file(name("--stresses", a.stresses, "stresses_path"), r.stresses);
    if (a.given.count("--stack-color") > 0) {
        if (a.stack_color != "state" && a.stack_color != "stress")
            throw ArgumentError("--stack-color: value '" + a.stack_color + "' is not allowed: state or stress");
        if (r.plot.empty())
            throw ArgumentError("--stack-color: value '" + a.stack_color + "' colours the --plot figure of the deformed stack: "
                                "give --plot PREFIX (or outputs.plot_prefix) too");
        r.stack_stress = a.stack_color == "stress";
    }
    validate(a, r.options, r.scenario ? &*r.scenario : nullptr);
    return r;
}

}  // namespace stackbeam::cli
