// Scenario files (TOML, read with toml11): every key checked, errors name the
// key's path in the file. Format: docs/model-and-scenarios.md.
#include "stackbeam/io/scenario.hpp"
#include "toml_text.hpp"

#include <toml.hpp>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <utility>
#include <vector>

#include "stackbeam/errors.hpp"
#include "stackbeam/time/option_table.hpp"

namespace stackbeam {

STACKBEAM_ENUM_WORDS(InterfaceLawWord, {InterfaceLawWord::coulomb, "coulomb"},
    {InterfaceLawWord::frictionless, "frictionless"}, {InterfaceLawWord::bonded, "bonded"})

namespace {

const char* type_name(const toml::value& v) {
    switch (v.type()) {
        case toml::value_t::boolean: return "a boolean";
        case toml::value_t::integer: return "an integer";
        case toml::value_t::floating: return "a float";
        case toml::value_t::string: return "a string";
        case toml::value_t::offset_datetime:
        case toml::value_t::local_datetime:
        case toml::value_t::local_date:
        case toml::value_t::local_time: return "a date/time";
        case toml::value_t::array: return "an array";
        case toml::value_t::table: return "a table";
        case toml::value_t::empty: return "empty";
    }
    return "unknown";
}

std::string join(const std::vector<std::string>& items) {
    std::string out;
    for (const auto& s : items) out += (out.empty() ? "" : ", ") + s;
    return out;
}

/// Shared state of one parse: the source name and where each key path is.
class Context {
public:
    explicit Context(std::string source, std::map<std::string, std::string> locations = {})
        : source_(std::move(source)), locations_(std::move(locations)) {}

    std::string where(const toml::value& v) const {
        const auto loc = v.location();
        return source_ + ":" + std::to_string(loc.line()) + ":" + std::to_string(loc.column());
    }
    void remember(const std::string& path, const toml::value& v) { locations_[path] = where(v); }
    /// Location of `path` or of its nearest remembered parent ("" if none).
    std::string location_of(std::string path) const {
        while (!path.empty()) {
            const auto it = locations_.find(path);
            if (it != locations_.end()) return it->second;
            const auto cut = path.find_last_of(".[");
            if (cut == std::string::npos) break;
            path.erase(cut);
        }
        return source_;
    }
    [[noreturn]] void fail(const std::string& path, const std::string& message) const {
        throw InputError(path, message, location_of(path));
    }
    const std::string& source() const noexcept { return source_; }
    const std::map<std::string, std::string>& locations() const noexcept { return locations_; }

private:
    std::string source_;
    std::map<std::string, std::string> locations_;
};

std::string child(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }
std::string element(const std::string& path, std::size_t i) { return path + "[" + std::to_string(i) + "]"; }

/// A TOML table whose keys are all checked against a list of allowed keys.
class Table {
public:
    Table(Context& ctx, const toml::value& v, std::string path, std::vector<std::string> allowed)
        : ctx_(ctx), v_(v), path_(std::move(path)), allowed_(std::move(allowed)) {
        if (!v.is_table())
            ctx_.fail(path_.empty() ? "(top level)" : path_,
                      std::string("is ") + type_name(v) + ": must be a table (keys " + join(allowed_) + ")");
        if (!path_.empty()) ctx_.remember(path_, v);
        std::vector<std::string> keys;
        for (const auto& kv : v.as_table()) keys.push_back(kv.first);
        std::sort(keys.begin(), keys.end());
        for (const auto& k : keys) {
            ctx_.remember(child(path_, k), v.as_table().at(k));
            if (std::find(allowed_.begin(), allowed_.end(), k) == allowed_.end())
                ctx_.fail(child(path_, k), "unknown key '" + k + "'" + (path_.empty() ? "" : " in " + path_) +
                                               ": allowed keys are " + join(allowed_));
        }
    }

    const std::string& path() const noexcept { return path_; }
    Context& context() const noexcept { return ctx_; }
    bool has(const std::string& key) const { return v_.as_table().count(key) > 0; }
    const toml::value& at(const std::string& key) const { return v_.as_table().at(key); }

    [[noreturn]] void missing(const std::string& key, const std::string& what) const {
        ctx_.fail(child(path_, key), "required key is missing: " + what);
    }

    /// A number (an integer or a float); required unless a default is given.
    double number(const std::string& key, const std::string& what, const double* fallback = nullptr) const {
        if (!has(key)) {
            if (fallback) return *fallback;
            missing(key, what);
        }
        const auto& v = at(key);
        if (v.is_floating()) return v.as_floating();
        if (v.is_integer()) return static_cast<double>(v.as_integer());
        wrong_type(key, v, "a number: " + what);
    }
    double number_or(const std::string& key, const std::string& what, double fallback) const {
        return number(key, what, &fallback);
    }

