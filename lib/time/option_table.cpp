// The user options of SimulationOptions, defined once (option_table.hpp): the
// scenario reader, the command line and SimulationOptions::validate() read them here.
#include "stackbeam/time/option_table.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include "stackbeam/errors.hpp"
#include "stackbeam/time/simulation.hpp"

namespace stackbeam {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
static_assert(kSparsePathMinComponents == 150, "the --contact-path help below states the threshold: update it");
using T = OptionSpec::Type;

std::string number_text(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.15g", v);
    return buf;
}

}  // namespace

STACKBEAM_ENUM_WORDS(TauRule, {TauRule::current, "current"}, {TauRule::previous_step, "previous-step"})

namespace {

const char* to_word(TauRule rule) { return word_of(rule); }

TauRule parse_tau_rule(const std::string& text, const std::string& field) {
    return parse_word<TauRule>(text, field, "tau rule");
}

/// A keyword option's choices for the table and --help: "a | b | c" from the enum's word table.
template <class E>
const char* choices_of() {
    static const std::string text = word_list<E>("", " | ");
    return text.c_str();
}

// Builders of the rows: a number, an integer, a keyword.
OptionSpec real(const char* member, const char* key, const char* flag, const char* alias, const char* unit,
                const char* help, double lo, bool lo_open, double hi, bool hi_open, const char* note,
                double (*get)(const SimulationOptions&), void (*set)(SimulationOptions&, double)) {
    return {member, key, flag, alias, unit, help, T::real, lo, hi, lo_open, hi_open, note, "", get, set, nullptr, nullptr};
}
OptionSpec integer(const char* member, const char* key, const char* flag, const char* help, double lo, double hi,
                   double (*get)(const SimulationOptions&), void (*set)(SimulationOptions&, double)) {
    return {member, key, flag, "", "-", help, T::integer, lo, hi, false, false, "", "", get, set, nullptr, nullptr};
}
OptionSpec keyword(const char* member, const char* key, const char* flag, const char* help, const char* choices,
                   std::string (*get)(const SimulationOptions&),
                   void (*set)(SimulationOptions&, const std::string&, const std::string&)) {
    return {member, key, flag, "", "", help, T::keyword, 0.0, 0.0, false, false, "", choices, nullptr, nullptr, get, set};
}

std::vector<OptionSpec> make_table() {
    using O = SimulationOptions;
    using S = const std::string&;
    return {
        keyword("mode", "integrator.mode", "--mode",
                "time stepping: closed-form (the paper's exact step, fixed dt), cvode (SUNDIALS CVODE, root-finding "
                "on every stick-slip and open-close transition), newmark (leaves with mass, --beam-density; "
                "average-acceleration Newmark, fixed dt)",
                choices_of<Mode>(), [](const O& o) { return std::string(to_string(o.mode)); },
                [](O& o, S t, S f) { o.mode = parse_mode(t, f); }),
        real("dt_s", "integrator.dt_s", "--dt", "", "s", "time step (mode cvode: the output interval)", 0.0, true, kInf,
             false, "", [](const O& o) { return o.dt_s; }, [](O& o, double v) { o.dt_s = v; }),
        real("t_end_s", "integrator.t_end_s", "--t-end", "", "s", "end time", 0.0, true, kInf, false, "",
             [](const O& o) { return o.t_end_s; }, [](O& o, double v) { o.t_end_s = v; }),
        keyword("tau_rule", "integrator.tau_rule", "--tau-rule",
                "friction limit of a step: from the step's own normal forces (current) or the previous step's",
                choices_of<TauRule>(), [](const O& o) { return std::string(to_word(o.tau_rule)); },
                [](O& o, S t, S f) { o.tau_rule = parse_tau_rule(t, f); }),
        real("restitution", "integrator.restitution", "--restitution", "", "-",
             "mode newmark with massive leaves: the impact law's normal restitution coefficient", 0.0, false, 1.0,
             false, "0: perfectly inelastic, 1: elastic", [](const O& o) { return o.restitution; },
             [](O& o, double v) { o.restitution = v; }),
        keyword("contact_path", "integrator.contact_path", "--contact-path",
                "contact problem: auto (dense below kSparsePathMinComponents = 150 contact components, else "
                "sparse), dense, sparse (exact solver only; not in mode cvode)",
                choices_of<ContactPath>(), [](const O& o) { return std::string(to_string(o.contact_path)); },
                [](O& o, S t, S f) { o.contact_path = parse_contact_path(t, f); }),
        keyword("solver.kind", "integrator.solver.kind", "--solver",
                "contact solver (every mode; in mode cvode the per-step check): exact (active set), accelerated "
                "(eq. 17, E = per-pair block inverse), block-jacobi, paper (eq. 17, E = I)",
                choices_of<SolverKind>(),
                [](const O& o) { return std::string(to_string(o.solver.kind)); },
                [](O& o, S t, S f) { o.solver.kind = parse_solver_kind(t, f); }),
        real("solver.tolerance_m", "integrator.solver.tolerance_m", "--tolerance", "--tol", "m",
             "contact tolerance on ||v||_2 (eq. 9)", 0.0, true, kInf, false, "",
             [](const O& o) { return o.solver.tolerance_m; }, [](O& o, double v) { o.solver.tolerance_m = v; }),
        integer("solver.max_iterations", "integrator.solver.max_iterations", "--max-iterations",
                "iteration limit per step of the iterative solvers", 1.0, std::numeric_limits<int>::max(),
                [](const O& o) { return static_cast<double>(o.solver.max_iterations); },
                [](O& o, double v) { o.solver.max_iterations = static_cast<int>(v); }),
        real("solver.alpha_fraction", "integrator.solver.alpha_fraction", "--alpha-fraction", "", "-",
             "paper / block-jacobi solver: alpha as a fraction of its stability bound 2/lambda_max(E W)", 0.0, true,
             1.0, true, "", [](const O& o) { return o.solver.alpha_fraction; },
             [](O& o, double v) { o.solver.alpha_fraction = v; }),
        real("cvode.rtol", "integrator.cvode.rtol", "--rtol", "", "-", "mode cvode: CVODE's relative tolerance",
             1e-14, false, 1e-2, false, "", [](const O& o) { return o.cvode.rtol; },
             [](O& o, double v) { o.cvode.rtol = v; }),
        real("cvode.atol_m", "integrator.cvode.atol_m", "--atol", "", "m", "mode cvode: absolute tolerance on w", 0.0,
             true, kInf, false, "", [](const O& o) { return o.cvode.atol_m; },
             [](O& o, double v) { o.cvode.atol_m = v; }),
        real("cvode.max_step_s", "integrator.cvode.max_step_s", "--max-step", "", "s",
             "mode cvode: largest internal step", 0.0, false, kInf, false, "0: no limit",
             [](const O& o) { return o.cvode.max_step_s; }, [](O& o, double v) { o.cvode.max_step_s = v; }),
        integer("cvode.max_steps", "integrator.cvode.max_steps", "--max-steps",
                "mode cvode: limit on CVODE's internal steps over the run", 1.0, 1e18,
                [](const O& o) { return static_cast<double>(o.cvode.max_steps); },
                [](O& o, double v) { o.cvode.max_steps = static_cast<long>(v); }),
        real("cvode.modal_cutoff_rad_per_s", "integrator.cvode.modal_cutoff_rad_per_s", "--modal-cutoff", "",
             "rad/s",
             "mode cvode, massive leaves with friction: the stack's modes up to this circular frequency carry the "
             "inertia, those above respond quasi-statically (docs/time-integration.md)",
             0.0, false, kInf, false, "0: 10 x the stack's first frequency",
             [](const O& o) { return o.cvode.modal_cutoff_rad_per_s; },
             [](O& o, double v) { o.cvode.modal_cutoff_rad_per_s = v; }),
        keyword("cvode.leaf_inertia", "integrator.cvode.leaf_inertia", "--leaf-inertia",
                "mode cvode, massive leaves with friction: the whole massive stack (needs an elastic layer on every "
                "contact row), the stack's modes below the cut with a massless contact layer, or auto (massive "
                "where every row is elastic, else modal) (docs/time-integration.md)",
                choices_of<LeafInertia>(), [](const O& o) { return std::string(to_string(o.cvode.leaf_inertia)); },
                [](O& o, S t, S f) { o.cvode.leaf_inertia = parse_leaf_inertia(t, f); }),
        real("damping.rayleigh_alpha_per_s", "integrator.damping.rayleigh_alpha_per_s", "--rayleigh-alpha", "", "1/s",
             "structural damping C = alpha M + beta K of the leaves, mass coefficient (mode cvode, massive stack)", 0.0,
             false, kInf, false, "0: none",
             [](const O& o) { return o.damping.rayleigh_alpha_per_s; },
             [](O& o, double v) { o.damping.rayleigh_alpha_per_s = v; }),
        real("damping.rayleigh_beta_s", "integrator.damping.rayleigh_beta_s", "--rayleigh-beta", "", "s",
             "structural damping C = alpha M + beta K of the leaves, stiffness coefficient (mode cvode, massive stack)",
             0.0, false, kInf, false, "0: none",
             [](const O& o) { return o.damping.rayleigh_beta_s; },
             [](O& o, double v) { o.damping.rayleigh_beta_s = v; }),
        real("damping.layer_normal_time_s", "integrator.damping.layer_normal_time_s", "--layer-normal-time", "", "s",
             "the elastic layer's normal retardation time tau_L: a dashpot tau_L k_n on every closed pair with a layer, "
             "in parallel with its spring (mode cvode, massive stack: damps the contact points' own vibration on the layer)",
             0.0, false, kInf, false, "0: none",
             [](const O& o) { return o.damping.layer_normal_time_s; },
             [](O& o, double v) { o.damping.layer_normal_time_s = v; }),
        real("loading.gravity_m_per_s2", "loading.gravity_m_per_s2", "--gravity", "", "m/s^2",
             "gravity on R, acting in -y (static equilibrium first)", 0.0, false, kInf, false, "0: none",
             [](const O& o) { return o.loading.gravity_m_per_s2; },
             [](O& o, double v) { o.loading.gravity_m_per_s2 = v; }),
    };
}

}  // namespace

