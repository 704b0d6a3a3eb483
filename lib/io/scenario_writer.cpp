// Scenario files written back (to_toml): the inverse of the reader in scenario.cpp,
// key for key (docs/model-and-scenarios.md). Hand-written rather than through toml11's
// serializer so that the keys come in the documented order, one table per section,
// and every number in its shortest round-trip form (std::to_chars).
#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "stackbeam/io/scenario.hpp"
#include "stackbeam/time/option_table.hpp"

namespace stackbeam {

namespace {

/// The shortest text that reads back to `v` exactly (TOML: inf, -inf, nan as such).
std::string number(double v) {
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    char buf[64];
    const auto res = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, res.ptr);
}

/// A TOML basic string: quotes, backslashes and control characters escaped.
std::string quoted(const std::string& text) {
    std::string out = "\"";
    for (const unsigned char c : text) {
        switch (c) {
            case '"': out += "\\\""; break;
            case '\\': out += "\\\\"; break;
            case '\n': out += "\\n"; break;
            case '\t': out += "\\t"; break;
            case '\r': out += "\\r"; break;
            default:
                if (c < 0x20 || c == 0x7f) {
                    char buf[8];
                    std::snprintf(buf, sizeof buf, "\\u%04x", c);
                    out += buf;
                } else {
                    out += static_cast<char>(c);
                }
        }
    }
    return out + "\"";
}

std::string numbers(const std::vector<double>& values) {
    std::string out = "[";
    for (std::size_t i = 0; i < values.size(); ++i) out += (i ? ", " : "") + number(values[i]);
    return out + "]";
}

/// `key = value` lines of one table.
class Lines {
public:
    explicit Lines(std::ostringstream& out) : out_(out) {}
    void num(const char* key, double v) { out_ << key << " = " << number(v) << '\n'; }
    void integer(const char* key, long long v) { out_ << key << " = " << v << '\n'; }
    void word(const char* key, const std::string& v) { out_ << key << " = " << quoted(v) << '\n'; }
    void array(const char* key, const std::vector<double>& v) { out_ << key << " = " << numbers(v) << '\n'; }

private:
    std::ostringstream& out_;
};

void write_end(std::ostringstream& out, const char* name, const LeafEndSpec& e) {
    const LeafEndSpec none;
    if (e.eye_offset_m == none.eye_offset_m && e.shackle_angle_rad == none.shackle_angle_rad &&
        e.bushing_x_n_per_m == none.bushing_x_n_per_m && e.bushing_y_n_per_m == none.bushing_y_n_per_m &&
        e.bushing_rotation_n_m_per_rad == none.bushing_rotation_n_m_per_rad)
        return;  // absent: the defaults
    out << "[leaves." << name << "]\n";
    Lines l(out);
    l.num("eye_offset_m", e.eye_offset_m);
    l.num("shackle_angle_rad", e.shackle_angle_rad);
    l.num("bushing_x_n_per_m", e.bushing_x_n_per_m);
    l.num("bushing_y_n_per_m", e.bushing_y_n_per_m);
    l.num("bushing_rotation_n_m_per_rad", e.bushing_rotation_n_m_per_rad);
}

/// [leaves.material]: the given strengths (0: not given, left out) and the correction.
void write_material(std::ostringstream& out, const FatigueMaterial& m) {
    out << "[leaves.material]\n";
    Lines l(out);
    l.num("ultimate_strength_pa", m.ultimate_strength_pa);
    for (const auto& [key, value] : {std::pair<const char*, double>{"yield_strength_pa", m.yield_strength_pa},
                                     {"endurance_limit_pa", m.endurance_limit_pa},
                                     {"fatigue_strength_coefficient_pa", m.fatigue_strength_coefficient_pa},
                                     {"fatigue_strength_exponent", m.fatigue_strength_exponent}})
        if (value != 0.0) l.num(key, value);
    l.word("mean_stress_correction", to_string(m.mean_stress_correction));
}

void write_time_function(std::ostringstream& out, const std::string& table, const TimeFunction& f) {
    out << "[" << table << "]\n";
    Lines l(out);
    l.word("shape", to_string(f.shape));
    switch (f.shape) {
        case TimeFunction::Shape::constant: l.num("mean", f.mean); break;
        case TimeFunction::Shape::harmonic:
        case TimeFunction::Shape::triangle:
            l.num("mean", f.mean);
            l.num("amplitude", f.amplitude);
            l.num("frequency_hz", f.frequency_hz);
            l.num("phase_rad", f.phase_rad);
            break;
        case TimeFunction::Shape::table:
            l.array("times_s", f.times_s);
            l.array("values", f.values);
            break;
    }
}

/// [integrator] and its sub-tables: every key of the option table under "integrator."
/// (option_table.hpp), its table's keys together, in the table's order.
void write_integrator(std::ostringstream& out, const SimulationOptions& o) {
    const std::string prefix = "integrator.";
    std::vector<std::string> tables;                          // in order of first appearance
    std::map<std::string, std::vector<const OptionSpec*>> rows;  // table path -> its rows
    for (const OptionSpec& spec : simulation_option_table()) {
        const std::string key = spec.key;
        if (key.compare(0, prefix.size(), prefix) != 0) continue;
        const std::string table = key.substr(0, key.find_last_of('.'));
        if (rows.find(table) == rows.end()) tables.push_back(table);
        rows[table].push_back(&spec);
    }
    for (const std::string& table : tables) {
        out << "\n[" << table << "]\n";
        Lines l(out);
        for (const OptionSpec* spec : rows[table]) {
            const std::string key = std::string(spec->key).substr(table.size() + 1);
            switch (spec->type) {
                case OptionSpec::Type::keyword: l.word(key.c_str(), spec->get_word(o)); break;
                case OptionSpec::Type::integer: l.integer(key.c_str(), std::llround(spec->get(o))); break;
                case OptionSpec::Type::real: l.num(key.c_str(), spec->get(o)); break;
            }
        }
    }
}

}  // namespace