    /// An integer in [lo, hi]; required unless a default is given.
    long long integer(const std::string& key, const std::string& what, long long lo, long long hi,
                      const long long* fallback = nullptr) const {
        if (!has(key)) {
            if (fallback) return *fallback;
            missing(key, what);
        }
        const auto& v = at(key);
        if (!v.is_integer()) wrong_type(key, v, "an integer: " + what);
        const long long x = v.as_integer();
        if (x < lo || x > hi)
            ctx_.fail(child(path_, key), "value " + std::to_string(x) + " is not allowed: " + what);
        return x;
    }

    std::string string(const std::string& key, const std::string& what, const std::string* fallback = nullptr) const {
        if (!has(key)) {
            if (fallback) return *fallback;
            missing(key, what);
        }
        const auto& v = at(key);
        if (!v.is_string()) wrong_type(key, v, "a string: " + what);
        return v.as_string().str;
    }
    std::string string_or(const std::string& key, const std::string& what, const std::string& fallback) const {
        return string(key, what, &fallback);
    }

    /// An array of numbers; required.
    std::vector<double> numbers(const std::string& key, const std::string& what) const {
        if (!has(key)) missing(key, what);
        const auto& v = at(key);
        if (!v.is_array()) wrong_type(key, v, "an array of numbers: " + what);
        std::vector<double> out;
        const auto& a = v.as_array();
        for (std::size_t i = 0; i < a.size(); ++i) {
            const std::string path = element(child(path_, key), i);
            ctx_.remember(path, a[i]);
            if (a[i].is_floating()) out.push_back(a[i].as_floating());
            else if (a[i].is_integer()) out.push_back(static_cast<double>(a[i].as_integer()));
            else ctx_.fail(path, std::string("has the wrong type, ") + type_name(a[i]) + ": must be a number: " + what);
        }
        return out;
    }

    /// A required sub-table (check has() first for an optional one).
    Table table(const std::string& key, std::vector<std::string> allowed) const {
        if (!has(key)) missing(key, "a table [" + child(path_, key) + "] with keys " + join(allowed));
        return Table(ctx_, at(key), child(path_, key), std::move(allowed));
    }

    /// An array of tables ([[key]]); empty when absent and not required.
    const toml::array* array(const std::string& key, const std::string& what, bool required) const {
        if (!has(key)) {
            if (required) missing(key, what);
            return nullptr;
        }
        const auto& v = at(key);
        if (!v.is_array()) wrong_type(key, v, "an array: " + what);
        return &v.as_array();
    }