std::string OptionSpec::allowed() const {
    if (type == Type::keyword) return std::string("one of ") + choices;
    std::string out;
    const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
    if (type == Type::integer) {
        out = "an integer >= " + number_text(lo);
        if (has_hi && hi < 1e18) out += " and <= " + number_text(hi);
    } else if (has_lo && has_hi) {
        out = "a number in " + std::string(lo_open ? "(" : "[") + number_text(lo) + ", " + number_text(hi) +
              (hi_open ? ")" : "]");
    } else if (has_lo) {
        out = "a finite number " + std::string(lo_open ? "> " : ">= ") + number_text(lo);
    } else {
        out = "a finite number";
    }
    if (unit[0] != '\0' && std::string(unit) != "-") out += std::string(" [") + unit + "]";
    if (note[0] != '\0') out += std::string(" (") + note + ")";
    return out;
}

bool OptionSpec::allows(double value) const {
    if (type == Type::keyword || !std::isfinite(value)) return false;
    if (type == Type::integer && value != std::floor(value)) return false;
    if (lo_open ? !(value > lo) : !(value >= lo)) return false;
    if (hi_open ? !(value < hi) : !(value <= hi)) return false;
    return true;
}

std::string OptionSpec::value_text(const SimulationOptions& options) const {
    if (type == Type::keyword) return get_word(options);
    const double v = get(options);
    if (type == Type::integer) return std::to_string(static_cast<long long>(v));
    return number_text(v);
}

const std::vector<OptionSpec>& simulation_option_table() {
    static const std::vector<OptionSpec> table = make_table();
    return table;
}

const OptionSpec* find_option_by_member(const std::string& member) {
    for (const auto& spec : simulation_option_table())
        if (member == spec.member) return &spec;
    return nullptr;
}

void check_option(const OptionSpec& spec, double value) {
    if (!spec.allows(value))
        throw InputError(spec.member, "value " +
                                          (spec.type == OptionSpec::Type::integer && std::abs(value) < 1e18
                                               ? std::to_string(static_cast<long long>(value))
                                               : format_value(value)) +
                                          " is not allowed: must be " + spec.allowed());
}

}  // namespace stackbeam