std::string to_toml(const Scenario& s) {
    std::ostringstream out;
    Lines top(out);
    const ModelSpec& m = s.model;
    if (!s.description.empty()) top.word("description", s.description);

    for (const LeafSpec& leaf : m.leaves) {
        out << "\n[[leaves]]\n";
        Lines l(out);
        l.num("length_m", leaf.length_m);
        l.num("x_start_m", leaf.x_start_m);
        l.num("height_m", leaf.height_m);
        l.num("width_m", leaf.width_m);
        l.num("youngs_modulus_pa", leaf.youngs_modulus_pa);
        l.num("density_kg_per_m3", leaf.density_kg_per_m3);
        l.num("poisson_ratio", leaf.poisson_ratio);
        l.word("left_support", to_string(leaf.left_support));
        l.word("right_support", to_string(leaf.right_support));
        l.num("free_camber_m", leaf.free_camber_m);
        l.num("free_radius_m", leaf.free_radius_m);
        const LeafProfile& p = leaf.profile;
        if (!p.x_m.empty() || !p.thickness_m.empty() || !p.width_m.empty()) {
            out << "[leaves.profile]\n";
            l.array("x_m", p.x_m);
            if (!p.thickness_m.empty()) l.array("thickness_m", p.thickness_m);
            if (!p.width_m.empty()) l.array("width_m", p.width_m);
        }
        write_end(out, "left_end", leaf.left_end);
        write_end(out, "right_end", leaf.right_end);
        if (leaf.material) write_material(out, *leaf.material);  // a shared [material] is written per leaf
    }
    for (const InterfaceSpec& f : m.interfaces) {
        out << "\n[[interfaces]]\n";
        Lines l(out);
        if (f.law == InterfaceLaw::bonded) {
            l.word("law", word_of(InterfaceLawWord::bonded));  // its friction coefficient is not used (the reader sets 0)
        } else {
            l.word("law", word_of(InterfaceLawWord::coulomb));
            l.num("friction_coefficient", f.friction_coefficient);
        }
        l.num("initial_gap_m", f.initial_gap_m);
        l.word("contact", to_string(f.contact));
        l.num("normal_stiffness_pa_per_m", f.normal_stiffness_pa_per_m);
        l.num("tangential_stiffness_pa_per_m", f.tangential_stiffness_pa_per_m);
    }
    for (const ClampSpec& c : m.clamps) {
        out << "\n[[clamps]]\n";
        Lines l(out);
        l.num("x_m", c.x_m);
        l.num("preload_n", c.preload_n);
        l.num("length_m", c.length_m);
    }
    for (const ClipSpec& c : m.clips) {
        out << "\n[[clips]]\n";
        Lines l(out);
        l.num("x_m", c.x_m);
        l.integer("first_leaf", c.first_leaf);
        l.integer("last_leaf", c.last_leaf);
        l.num("clearance_m", c.clearance_m);
        l.num("stiffness_n_per_m", c.stiffness_n_per_m);
    }

    out << "\n[rigid_body]\n";
    top.num("mass_kg", m.rigid_body.mass_kg);
    top.num("x_m", m.rigid_body.x_m);
    if (!m.rigid_body.tied_leaves.empty()) {
        out << "tied_leaves = [";
        for (std::size_t i = 0; i < m.rigid_body.tied_leaves.size(); ++i)
            out << (i ? ", " : "") << m.rigid_body.tied_leaves[i];
        out << "]\n";
    }
    // the windup keys only where they differ from the defaults (files of vertical loadings unchanged)
    if (m.rigid_body.pitch_inertia_kg_m2 != 0.0) top.num("pitch_inertia_kg_m2", m.rigid_body.pitch_inertia_kg_m2);
    if (m.rigid_body.axial != SeatAxial::automatic) top.word("axial", to_string(m.rigid_body.axial));

    // [loading]: the loading of the options and R's initial conditions of the model
    const Loading& load = s.simulation.loading;
    out << "\n[loading]\n";
    top.word("kind", to_string(load.kind));
    top.num("initial_displacement_m", m.rigid_body.initial_displacement_m);
    top.num("initial_velocity_m_per_s", m.rigid_body.initial_velocity_m_per_s);
    top.num("gravity_m_per_s2", load.gravity_m_per_s2);
    if (load.longitudinal_force_n) top.num("longitudinal_force_height_m", load.longitudinal_force_height_m);
    if (load.kind == LoadingKind::applied_force) write_time_function(out, "loading.force_n", load.force_n);
    if (load.kind == LoadingKind::prescribed_displacement || load.kind == LoadingKind::base_excitation)
        write_time_function(out, "loading.displacement_m", load.displacement_m);
    if (load.seat_moment_n_m) write_time_function(out, "loading.seat_moment_n_m", *load.seat_moment_n_m);
    if (load.longitudinal_force_n) write_time_function(out, "loading.longitudinal_force_n", *load.longitudinal_force_n);
    if (load.seat_rotation_rad) write_time_function(out, "loading.seat_rotation_rad", *load.seat_rotation_rad);

    out << "\n[mesh]\n";
    top.num("element_length_m", m.mesh.element_length_m);
    top.word("symmetry", word_of(m.symmetry));

    if (m.probe) {
        out << "\n[probe]\n";
        top.integer("interface_index", m.probe->interface_index);
        top.num("x_m", m.probe->x_m);
    }

    write_integrator(out, s.simulation);

    const ScenarioOutputs& o = s.outputs;
    if (!o.csv_path.empty() || !o.events_path.empty() || !o.summary_path.empty() || !o.pairs_path.empty() ||
        !o.nodes_path.empty() || !o.plot_prefix.empty() || !o.stresses_path.empty()) {
        out << "\n[outputs]\n";
        for (const auto& [key, value] : {std::pair<const char*, const std::string*>{"csv_path", &o.csv_path},
                                         {"events_path", &o.events_path},
                                         {"summary_path", &o.summary_path},
                                         {"pairs_path", &o.pairs_path},
                                         {"nodes_path", &o.nodes_path},
                                         {"plot_prefix", &o.plot_prefix},
                                         {"stresses_path", &o.stresses_path}})
            if (!value->empty()) top.word(key, *value);
    }
    return out.str();
}

}  // namespace stackbeam