    [[noreturn]] void wrong_type(const std::string& key, const toml::value& v, const std::string& expected) const {
        ctx_.fail(child(path_, key), std::string("has the wrong type, ") + type_name(v) + ": must be " + expected);
    }

private:
    Context& ctx_;
    const toml::value& v_;
    std::string path_;
    std::vector<std::string> allowed_;
};

/// A keyword value out of the enum's word table (words.hpp); `fallback` when the key is absent
/// (nullptr: required).
template <class E>
E choice(const Table& t, const std::string& key, const E* fallback) {
    const std::string what = "one of " + word_list<E>("'");
    if (!t.has(key) && fallback) return *fallback;
    const std::string text = t.string(key, what);
    if (const auto value = find_word<E>(text)) return *value;
    t.context().fail(child(t.path(), key), "value '" + text + "' is not allowed: must be " + what);
}

// ---------------------------------------------------------------------------------------

/// The file's key path of a field named by Model::build or SimulationOptions::validate:
/// the option table's key for an option (option_table.hpp), else the model's path.
std::string file_path_of(const std::string& field) {
    if (const OptionSpec* spec = find_option_by_member(field)) return spec->key;
    static const std::pair<const char*, const char*> exact[] = {
        {"rigid_body.initial_displacement_m", "loading.initial_displacement_m"},
        {"rigid_body.initial_velocity_m_per_s", "loading.initial_velocity_m_per_s"},
    };
    for (const auto& [from, to] : exact)
        if (field == from) return to;
    // the solver's options outside the table (SolverOptions::max_active_set_iterations ...)
    const std::string solver = "solver.";
    if (field.compare(0, solver.size(), solver) == 0) return "integrator." + field;
    // "interfaces[i].leaves" (adjacent leaves do not overlap): the interface itself
    const std::string suffix = ".leaves";
    if (field.rfind("interfaces[", 0) == 0 && field.size() > suffix.size() &&
        field.compare(field.size() - suffix.size(), suffix.size(), suffix) == 0)
        return field.substr(0, field.size() - suffix.size());
    return field;
}

/// Rethrows `e` (from the library's validation) with the file's key path and location.
[[noreturn]] void rethrow_in_file(const Context& ctx, const InputError& e) {
    const std::string prefix = e.field() + ": ";
    std::string message = e.what();
    if (message.rfind(prefix, 0) == 0) message = message.substr(prefix.size());
    ctx.fail(file_path_of(e.field()), message);
}


/// [leaves.profile] and [leaves.left_end] / [leaves.right_end] (ranges: Model::build).
void parse_profile_and_ends(const Table& t, LeafSpec& l) {
    if (t.has("profile")) {
        const Table p = t.table("profile", {"x_m", "thickness_m", "width_m"});
        l.profile.x_m = p.numbers("x_m", "the profile's points from the leaf's left end [m]: 0, ..., length_m");
        if (p.has("thickness_m")) l.profile.thickness_m = p.numbers("thickness_m", "the thickness at each point [m], > 0");
        if (p.has("width_m")) l.profile.width_m = p.numbers("width_m", "the width at each point [m], > 0");
    }
    for (const auto& [key, end] : {std::pair<const char*, LeafEndSpec*>{"left_end", &l.left_end}, {"right_end", &l.right_end}}) {
        if (!t.has(key)) continue;
        const Table e = t.table(key, {"eye_offset_m", "shackle_angle_rad", "bushing_x_n_per_m", "bushing_y_n_per_m",
                                      "bushing_rotation_n_m_per_rad"});
        end->eye_offset_m = e.number_or("eye_offset_m", "the eye centre above the leaf's axis [m]", 0.0);
        end->shackle_angle_rad = e.number_or("shackle_angle_rad", "the link from the vertical [rad]", 0.0);
        end->bushing_x_n_per_m = e.number_or("bushing_x_n_per_m", "the axial bushing stiffness [N/m], >= 0", 0.0);
        end->bushing_y_n_per_m = e.number_or("bushing_y_n_per_m", "the transverse bushing stiffness [N/m], >= 0", 0.0);
        end->bushing_rotation_n_m_per_rad =
            e.number_or("bushing_rotation_n_m_per_rad", "the rotational bushing stiffness [N m/rad], >= 0", 0.0);
    }
}

/// A fatigue material table, [material] or [leaves.material] (model.hpp, FatigueMaterial;
/// ranges: validate_fatigue_material). A strength given as 0 is refused here: 0 stands for
/// "not given" in the spec, so the file says that by leaving the key out.
FatigueMaterial parse_material(const Table& parent, const std::string& key) {
    const Table t = parent.table(key, {"ultimate_strength_pa", "yield_strength_pa", "endurance_limit_pa",
                                       "fatigue_strength_coefficient_pa", "fatigue_strength_exponent",
                                       "mean_stress_correction"});
    auto optional = [&](const char* k, const char* what) {
        const double v = t.number_or(k, what, 0.0);
        if (t.has(k) && v == 0.0)
            t.context().fail(child(t.path(), k), std::string("value 0 is not allowed: ") + what + " (leave the key out when not given)");
        return v;
    };
    FatigueMaterial m;
    m.ultimate_strength_pa = t.number("ultimate_strength_pa", "the ultimate tensile strength S_u [Pa], > 0");
    m.yield_strength_pa = optional("yield_strength_pa", "the yield strength S_y [Pa], > 0");
    m.endurance_limit_pa = optional("endurance_limit_pa", "the endurance limit S_e [Pa], > 0");
    m.fatigue_strength_coefficient_pa = optional("fatigue_strength_coefficient_pa", "Basquin's sigma_f' [Pa], > 0");
    m.fatigue_strength_exponent = optional("fatigue_strength_exponent", "Basquin's exponent b [-], in (-1, 0)");
    const MeanStressCorrection goodman = MeanStressCorrection::goodman;
    m.mean_stress_correction = choice<MeanStressCorrection>(t, "mean_stress_correction", &goodman);
    return m;
}

void parse_leaves(const Table& top, ModelSpec& spec) {
    const auto* arr = top.array("leaves", "the leaves, [[leaves]] tables from the top of the stack down", true);
    const std::vector<std::string> keys = {"length_m",         "x_start_m",    "height_m",     "width_m",
                                           "youngs_modulus_pa", "density_kg_per_m3", "poisson_ratio", "left_support",
                                           "right_support", "profile", "left_end", "right_end", "free_camber_m",
                                           "free_radius_m", "material"};
    for (std::size_t i = 0; i < arr->size(); ++i) {
        Table t(top.context(), (*arr)[i], element("leaves", i), keys);
        LeafSpec l;
        l.length_m = t.number("length_m", "the leaf length [m], > 0");
        l.x_start_m = t.number_or("x_start_m", "x of the leaf's left end [m]", 0.0);
        parse_profile_and_ends(t, l);  // height_m / width_m optional with a profile of them
        l.height_m = l.profile.thickness_m.empty() ? t.number("height_m", "the leaf thickness [m], > 0")
                                                   : t.number_or("height_m", "the leaf thickness [m], > 0", 0.0);
        l.width_m = l.profile.width_m.empty() ? t.number("width_m", "the leaf width [m], > 0")
                                              : t.number_or("width_m", "the leaf width [m], > 0", 0.0);
        l.youngs_modulus_pa = t.number("youngs_modulus_pa", "Young's modulus [Pa], > 0");
        l.density_kg_per_m3 = t.number_or("density_kg_per_m3", "density [kg/m^3], >= 0", 0.0);
        l.poisson_ratio = t.number_or("poisson_ratio", "Poisson's ratio [-], in (-1, 0.5)", LeafSpec{}.poisson_ratio);
        const SupportKind free = SupportKind::free;
        l.left_support = choice(t, "left_support", &free);
        l.right_support = choice(t, "right_support", &free);
        l.free_camber_m = t.number_or("free_camber_m", "the free arc height [m], + ends up (0: flat)", 0.0);
        l.free_radius_m = t.number_or("free_radius_m", "the free radius [m], + ends up (0: flat)", 0.0);
        if (t.has("material")) l.material = parse_material(t, "material");
        spec.leaves.push_back(l);
    }
    // [material]: the leaves' shared fatigue strength, for every leaf without its own
    // [leaves.material] (which replaces it whole); checked here, under the key path as written
    if (!top.has("material")) return;
    const FatigueMaterial shared = parse_material(top, "material");
    try {
        validate_fatigue_material(shared, "material");
    } catch (const InputError& e) {
        rethrow_in_file(top.context(), e);
    }
    for (LeafSpec& l : spec.leaves)
        if (!l.material) l.material = shared;
}

void parse_interfaces(const Table& top, ModelSpec& spec) {
    const auto* arr = top.array("interfaces", "one [[interfaces]] table per pair of adjacent leaves", spec.leaves.size() > 1);
    if (!arr) return;
    using Law = InterfaceLawWord;
    for (std::size_t i = 0; i < arr->size(); ++i) {
        Table t(top.context(), (*arr)[i], element("interfaces", i),
                {"law", "friction_coefficient", "initial_gap_m", "contact", "normal_stiffness_pa_per_m",
                 "tangential_stiffness_pa_per_m"});
        InterfaceSpec f;
        const Law law = choice<Law>(t, "law", nullptr);
        if (law == Law::coulomb) {
            f.law = InterfaceLaw::coulomb;
            f.friction_coefficient = t.number("friction_coefficient", "the Coulomb coefficient mu [-], >= 0 (law 'coulomb')");
        } else {
            if (t.has("friction_coefficient"))
                t.context().fail(child(t.path(), "friction_coefficient"),
                                 std::string("is not allowed with law '") + word_of(law) +
                                     "': only law 'coulomb' takes a friction coefficient");
            f.law = law == Law::bonded ? InterfaceLaw::bonded : InterfaceLaw::coulomb;
            f.friction_coefficient = 0.0;
        }
        f.initial_gap_m = t.number_or("initial_gap_m", "the initial normal gap [m], finite; < 0 an interference, closed by the assembly", 0.0);
        if (t.has("contact")) {
            const std::string text = t.string("contact", "one of " + word_list<InterfaceContact>("'"));
            try {
                f.contact = parse_interface_contact(text, child(t.path(), "contact"));
            } catch (const InputError& e) {
                rethrow_in_file(t.context(), e);  // with the key's place in the file
            }
        }
        // range and "needs contact = 'elastic'": Model::build, reported at the key's line
        f.normal_stiffness_pa_per_m = t.number_or(
            "normal_stiffness_pa_per_m", "the elastic layer's normal stiffness per unit area k_n [Pa/m], >= 0 (0: derived)", 0.0);
        f.tangential_stiffness_pa_per_m =
            t.number_or("tangential_stiffness_pa_per_m",
                        "the elastic layer's tangential stiffness per unit area k_t [Pa/m], >= 0 (0: derived)", 0.0);
        spec.interfaces.push_back(f);
    }
}

void parse_clamps(const Table& top, ModelSpec& spec) {
    const auto* arr = top.array("clamps", "[[clamps]] tables", false);
    if (!arr) return;
    for (std::size_t i = 0; i < arr->size(); ++i) {
        Table t(top.context(), (*arr)[i], element("clamps", i), {"x_m", "preload_n", "length_m"});
        ClampSpec c;
        c.x_m = t.number("x_m", "the clamp position [m]");
        c.preload_n = t.number_or("preload_n", "the clamp force [N], >= 0", 0.0);
        c.length_m = t.number_or("length_m", "the clamp's length along x [m], >= 0 (0: a point tie)", 0.0);
        spec.clamps.push_back(c);
    }
}

void parse_clips(const Table& top, ModelSpec& spec) {
    const auto* arr = top.array("clips", "[[clips]] tables (rebound clips)", false);
    if (!arr) return;
    for (std::size_t i = 0; i < arr->size(); ++i) {
        Table t(top.context(), (*arr)[i], element("clips", i), {"x_m", "first_leaf", "last_leaf", "clearance_m", "stiffness_n_per_m"});
        ClipSpec c;
        c.x_m = t.number("x_m", "the clip position [m]");
        const long long n = static_cast<long long>(spec.leaves.size());  // the range against the stack: Model::build
        c.first_leaf = static_cast<int>(t.integer("first_leaf", "a leaf index 0.." + std::to_string(n - 2), 0, n - 2));
        c.last_leaf = static_cast<int>(t.integer("last_leaf", "a leaf index 1.." + std::to_string(n - 1), 1, n - 1));
        c.clearance_m = t.number("clearance_m", "the opening the clip allows [m], > 0");
        c.stiffness_n_per_m = t.number_or("stiffness_n_per_m", "the strap's stiffness [N/m], > 0", ClipSpec{}.stiffness_n_per_m);
        spec.clips.push_back(c);
    }
}

void parse_rigid_body(const Table& top, ModelSpec& spec) {
    const Table t = top.table("rigid_body", {"mass_kg", "x_m", "tied_leaves", "pitch_inertia_kg_m2", "axial"});
    spec.rigid_body.mass_kg = t.number("mass_kg", "the mass [kg], > 0");
    spec.rigid_body.x_m = t.number("x_m", "the attachment position [m]");
    spec.rigid_body.pitch_inertia_kg_m2 =
        t.number_or("pitch_inertia_kg_m2", "the axle's pitch inertia about the seat [kg m^2], >= 0", 0.0);
    const SeatAxial automatic = SeatAxial::automatic;
    spec.rigid_body.axial = choice<SeatAxial>(t, "axial", &automatic);
    if (t.has("tied_leaves")) {
        const auto& v = t.at("tied_leaves");
        if (!v.is_array()) t.wrong_type("tied_leaves", v, "an array of leaf indices");
        const auto& arr = v.as_array();
        for (std::size_t k = 0; k < arr.size(); ++k) {
            const std::string path = element("rigid_body.tied_leaves", k);
            t.context().remember(path, arr[k]);
            if (!arr[k].is_integer())
                t.context().fail(path, std::string("has the wrong type, ") + type_name(arr[k]) + ": must be an integer leaf index");
            const long long x = arr[k].as_integer();
            if (x < 0 || x >= static_cast<long long>(spec.leaves.size()))
                t.context().fail(path, "value " + std::to_string(x) + " is not a leaf index: allowed 0.." +
                                           std::to_string(static_cast<long long>(spec.leaves.size()) - 1));
            spec.rigid_body.tied_leaves.push_back(static_cast<int>(x));
        }
    }
}

/// A time function `[loading.<key>]` (loading.hpp, TimeFunction); `unit` for messages.
TimeFunction parse_time_function(const Table& parent, const std::string& key, const std::string& unit) {
    const Table t = parent.table(key, {"shape", "mean", "amplitude", "frequency_hz", "phase_rad", "times_s", "values"});
    using S = TimeFunction::Shape;
    TimeFunction f;
    f.shape = choice<S>(t, "shape", nullptr);
    auto only = [&](const std::string& k, bool allowed) {
        if (t.has(k) && !allowed)
            t.context().fail(child(t.path(), k), "is not used by shape '" + std::string(to_string(f.shape)) +
                                                     "': remove it (constant: mean; harmonic, triangle: mean, amplitude, "
                                                     "frequency_hz, phase_rad; table: times_s, values)");
    };
    const bool periodic = f.shape == S::harmonic || f.shape == S::triangle;
    only("mean", f.shape != S::table);
    only("amplitude", periodic);
    only("frequency_hz", periodic);
    only("phase_rad", periodic);
    only("times_s", f.shape == S::table);
    only("values", f.shape == S::table);
    if (f.shape == S::constant) f.mean = t.number("mean", "the value [" + unit + "]");
    if (periodic) {
        f.mean = t.number_or("mean", "the offset [" + unit + "]", 0.0);
        f.amplitude = t.number("amplitude", "the amplitude [" + unit + "], >= 0");
        f.frequency_hz = t.number("frequency_hz", "the frequency [Hz], > 0");
        f.phase_rad = t.number_or("phase_rad", "the phase [rad]", 0.0);
    }
    if (f.shape == S::table) {
        f.times_s = t.numbers("times_s", "the times [s], strictly increasing");
        f.values = t.numbers("values", "the values [" + unit + "], one per time");
    }
    return f;
}

Loading parse_loading(const Table& top, ModelSpec& spec) {
    const Table t = top.table("loading", {"kind", "initial_displacement_m", "initial_velocity_m_per_s", "gravity_m_per_s2",
                                          "force_n", "displacement_m", "seat_moment_n_m", "longitudinal_force_n",
                                          "longitudinal_force_height_m", "seat_rotation_rad"});
    Loading l;
    l.kind = choice<LoadingKind>(t, "kind", nullptr);
    spec.rigid_body.initial_displacement_m = t.number_or("initial_displacement_m", "w(0) [m]", 0.0);
    spec.rigid_body.initial_velocity_m_per_s = t.number_or("initial_velocity_m_per_s", "dw/dt(0) [m/s]", 0.0);
    l.gravity_m_per_s2 = t.number_or("gravity_m_per_s2", "g [m/s^2], >= 0, acting in -y", 0.0);
    const bool force = l.kind == LoadingKind::applied_force;
    const bool disp = l.kind == LoadingKind::prescribed_displacement || l.kind == LoadingKind::base_excitation;
    if (t.has("force_n") && !force)
        t.context().fail("loading.force_n", "is only used with kind = 'applied-force' (kind is '" +
                                                std::string(to_string(l.kind)) + "')");
    if (t.has("displacement_m") && !disp)
        t.context().fail("loading.displacement_m",
                         "is only used with kind = 'prescribed-displacement' or 'base-excitation' (kind is '" +
                             std::string(to_string(l.kind)) + "')");
    if (force) l.force_n = parse_time_function(t, "force_n", "N");
    if (disp) l.displacement_m = parse_time_function(t, "displacement_m", "m");
    // seat loads and the windup rig (loading.hpp)
    if (t.has("seat_moment_n_m")) l.seat_moment_n_m = parse_time_function(t, "seat_moment_n_m", "N m");
    if (t.has("longitudinal_force_n")) l.longitudinal_force_n = parse_time_function(t, "longitudinal_force_n", "N");
    l.longitudinal_force_height_m =
        t.number_or("longitudinal_force_height_m", "the longitudinal force's height above the seat [m]", 0.0);
    if (t.has("seat_rotation_rad")) l.seat_rotation_rad = parse_time_function(t, "seat_rotation_rad", "rad");
    return l;
}

void parse_mesh(const Table& top, ModelSpec& spec) {
    const Table t = top.table("mesh", {"element_length_m", "symmetry"});
    spec.mesh.element_length_m = t.number("element_length_m", "the largest element length [m], > 0");
    const Symmetry full = Symmetry::full;
    spec.symmetry = choice<Symmetry>(t, "symmetry", &full);
}

void parse_probe(const Table& top, ModelSpec& spec) {
    if (!top.has("probe")) return;
    const Table t = top.table("probe", {"interface_index", "x_m"});
    ProbeSpec p;
    p.interface_index = static_cast<int>(t.integer("interface_index", "the interface index, 0.." +
                                                                          std::to_string(static_cast<long long>(spec.leaves.size()) - 2),
                                                   0, std::numeric_limits<int>::max()));
    p.x_m = t.number("x_m", "the probe position [m]");
    spec.probe = p;
}

/// [integrator], [integrator.solver], [integrator.cvode], [integrator.damping]: the keys of the option table
/// (option_table.hpp) under "integrator.", each checked by its row as it is read.
void parse_integrator(const Table& top, SimulationOptions& o) {
    const std::string prefix = "integrator.";
    std::map<std::string, std::vector<std::string>> keys = {  // table path -> its allowed keys
        {"integrator", {}}, {"integrator.solver", {}}, {"integrator.cvode", {}}, {"integrator.damping", {}}};
    for (const OptionSpec& spec : simulation_option_table()) {
        const std::string key = spec.key;
        if (key.compare(0, prefix.size(), prefix) != 0) continue;
        const auto cut = key.find_last_of('.');
        keys[key.substr(0, cut)].push_back(key.substr(cut + 1));
    }
    keys["integrator"].insert(keys["integrator"].end(), {"solver", "cvode", "damping"});
    const Table t = top.table("integrator", keys["integrator"]);
    for (const char* required : {"mode", "dt_s", "t_end_s"})
        if (!t.has(required)) t.missing(required, find_option_by_member(required)->help);
    std::map<std::string, Table> tables;
    tables.emplace("integrator", t);
    for (const char* sub : {"solver", "cvode", "damping"})
        if (t.has(sub)) tables.emplace(prefix + sub, t.table(sub, keys[prefix + sub]));
    for (const OptionSpec& spec : simulation_option_table()) {
        const std::string key = spec.key;
        if (key.compare(0, prefix.size(), prefix) != 0) continue;
        const auto cut = key.find_last_of('.');
        const auto table = tables.find(key.substr(0, cut));
        const std::string leaf = key.substr(cut + 1);
        if (table == tables.end() || !table->second.has(leaf)) continue;  // the default stays
        const Table& in = table->second;
        try {
            if (spec.type == OptionSpec::Type::keyword) {
                spec.set_word(o, in.string(leaf, spec.allowed()), spec.member);
                continue;
            }
            const double v = spec.type == OptionSpec::Type::integer
                                 ? static_cast<double>(in.integer(leaf, spec.allowed(), std::numeric_limits<long long>::min(),
                                                                  std::numeric_limits<long long>::max()))
                                 : in.number(leaf, spec.allowed());
            check_option(spec, v);
            spec.set(o, v);
        } catch (const InputError& e) {
            if (e.field() == spec.key) throw;  // from Table: already with the key and its location
            rethrow_in_file(t.context(), e);
        }
    }
}

void parse_outputs(const Table& top, ScenarioOutputs& out) {
    if (!top.has("outputs")) return;
    const Table t = top.table("outputs", {"csv_path", "events_path", "summary_path", "pairs_path", "nodes_path", "plot_prefix",
                                         "stresses_path"});
    auto path = [&](const char* key, const char* what) {
        if (!t.has(key)) return std::string();
        const std::string p = t.string(key, what);
        if (p.empty()) t.context().fail(child("outputs", key), "is empty: must be a file name (" + std::string(what) + ")");
        return p;
    };
    out.csv_path = path("csv_path", "the per-step CSV");
    out.events_path = path("events_path", "the event log");
    out.summary_path = path("summary_path", "the JSON summary");
    out.pairs_path = path("pairs_path", "the per-pair CSV");
    out.nodes_path = path("nodes_path", "the nodal displacements' CSV");
    out.plot_prefix = path("plot_prefix", "the prefix of the PNG figures");
    out.stresses_path = path("stresses_path", "the leaves' stresses' CSV");
}

/// The TOML parser recurses into nested arrays and inline tables, so a file of
/// thousands of '[' would overflow the stack: refuse nesting deeper than a scenario
/// ever needs before parsing. Scans brackets outside strings and comments.
void check_nesting(const std::string& text, const std::string& source_name) {
    constexpr int kMaxDepth = 32;
    int depth = 0, line = 1;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (c == '\n') {
            ++line;
        } else if (c == '#') {
            while (i + 1 < text.size() && text[i + 1] != '\n') ++i;
        } else if (c == '"' || c == '\'') {
            const bool multi = text.compare(i, 3, std::string(3, c)) == 0;
            const std::string close = multi ? std::string(3, c) : std::string(1, c);
            i += close.size();
            while (i < text.size() && text.compare(i, close.size(), close) != 0) {
                if (c == '"' && text[i] == '\\') ++i;  // an escape in a basic string
                else if (text[i] == '\n') {
                    ++line;
                    if (!multi) break;  // an unterminated string: the parser reports it
                }
                ++i;
            }
            i += close.size() - 1;
        } else if (c == '[' || c == '{') {
            if (++depth > kMaxDepth)
                throw InputError(source_name, "TOML syntax error: arrays or tables nested deeper than " +
                                                  std::to_string(kMaxDepth) + " levels at line " + std::to_string(line));
        } else if (c == ']' || c == '}') {
            depth = std::max(0, depth - 1);
        }
    }
}

/// TOML text must be UTF-8, and the TOML parser's own check of strings reads out of
/// bounds when it reports a bad sequence in a literal string (toml11 3.7.1, found by
/// fuzz/fuzz_scenario: fuzz/regressions/scenario/invalid-utf8-*): refuse any invalid
/// UTF-8 (RFC 3629: no overlong forms, no surrogates, nothing above U+10FFFF) before parsing.
void check_utf8(const std::string& text, const std::string& source_name) {
    int line = 1;
    std::size_t line_start = 0;
    for (std::size_t i = 0; i < text.size();) {
        const auto c = static_cast<unsigned char>(text[i]);
        std::size_t n = 0;  // continuation bytes
        unsigned lo = 0x80, hi = 0xBF;  // the allowed range of the first continuation byte
        if (c < 0x80) n = 0;
        else if (c >= 0xC2 && c <= 0xDF) n = 1;
        else if (c == 0xE0) n = 2, lo = 0xA0;
        else if (c >= 0xE1 && c <= 0xEC) n = 2;
        else if (c == 0xED) n = 2, hi = 0x9F;
        else if (c >= 0xEE && c <= 0xEF) n = 2;
        else if (c == 0xF0) n = 3, lo = 0x90;
        else if (c >= 0xF1 && c <= 0xF3) n = 3;
        else if (c == 0xF4) n = 3, hi = 0x8F;
        else n = 99;  // 0x80-0xC1, 0xF5-0xFF: never a first byte
        bool ok = n != 99;
        for (std::size_t k = 1; ok && k <= n; ++k) {
            if (i + k >= text.size()) {
                ok = false;
                break;
            }
            const auto b = static_cast<unsigned char>(text[i + k]);
            ok = k == 1 ? b >= lo && b <= hi : b >= 0x80 && b <= 0xBF;
        }
        if (!ok) {
            char byte[8];
            std::snprintf(byte, sizeof byte, "0x%02X", static_cast<unsigned>(c));
            throw InputError(source_name, "TOML syntax error: not UTF-8 text: byte " + std::string(byte) + " at line " +
                                              std::to_string(line) + ", column " + std::to_string(i - line_start + 1) +
                                              " is not a valid UTF-8 sequence (a TOML file must be UTF-8)");
        }
        if (c == '\n') {
            ++line;
            line_start = i + 1;
        }
        i += n + 1;
    }
}

}  // namespace

void detail::check_toml_text(const std::string& text, const std::string& source_name) {
    check_utf8(text, source_name);
    check_nesting(text, source_name);
}

Scenario parse_scenario(const std::string& text, const std::string& source_name) {
    Context ctx(source_name);
    detail::check_toml_text(text, source_name);
    toml::value root;
    try {
        std::istringstream in(text);
        root = toml::parse(in, source_name);
    } catch (const toml::syntax_error& e) {
        throw InputError(source_name, std::string("TOML syntax error:\n") + e.what());
    } catch (const std::exception& e) {
        throw InputError(source_name, std::string("cannot parse as TOML: ") + e.what());
    }

    Scenario s;
    s.source = source_name;
    const Table top(ctx, root, "",
                    {"description", "leaves", "interfaces", "clamps", "rigid_body", "loading", "mesh", "probe",
                     "integrator", "outputs", "clips", "material"});
    s.description = top.string_or("description", "free text", "");
    parse_leaves(top, s.model);
    parse_interfaces(top, s.model);
    parse_clamps(top, s.model);
    parse_clips(top, s.model);
    parse_rigid_body(top, s.model);
    const Loading loading = parse_loading(top, s.model);
    parse_mesh(top, s.model);
    parse_probe(top, s.model);
    parse_integrator(top, s.simulation);
    s.simulation.loading = loading;
    parse_outputs(top, s.outputs);

    try {
        Model::build(s.model);
        s.simulation.validate();
        require_loading_fits(s.model, s.simulation.loading);
    } catch (const InputError& e) {
        rethrow_in_file(ctx, e);
    }
    s.key_locations = ctx.locations();
    return s;
}

void rethrow_in_scenario(const Scenario& scenario, const InputError& e) {
    rethrow_in_file(Context(scenario.source, scenario.key_locations), e);
}

std::string detail::read_input_file(const std::string& path, const std::string& what, const std::string& field,
                                   const std::string& location, long long max_bytes) {
    auto refuse = [&](const std::string& why) -> InputError {
        const std::string message = what + " '" + path + "' " + why;
        return location.empty() ? InputError(field, message) : InputError(field, message, location);
    };
    // O_NONBLOCK: opening a FIFO with no writer would wait for one; the type is checked before any read
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) throw refuse(std::string("cannot be opened: ") + std::strerror(errno));
    struct Closer {
        int fd;
        ~Closer() { ::close(fd); }
    } closer{fd};
    struct stat st {};
    if (::fstat(fd, &st) != 0) throw refuse(std::string("cannot be examined: ") + std::strerror(errno));
    if (!S_ISREG(st.st_mode)) {
        const char* kind = S_ISDIR(st.st_mode)    ? "a directory"
                           : S_ISFIFO(st.st_mode) ? "a FIFO (named pipe)"
                           : S_ISCHR(st.st_mode)  ? "a character device"
                           : S_ISBLK(st.st_mode)  ? "a block device"
                           : S_ISSOCK(st.st_mode) ? "a socket"
                                                  : "not a regular file";
        throw refuse(std::string("is ") + kind + ": a regular file is required");
    }
    if (st.st_size > max_bytes)
        throw refuse("has " + std::to_string(static_cast<long long>(st.st_size)) + " bytes: at most " +
                     std::to_string(max_bytes) + " are read");
    std::string text;
    char buffer[65536];
    for (;;) {  // read to the end (the file may grow meanwhile: the cap holds for what is read)
        const ssize_t n = ::read(fd, buffer, sizeof buffer);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) throw refuse(std::string("cannot be read: ") + std::strerror(errno));
        if (n == 0) break;
        text.append(buffer, static_cast<std::size_t>(n));
        if (static_cast<long long>(text.size()) > max_bytes)
            throw refuse("has more than " + std::to_string(max_bytes) + " bytes: at most " + std::to_string(max_bytes) +
                         " are read");
    }
    return text;
}

Scenario load_scenario(const std::string& path) {
    return parse_scenario(detail::read_input_file(path, "the scenario file", path), path);
}

}  // namespace stackbeam
