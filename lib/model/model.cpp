#include "stackbeam/model/model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <sstream>

#include "model/assembly.hpp"
#include "stackbeam/errors.hpp"

namespace stackbeam {

STACKBEAM_ENUM_WORDS(SupportKind, {SupportKind::free, "free"}, {SupportKind::pinned, "pinned"},
    {SupportKind::fixed, "fixed"}, {SupportKind::hinged, "hinged"}, {SupportKind::shackle, "shackle"},
    {SupportKind::bushing, "bushing"})

STACKBEAM_ENUM_WORDS(InterfaceContact, {InterfaceContact::rigid, "rigid"}, {InterfaceContact::elastic, "elastic"})

STACKBEAM_ENUM_WORDS(Symmetry, {Symmetry::full, "full"}, {Symmetry::half, "half"})

STACKBEAM_ENUM_WORDS(SeatAxial, {SeatAxial::automatic, "auto"}, {SeatAxial::held, "held"}, {SeatAxial::free, "free"})

STACKBEAM_ENUM_WORDS(MeanStressCorrection, {MeanStressCorrection::goodman, "goodman"},
    {MeanStressCorrection::gerber, "gerber"}, {MeanStressCorrection::soderberg, "soderberg"},
    {MeanStressCorrection::morrow, "morrow"})

const char* to_string(SupportKind kind) { return word_of(kind); }
const char* to_string(InterfaceContact contact) { return word_of(contact); }
const char* to_string(MeanStressCorrection correction) { return word_of(correction); }
const char* to_string(SeatAxial axial) { return word_of(axial); }

namespace {
/// Whether an end support holds the stack axially through its eye (then the seat need not).
bool holds_axially(SupportKind s, const LeafEndSpec& e) {
    return s == SupportKind::hinged || (s == SupportKind::shackle && e.shackle_angle_rad != 0.0) ||
           (s == SupportKind::bushing && e.bushing_x_n_per_m > 0.0);
}
}  // namespace

bool ends_locate_axially(const ModelSpec& spec) {
    return std::any_of(spec.leaves.begin(), spec.leaves.end(), [](const LeafSpec& l) {
        return holds_axially(l.left_support, l.left_end) || holds_axially(l.right_support, l.right_end);
    });
}

bool seat_slides(const ModelSpec& spec) {
    if (spec.symmetry == Symmetry::half) return false;
    return spec.rigid_body.axial == SeatAxial::free ||
           (spec.rigid_body.axial == SeatAxial::automatic && ends_locate_axially(spec));
}

InterfaceContact parse_interface_contact(const std::string& text, const std::string& field) {
    if (const auto contact = find_word<InterfaceContact>(text)) return *contact;
    throw InputError(field, "value '" + text + "' is not allowed: must be " + word_list<InterfaceContact>("'", ", ", " or "));
}

namespace {
/// The profile's value at absolute x (linear between its points, clamped to its ends), or `constant`.
double profile_at(const LeafSpec& leaf, const std::vector<double>& values, double constant, double x) {
    const auto& px = leaf.profile.x_m;
    if (values.empty() || values.size() != px.size()) return constant;
    const double s = x - leaf.x_start_m;
    if (s <= px.front()) return values.front();
    if (s >= px.back()) return values.back();
    const std::size_t k = static_cast<std::size_t>(std::upper_bound(px.begin(), px.end(), s) - px.begin());
    const double f = (s - px[k - 1]) / (px[k] - px[k - 1]);
    return values[k - 1] + f * (values[k] - values[k - 1]);
}
}  // namespace

double leaf_thickness_m(const LeafSpec& leaf, double x_m) { return profile_at(leaf, leaf.profile.thickness_m, leaf.height_m, x_m); }
double leaf_width_m(const LeafSpec& leaf, double x_m) { return profile_at(leaf, leaf.profile.width_m, leaf.width_m, x_m); }

InterfaceLayer interface_layer(const ModelSpec& spec, int i, double x_m) {
    const LeafSpec& la = spec.leaves[static_cast<std::size_t>(i)];
    const LeafSpec& lb = spec.leaves[static_cast<std::size_t>(i) + 1];
    // the two leaves as constant sections of their thickness and width at x (a profile's local section)
    const double x = std::isnan(x_m) ? std::max(la.x_start_m, lb.x_start_m) : x_m;
    LeafSpec a = la, b = lb;
    a.height_m = leaf_thickness_m(la, x);
    a.width_m = leaf_width_m(la, x);
    b.height_m = leaf_thickness_m(lb, x);
    b.width_m = leaf_width_m(lb, x);
    const InterfaceSpec& f = spec.interfaces[static_cast<std::size_t>(i)];
    auto plane_strain = [](const LeafSpec& l) { return l.youngs_modulus_pa / (1.0 - l.poisson_ratio * l.poisson_ratio); };
    auto shear = [](const LeafSpec& l) { return l.youngs_modulus_pa / (2.0 * (1.0 + l.poisson_ratio)); };
    InterfaceLayer r;
    r.normal_stiffness_pa_per_m = f.normal_stiffness_pa_per_m > 0.0
                                      ? f.normal_stiffness_pa_per_m
                                      : 1.0 / (0.5 * a.height_m / plane_strain(a) + 0.5 * b.height_m / plane_strain(b));
    r.tangential_stiffness_pa_per_m = f.tangential_stiffness_pa_per_m > 0.0
                                          ? f.tangential_stiffness_pa_per_m
                                          : 1.0 / (0.5 * a.height_m / shear(a) + 0.5 * b.height_m / shear(b));
    r.contact_width_m = std::min(a.width_m, b.width_m);
    const double EIa = a.youngs_modulus_pa * a.width_m * a.height_m * a.height_m * a.height_m / 12.0;
    const double EIb = b.youngs_modulus_pa * b.width_m * b.height_m * b.height_m * b.height_m / 12.0;
    const double EIeq = EIa * EIb / (EIa + EIb);
    r.decay_length_m = std::pow(4.0 * EIeq / (r.normal_stiffness_pa_per_m * r.contact_width_m), 0.25);
    return r;
}

namespace {

std::string idx(const char* array, std::size_t i, const char* field) {
    std::ostringstream os;
    os << array << '[' << i << "]." << field;
    return os.str();
}

void require_positive(const std::string& field, double value, const char* unit) {
    if (!std::isfinite(value) || value <= 0.0)
        throw InputError(field, "value " + format_value(value) + " is not allowed: must be finite and > 0 " + unit);
}

void require_nonnegative(const std::string& field, double value, const char* unit) {
    if (!std::isfinite(value) || value < 0.0)
        throw InputError(field, "value " + format_value(value) + " is not allowed: must be finite and >= 0 " + unit);
}

void require_finite(const std::string& field, double value) {
    if (!std::isfinite(value))
        throw InputError(field, "value " + format_value(value) + " is not allowed: must be finite");
}

double leaf_end(const LeafSpec& leaf) { return leaf.x_start_m + leaf.length_m; }

/// leaves[i]: its thickness and width, constant (height_m, width_m) or a profile.
void validate_section(const LeafSpec& l, std::size_t i) {
    const LeafProfile& p = l.profile;
    const std::string pre = idx("leaves", i, "profile.");
    struct Part {
        const char *key, *pkey;
        const std::vector<double>& values;
        double constant;
    };
    for (const Part& part : {Part{"height_m", "thickness_m", p.thickness_m, l.height_m}, Part{"width_m", "width_m", p.width_m, l.width_m}}) {
        const char *key = part.key, *pkey = part.pkey;
        const std::vector<double>& values = part.values;
        const double constant = part.constant;
        if (values.empty()) {
            require_positive(idx("leaves", i, key), constant, "[m]");
            continue;
        }
        if (constant != 0.0)
            throw InputError(idx("leaves", i, key), "value " + format_value(constant) + " is given with " + pre + pkey +
                                                        ": give the leaf's " + pkey + " one way, the constant or the profile");
        if (values.size() != p.x_m.size())
            throw InputError(pre + pkey, "has " + std::to_string(values.size()) + " values: must have one per point of " +
                                             pre + "x_m (" + std::to_string(p.x_m.size()) + ")");
        for (std::size_t k = 0; k < values.size(); ++k)
            require_positive(pre + pkey + "[" + std::to_string(k) + "]", values[k], "[m]");
    }
    if (p.x_m.empty()) return;
    if (p.thickness_m.empty() && p.width_m.empty())
        throw InputError(pre + "x_m", "is given without thickness_m or width_m: a profile needs one of them");
    if (p.x_m.size() < 2)
        throw InputError(pre + "x_m", "has " + std::to_string(p.x_m.size()) + " point: a profile needs at least 2 (0 and the leaf's length)");
    const double tol = 1e-9 * l.length_m;
    for (std::size_t k = 0; k < p.x_m.size(); ++k) {
        const std::string f = pre + "x_m[" + std::to_string(k) + "]";
        const double x = p.x_m[k];
        require_finite(f, x);
        if (k == 0 && std::abs(x) > tol)
            throw InputError(f, "value " + format_value(x) + " is not allowed: the profile's first point must be 0 (the leaf's left end; x_m is measured from x_start_m)");
        if (k + 1 == p.x_m.size() && std::abs(x - l.length_m) > tol)
            throw InputError(f, "value " + format_value(x) + " is not allowed: the profile's last point must be the leaf's length " +
                                    format_value(l.length_m) + " m");
        if (k > 0 && !(x - p.x_m[k - 1] > tol))
            throw InputError(f, "value " + format_value(x) + " is not allowed: the points must increase (previous " +
                                    format_value(p.x_m[k - 1]) + " m)");
    }
}

/// leaves[i].<side>_end against its support kind.
void validate_end(SupportKind kind, const LeafEndSpec& e, std::size_t i, const char* side, bool half) {
    const std::string pre = idx("leaves", i, (std::string(side) + "_end.").c_str());
    const std::string support = idx("leaves", i, (std::string(side) + "_support").c_str());
    require_finite(pre + "eye_offset_m", e.eye_offset_m);
    require_finite(pre + "shackle_angle_rad", e.shackle_angle_rad);
    if (e.shackle_angle_rad != 0.0 && kind != SupportKind::shackle)
        throw InputError(pre + "shackle_angle_rad", "value " + format_value(e.shackle_angle_rad) + " is given but " + support +
                                                        " is '" + to_string(kind) + "': a shackle angle needs support 'shackle'");
    if (!(std::abs(e.shackle_angle_rad) < 2.0 * std::atan(1.0)))
        throw InputError(pre + "shackle_angle_rad", "value " + format_value(e.shackle_angle_rad) +
                                                        " is not allowed: must be in (-pi/2, pi/2) [rad] (from the vertical)");
    bool any = false;
    for (const auto& [key, k] : {std::pair<const char*, double>{"bushing_x_n_per_m", e.bushing_x_n_per_m},
                                 {"bushing_y_n_per_m", e.bushing_y_n_per_m},
                                 {"bushing_rotation_n_m_per_rad", e.bushing_rotation_n_m_per_rad}}) {
        require_nonnegative(pre + key, k, "[N/m, N m/rad]");
        if (k > 0.0 && kind != SupportKind::bushing)
            throw InputError(pre + key, "value " + format_value(k) + " is given but " + support + " is '" + to_string(kind) +
                                            "': a bushing stiffness needs support 'bushing'");
        any = any || k > 0.0;
    }
    if (kind == SupportKind::bushing && !any)
        throw InputError(pre + "bushing_y_n_per_m", "the support is 'bushing' but every bushing stiffness is 0: give one > 0");
    const bool plain = kind == SupportKind::free || kind == SupportKind::pinned || kind == SupportKind::fixed;
    if (half && (!plain || e.eye_offset_m != 0.0))
        throw InputError(plain ? pre + "eye_offset_m" : support,
                         "the half model takes supports 'free', 'pinned' or 'fixed' without an eye offset: use mesh.symmetry = 'full'");
}

/// The mesh's rule for close clamps (docs/model-and-scenarios.md, "Mesh"; decision 071): two
/// nodes a small fraction of element_length_m h apart make an element of length l << h whose
/// bending stiffness 12 EI / l^3 is (h / l)^3 times the others' (two clamps 0.35 mm apart on
/// h = 0.08 m: 1e7 times, 3e14 N/m), and the stack's equations then hold in double only to
/// eps |K| |z|, a round-off floor in every energy balance (decision 065). So two clamps closer
/// than kNodeMergeFraction h meet at their midpoint, one node: each moves by at most
/// kNodeMergeFraction h / 2 (5 mm on h = 0.1 m), and there they act as one clamp, their preloads
/// and lengths added (on an elastic interface the clamp's layer is its length's: the same area).
/// Only where neither clamp ties two leaves rigidly (every interface it crosses bonded, or
/// elastic and the clamp of a length > 0): two rigid ties l apart lock the leaves' relative slope there for any l > 0, and one
/// tie does not (measured on a two-leaf stack, clamps 0.35 mm apart: the rig's largest force 894 N
/// tied twice, 670 N once, on every mesh), so merging them would change the model's answer, not
/// its round-off. A clamp merges once (three within reach: the first two, by x); clamps on both
/// sides of the seat (rigid_body.x_m) stay apart (the half model mirrors them there); a clamp
/// near a leaf's end, a profile's breakpoint, a clip or the probe keeps its place (moving it onto
/// a leaf's end could change the interfaces it clamps).
constexpr double kNodeMergeFraction = 0.1;

/// Moves the clamps of `spec` by the rule above (the model's spec keeps the moved positions; the
/// clamps that meet at one point make one pair per interface). tol: the model's position
/// tolerance [m]. Returns one sentence per merge for Model::adjustments() (the user is told).
std::vector<std::string> merge_close_clamps(ModelSpec& spec, double tol) {
    const double reach = kNodeMergeFraction * spec.mesh.element_length_m;  // [m]
    // whether clamp c ties two leaves rigidly: it crosses an interface that is not bonded, rigid
    // or with c a point clamp (length 0: rigid on an elastic interface too)
    const auto rigid_tie = [&](const ClampSpec& c) {
        const auto present = [&](std::size_t leaf) {
            return c.x_m >= spec.leaves[leaf].x_start_m - tol && c.x_m <= leaf_end(spec.leaves[leaf]) + tol;
        };
        for (std::size_t i = 0; i + 1 < spec.leaves.size(); ++i)
            if (present(i) && present(i + 1) && spec.interfaces[i].law != InterfaceLaw::bonded &&
                (spec.interfaces[i].contact == InterfaceContact::rigid || c.length_m == 0.0))
                return true;
        return false;
    };
    std::vector<bool> merged(spec.clamps.size(), false);  // each clamp merges once: it moves by at most reach / 2
    std::vector<std::size_t> order(spec.clamps.size());
    for (std::size_t c = 0; c < order.size(); ++c) order[c] = c;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return spec.clamps[a].x_m < spec.clamps[b].x_m; });
    const double seat = spec.rigid_body.x_m;
    std::vector<std::string> notes;
    for (std::size_t k = 0; k + 1 < order.size(); ++k) {
        ClampSpec &a = spec.clamps[order[k]], &b = spec.clamps[order[k + 1]];
        const double gap = b.x_m - a.x_m;
        if (merged[order[k]] || gap <= tol || gap > reach) continue;
        if (a.x_m <= seat + tol && b.x_m >= seat - tol) continue;  // across (or at) the seat: the half model's mirror
        if (rigid_tie(a) || rigid_tie(b)) continue;
        const std::size_t i = std::min(order[k], order[k + 1]), j = std::max(order[k], order[k + 1]);
        const double xi = spec.clamps[i].x_m, xj = spec.clamps[j].x_m;
        a.x_m = b.x_m = 0.5 * (a.x_m + b.x_m);
        merged[order[k]] = merged[order[k + 1]] = true;
        const auto clamp = [](std::size_t c, double x) { return "clamps[" + std::to_string(c) + "] (x = " + format_value(x) + " m)"; };
        notes.push_back(clamp(i, xi) + " and " + clamp(j, xj) + ", " + format_value(gap) + " m apart, act as one clamp at x = " +
                        format_value(a.x_m) + " m, their preloads and lengths added: two clamps closer than a tenth of "
                        "mesh.element_length_m (" + format_value(reach) + " m of " + format_value(spec.mesh.element_length_m) +
                        " m) share a node, as an element that short would leave a round-off floor in every energy balance "
                        "(docs/model-and-scenarios.md, \"Mesh\"; a smaller element_length_m keeps them apart)");
    }
    return notes;
}
}  // namespace

void validate_fatigue_material(const FatigueMaterial& m, const std::string& path) {
    const std::string pre = path + ".";
    require_positive(pre + "ultimate_strength_pa", m.ultimate_strength_pa, "[Pa]");
    // the optional strengths: 0 is "not given", anything else finite and > 0
    for (const auto& [key, value] : {std::pair<const char*, double>{"yield_strength_pa", m.yield_strength_pa},
                                     {"endurance_limit_pa", m.endurance_limit_pa},
                                     {"fatigue_strength_coefficient_pa", m.fatigue_strength_coefficient_pa}})
        if (value != 0.0) require_positive(pre + key, value, "[Pa] (0 or absent: not given)");
    const double b = m.fatigue_strength_exponent;
    if (b != 0.0 && !(std::isfinite(b) && b > -1.0 && b < 0.0))
        throw InputError(pre + "fatigue_strength_exponent",
                         "value " + format_value(b) + " is not allowed: Basquin's exponent b must be in (-1, 0) [-] (steels about -0.05 to -0.12)");
    if ((b != 0.0) != (m.fatigue_strength_coefficient_pa != 0.0)) {
        const bool has_b = b != 0.0;
        throw InputError(pre + (has_b ? "fatigue_strength_coefficient_pa" : "fatigue_strength_exponent"),
                         std::string("required key is missing: the S-N curve sigma_a = sigma_f' (2N)^b needs both ") +
                             "fatigue_strength_coefficient_pa and fatigue_strength_exponent (" +
                             (has_b ? "fatigue_strength_exponent" : "fatigue_strength_coefficient_pa") + " is given)");
    }
    if (m.yield_strength_pa > m.ultimate_strength_pa)
        throw InputError(pre + "yield_strength_pa", "value " + format_value(m.yield_strength_pa) +
                                                        " is not allowed: must be <= ultimate_strength_pa (" +
                                                        format_value(m.ultimate_strength_pa) + " Pa)");
    if (m.endurance_limit_pa >= m.ultimate_strength_pa)
        throw InputError(pre + "endurance_limit_pa", "value " + format_value(m.endurance_limit_pa) +
                                                         " is not allowed: must be < ultimate_strength_pa (" +
                                                         format_value(m.ultimate_strength_pa) + " Pa)");
    if (m.endurance_limit_pa == 0.0 && !has_sn_curve(m))
        throw InputError(pre + "endurance_limit_pa",
                         "required key is missing: a fatigue material needs an endurance limit (endurance_limit_pa) or "
                         "an S-N curve (fatigue_strength_coefficient_pa and fatigue_strength_exponent), or both");
    if (m.mean_stress_correction == MeanStressCorrection::soderberg && m.yield_strength_pa == 0.0)
        throw InputError(pre + "yield_strength_pa", "required key is missing: mean_stress_correction 'soderberg' needs the yield strength");
    if (m.mean_stress_correction == MeanStressCorrection::morrow && m.fatigue_strength_coefficient_pa == 0.0)
        throw InputError(pre + "fatigue_strength_coefficient_pa",
                         "required key is missing: mean_stress_correction 'morrow' needs the fatigue strength coefficient sigma_f'");
}

bool Model::leaf_has_node(int leaf, int node) const {
    return node >= first_node_[leaf] && node <= last_node_[leaf];
}

namespace {

// Model::build's steps, in order: the checks of the spec (each InputError names the key), then
// the mesh (node_grid), the leaves' node ranges, the centroid heights and the candidate pairs.

/// Whether x [m] lies on leaves[leaf] (within the model's x tolerance of its ends).
using Present = std::function<bool(std::size_t, double)>;

/// Each leaf's fields (length, position, section, ends, material); returns the stack's extent
/// [x_min, x_max] [m].
std::pair<double, double> validate_leaves(const ModelSpec& spec) {
    const auto& leaves = spec.leaves;
    double x_min = std::numeric_limits<double>::infinity();
    double x_max = -x_min;
    for (std::size_t i = 0; i < leaves.size(); ++i) {
        const auto& l = leaves[i];
        require_positive(idx("leaves", i, "length_m"), l.length_m, "[m]");
        require_finite(idx("leaves", i, "x_start_m"), l.x_start_m);
        validate_section(l, i);
        validate_end(l.left_support, l.left_end, i, "left", spec.symmetry == Symmetry::half);
        validate_end(l.right_support, l.right_end, i, "right", spec.symmetry == Symmetry::half);
        require_positive(idx("leaves", i, "youngs_modulus_pa"), l.youngs_modulus_pa, "[Pa]");
        require_nonnegative(idx("leaves", i, "density_kg_per_m3"), l.density_kg_per_m3, "[kg/m^3]");
        if (!std::isfinite(l.poisson_ratio) || l.poisson_ratio <= -1.0 || l.poisson_ratio >= 0.5)
            throw InputError(idx("leaves", i, "poisson_ratio"),
                             "value " + format_value(l.poisson_ratio) + " is not allowed: must be in (-1, 0.5) [-]");
        if (l.material) validate_fatigue_material(*l.material, idx("leaves", i, "material"));
        x_min = std::min(x_min, l.x_start_m);
        x_max = std::max(x_max, leaf_end(l));
    }
    return {x_min, x_max};
}

/// One interface between each pair of adjacent leaves, its fields, and the leaves' overlap.
void validate_interfaces(const ModelSpec& spec, double tol) {
    const auto& leaves = spec.leaves;
    if (spec.interfaces.size() != leaves.size() - 1)
        throw InputError("interfaces", "has " + std::to_string(spec.interfaces.size()) +
                                           " entries: a stack of " + std::to_string(leaves.size()) +
                                           " leaves needs exactly " + std::to_string(leaves.size() - 1));
    for (std::size_t i = 0; i < spec.interfaces.size(); ++i) {
        const auto& f = spec.interfaces[i];
        require_nonnegative(idx("interfaces", i, "friction_coefficient"), f.friction_coefficient, "[-]");
        require_finite(idx("interfaces", i, "initial_gap_m"), f.initial_gap_m);  // < 0: an interference (assembly)
        for (const auto& [key, value] : {std::pair<const char*, double>{"normal_stiffness_pa_per_m", f.normal_stiffness_pa_per_m},
                                         {"tangential_stiffness_pa_per_m", f.tangential_stiffness_pa_per_m}}) {
            require_nonnegative(idx("interfaces", i, key), value, "[Pa/m] (0: derived from the leaves)");
            if (value > 0.0 && f.contact != InterfaceContact::elastic)
                throw InputError(idx("interfaces", i, key), "value " + format_value(value) +
                                                                " is given but interfaces[" + std::to_string(i) +
                                                                "].contact is 'rigid': a layer stiffness needs contact = 'elastic'");
        }
        const double lo = std::max(leaves[i].x_start_m, leaves[i + 1].x_start_m);
        const double hi = std::min(leaf_end(leaves[i]), leaf_end(leaves[i + 1]));
        if (hi - lo <= tol)
            throw InputError(idx("interfaces", i, "leaves"),
                             "leaves[" + std::to_string(i) + "] and leaves[" + std::to_string(i + 1) +
                                 "] do not overlap along x: adjacent leaves must touch over a positive length");
    }
}

/// The rigid body's fields; returns the leaves it ties, in increasing order (rigid_body.tied_leaves,
/// or every leaf present at its attachment x_m).
std::vector<int> validate_rigid_body(const ModelSpec& spec, const Present& present) {
    const auto& leaves = spec.leaves;
    const auto& rb = spec.rigid_body;
    require_positive("rigid_body.mass_kg", rb.mass_kg, "[kg]");
    require_finite("rigid_body.x_m", rb.x_m);
    require_finite("rigid_body.initial_displacement_m", rb.initial_displacement_m);
    require_finite("rigid_body.initial_velocity_m_per_s", rb.initial_velocity_m_per_s);
    require_nonnegative("rigid_body.pitch_inertia_kg_m2", rb.pitch_inertia_kg_m2, "[kg m^2]");
    std::vector<int> tied;
    if (rb.tied_leaves.empty()) {
        for (std::size_t i = 0; i < leaves.size(); ++i)
            if (present(i, rb.x_m)) tied.push_back(static_cast<int>(i));
        if (tied.empty())
            throw InputError("rigid_body.x_m", "value " + format_value(rb.x_m) +
                                                   " is off every leaf: the attachment must lie on a leaf");
        return tied;
    }
    for (std::size_t k = 0; k < rb.tied_leaves.size(); ++k) {
        const int leaf = rb.tied_leaves[k];
        const std::string field = "rigid_body.tied_leaves[" + std::to_string(k) + "]";
        if (leaf < 0 || leaf >= static_cast<int>(leaves.size()))
            throw InputError(field, "value " + std::to_string(leaf) + " is not a leaf index: allowed 0.." +
                                        std::to_string(leaves.size() - 1));
        if (!present(leaf, rb.x_m))
            throw InputError(field, "leaf " + std::to_string(leaf) + " does not reach the attachment x = " +
                                        format_value(rb.x_m) + " m");
        if (std::find(tied.begin(), tied.end(), leaf) != tied.end())
            throw InputError(field, "leaf " + std::to_string(leaf) + " is listed twice");
        tied.push_back(leaf);
    }
    std::sort(tied.begin(), tied.end());
    return tied;
}

/// Each clamp's fields, on an interface, at a position of its own.
void validate_clamps(const ModelSpec& spec, double tol, const Present& present) {
    for (std::size_t c = 0; c < spec.clamps.size(); ++c) {
        const auto& cl = spec.clamps[c];
        require_finite(idx("clamps", c, "x_m"), cl.x_m);
        require_nonnegative(idx("clamps", c, "preload_n"), cl.preload_n, "[N]");
        require_nonnegative(idx("clamps", c, "length_m"), cl.length_m, "[m] (0: a point tie)");
        bool crosses = false;
        for (std::size_t i = 0; i + 1 < spec.leaves.size(); ++i) crosses = crosses || (present(i, cl.x_m) && present(i + 1, cl.x_m));
        if (!crosses)
            throw InputError(idx("clamps", c, "x_m"), "value " + format_value(cl.x_m) +
                                                          " crosses no interface: a clamp must lie where two adjacent leaves overlap");
        for (std::size_t d = 0; d < c; ++d)
            if (std::abs(spec.clamps[d].x_m - cl.x_m) <= tol)
                throw InputError(idx("clamps", c, "x_m"), "value " + format_value(cl.x_m) + " duplicates clamps[" +
                                                              std::to_string(d) + "]: clamps must be at distinct positions");
    }
}

/// The mesh's element length over the stack's extent [m].
void validate_mesh(const ModelSpec& spec, double extent) {
    require_positive("mesh.element_length_m", spec.mesh.element_length_m, "[m]");
    if (extent / spec.mesh.element_length_m > 1e6)
        throw InputError("mesh.element_length_m", "value " + format_value(spec.mesh.element_length_m) +
                                                      " gives more than 1e6 elements along the stack: use a longer element");
}

/// The half model: the stack mirrored about the attachment (leaves centred, equal supports,
/// profiles and clamps mirrored), the seat tying every leaf, neither rotating nor sliding.
void validate_half_model(const ModelSpec& spec, const std::vector<int>& tied, double tol) {
    const auto& leaves = spec.leaves;
    const auto& rb = spec.rigid_body;
    const double xr = rb.x_m;
    // the symmetry plane holds the seat's rotation and axial motion (theta = u = 0 there)
    if (rb.pitch_inertia_kg_m2 > 0.0)
        throw InputError("rigid_body.pitch_inertia_kg_m2",
                         "value " + format_value(rb.pitch_inertia_kg_m2) +
                             " is not used by the half model, whose seat does not rotate (give 0, or use mesh.symmetry = 'full')");
    if (rb.axial == SeatAxial::free)
        throw InputError("rigid_body.axial", "value 'free' is not available on the half model, whose symmetry plane "
                                             "locates the seat axially (use mesh.symmetry = 'full')");
    for (std::size_t i = 0; i < leaves.size(); ++i) {
        const auto& l = leaves[i];
        if (std::abs(l.x_start_m + 0.5 * l.length_m - xr) > tol)
            throw InputError(idx("leaves", i, "x_start_m"),
                             "the half model needs every leaf centred on the attachment x = " + format_value(xr) +
                                 " m; this leaf's centre is at " + format_value(l.x_start_m + 0.5 * l.length_m) + " m");
        if (l.left_support != l.right_support)
            throw InputError(idx("leaves", i, "right_support"), "the half model needs equal supports at both ends");
        for (double px : l.profile.x_m) {  // a profile mirrored about the attachment
            const double x = l.x_start_m + px, xm = 2.0 * xr - x;
            if (std::abs(leaf_thickness_m(l, x) - leaf_thickness_m(l, xm)) > 1e-9 * leaf_thickness_m(l, x) ||
                std::abs(leaf_width_m(l, x) - leaf_width_m(l, xm)) > 1e-9 * leaf_width_m(l, x))
                throw InputError(idx("leaves", i, "profile"), "the half model needs each profile mirrored about the attachment x = " +
                                                                  format_value(xr) + " m; at x = " + format_value(x) + " m it is not");
        }
    }
    if (tied.size() != leaves.size())
        throw InputError("rigid_body.tied_leaves", "the half model needs the seat to tie every leaf");
    for (std::size_t c = 0; c < spec.clamps.size(); ++c) {
        const auto& cl = spec.clamps[c];
        if (std::abs(cl.x_m - xr) <= tol) continue;
        const bool mirrored = std::any_of(spec.clamps.begin(), spec.clamps.end(), [&](const ClampSpec& o) {
            return std::abs(o.x_m - (2.0 * xr - cl.x_m)) <= tol && o.preload_n == cl.preload_n &&
                   o.length_m == cl.length_m;
        });
        if (!mirrored)
            throw InputError(idx("clamps", c, "x_m"), "the half model needs each clamp mirrored about x = " +
                                                          format_value(xr) + " m with the same preload and length");
    }
}

/// The probe, when given: on an interface, within the meshed region (x <= x_hi [m]).
void validate_probe(const ModelSpec& spec, const Present& present, double x_hi, double tol) {
    if (!spec.probe) return;
    const auto& pr = *spec.probe;
    if (pr.interface_index < 0 || pr.interface_index + 1 >= static_cast<int>(spec.leaves.size()))
        throw InputError("probe.interface_index", "value " + std::to_string(pr.interface_index) +
                                                      " is not an interface: allowed 0.." +
                                                      std::to_string(static_cast<int>(spec.leaves.size()) - 2));
    require_finite("probe.x_m", pr.x_m);
    if (!present(pr.interface_index, pr.x_m) || !present(pr.interface_index + 1, pr.x_m) || pr.x_m > x_hi + tol)
        throw InputError("probe.x_m", "value " + format_value(pr.x_m) + " is not on interface " +
                                          std::to_string(pr.interface_index) + " (within the meshed region)");
}

/// The mesh: the nodes' x [m] up to x_hi, increasing. Every break (a leaf's ends and profile
/// points, a clamp, a clip, the attachment, the probe) is a node; between two breaks, elements
/// of at most mesh.element_length_m, equal.
std::vector<double> node_grid(const ModelSpec& spec, double tol, double x_hi) {
    const auto& rb = spec.rigid_body;
    std::vector<double> breaks;
    for (const auto& l : spec.leaves) {
        breaks.push_back(l.x_start_m);
        breaks.push_back(leaf_end(l));
        for (double px : l.profile.x_m) breaks.push_back(l.x_start_m + px);  // a profile's breakpoints are nodes
    }
    for (const auto& cl : spec.clamps) breaks.push_back(cl.x_m);
    for (const auto& cl : spec.clips) breaks.push_back(cl.x_m);
    breaks.push_back(rb.x_m);
    if (spec.probe) breaks.push_back(spec.probe->x_m);
    std::sort(breaks.begin(), breaks.end());
    std::vector<double> uniq;
    for (double b : breaks) {
        if (b > x_hi + tol) continue;
        if (uniq.empty() || b - uniq.back() > tol) uniq.push_back(b);
    }
    if (spec.symmetry == Symmetry::half && std::abs(uniq.back() - rb.x_m) > tol) uniq.push_back(rb.x_m);
    std::vector<double> nodes_x{uniq.front()};
    for (std::size_t s = 1; s < uniq.size(); ++s) {
        const double a = uniq[s - 1], b = uniq[s];
        const int n = std::max(1, static_cast<int>(std::ceil((b - a) / spec.mesh.element_length_m - 1e-6)));
        for (int k = 1; k <= n; ++k) nodes_x.push_back(k == n ? b : a + (b - a) * k / n);
    }
    return nodes_x;
}

/// The index of the first node at or after x - tol.
int node_at(const std::vector<double>& nodes_x, double x, double tol) {
    const auto it = std::lower_bound(nodes_x.begin(), nodes_x.end(), x - tol);
    return static_cast<int>(it - nodes_x.begin());
}

/// Each leaf's thickness at the seat [m].
std::vector<double> seat_thicknesses(const ModelSpec& spec) {
    std::vector<double> ts(spec.leaves.size());
    for (std::size_t i = 0; i < spec.leaves.size(); ++i) ts[i] = leaf_thickness_m(spec.leaves[i], spec.rigid_body.x_m);
    return ts;
}

/// The leaves' centroid heights [m] (y up, leaf 0 on top), stacked at the seat with the
/// interfaces' gaps, zero midway across the tied leaves. At the seat a profiled leaf's axis lies
/// half its local thickness `ts` from its surfaces.
std::vector<double> centroid_heights(const ModelSpec& spec, const std::vector<double>& ts, const std::vector<int>& tied) {
    std::vector<double> yc(spec.leaves.size());
    double top = 0.0;
    for (std::size_t i = 0; i < spec.leaves.size(); ++i) {
        yc[i] = top - 0.5 * ts[i];
        top -= ts[i] + (i < spec.interfaces.size() ? spec.interfaces[i].initial_gap_m : 0.0);
    }
    const int t0 = tied.front(), t1 = tied.back();
    const double mid = 0.5 * ((yc[t0] + 0.5 * ts[t0]) + (yc[t1] - 0.5 * ts[t1]));
    for (auto& y : yc) y -= mid;
    return yc;
}

/// Where the leaves' profiles are thinner than at the seat (straight axes, stacked there) they
/// leave a taper gap: it is added to p.initial_gap_m; returns it [m]. The profiles may not overlap
/// unless a positive gap makes room (an explicit interference, a negative gap, is the gap's own
/// and adds to the taper's gap).
double add_taper_gap(const ModelSpec& spec, std::size_t i, const std::vector<double>& ts, PairSpec& p) {
    const auto& leaves = spec.leaves;
    const double here = leaf_thickness_m(leaves[i], p.x_m) + leaf_thickness_m(leaves[i + 1], p.x_m);
    const double taper_gap = 0.5 * (ts[i] + ts[i + 1] - here);
    const double room = std::max(0.0, p.initial_gap_m);
    if (room + taper_gap < -1e-9 * here)
        throw InputError(idx("interfaces", i, "initial_gap_m"),
                         "leaves[" + std::to_string(i) + "] and leaves[" + std::to_string(i + 1) + "] would overlap by " +
                             format_value(-taper_gap - room) + " m at x = " + format_value(p.x_m) +
                             " m: the leaves are stacked at the seat (rigid_body.x_m) on straight axes, so their "
                             "profiles must not be thicker elsewhere than there, or the gap must make room");
    p.initial_gap_m = p.initial_gap_m >= 0.0 ? std::max(0.0, p.initial_gap_m + taper_gap)
                                             : p.initial_gap_m + std::max(0.0, taper_gap);
    return taper_gap;
}

/// The pair's kind: bonded by the interface's law, a clamp (with its preload) where one crosses,
/// else Coulomb.
void set_pair_kind(const ModelSpec& spec, std::size_t i, double tol, PairSpec& p) {
    p.kind = PairKind::coulomb;
    if (spec.interfaces[i].law == InterfaceLaw::bonded) {
        p.kind = PairKind::bonded;
        p.friction_coefficient = 0.0;
        return;
    }
    for (const auto& cl : spec.clamps)
        if (std::abs(cl.x_m - p.x_m) <= tol) {  // clamps merged at one point add up (merge_close_clamps)
            p.kind = PairKind::clamp;
            p.preload_n += cl.preload_n;
        }
}

/// The candidate pairs of interfaces[i], one per node both leaves share (x <= the meshed region).
void add_interface_pairs(const ModelSpec& spec, const Model& m, std::size_t i, const std::vector<double>& ts,
                         std::vector<PairSpec>& pairs) {
    const auto& leaves = spec.leaves;
    const auto& nodes_x = m.nodes_x();
    const double tol = m.x_tolerance_m();
    const bool half = spec.symmetry == Symmetry::half;
    const int lo = std::max(m.first_node(static_cast<int>(i)), m.first_node(static_cast<int>(i) + 1));
    const int hi = std::min(m.last_node(static_cast<int>(i)), m.last_node(static_cast<int>(i) + 1));
    const bool elastic = spec.interfaces[i].contact == InterfaceContact::elastic;
    const bool profiled = !leaves[i].profile.x_m.empty() || !leaves[i + 1].profile.x_m.empty();
    InterfaceLayer layer = interface_layer(spec, static_cast<int>(i));
    for (int n = lo; n <= hi; ++n) {
        if (elastic && profiled) layer = interface_layer(spec, static_cast<int>(i), nodes_x[n]);  // the local sections
        PairSpec p;
        p.interface_index = static_cast<int>(i);
        p.node = n;
        p.x_m = nodes_x[n];
        p.friction_coefficient = spec.interfaces[i].friction_coefficient;
        p.initial_gap_m = spec.interfaces[i].initial_gap_m;
        const double taper_gap = profiled ? add_taper_gap(spec, i, ts, p) : 0.0;
        set_pair_kind(spec, i, tol, p);
        if (elastic) {
            // The layer over the pair's area A = b L: L the tributary length (half of each
            // neighbouring element of the interface; lumped, node to node), or a clamp's own
            // length (half of it on the symmetry plane of the half model). A point clamp stays rigid.
            double L = 0.0;
            if (p.kind == PairKind::clamp) {
                for (const auto& cl : spec.clamps)
                    if (std::abs(cl.x_m - p.x_m) <= tol) L += cl.length_m;
                if (half && n == m.attachment_node()) L *= 0.5;
            } else {
                if (n < hi) L += 0.5 * (nodes_x[n + 1] - nodes_x[n]);
                if (n > lo) L += 0.5 * (nodes_x[n] - nodes_x[n - 1]);
            }
            if (L > 0.0) {
                const double area = layer.contact_width_m * L;
                p.normal_compliance_m_per_n = 1.0 / (layer.normal_stiffness_pa_per_m * area);
                p.tangential_compliance_m_per_n = 1.0 / (layer.tangential_stiffness_pa_per_m * area);
            }
        }
        if (p.kind == PairKind::clamp && taper_gap > 1e-12) {
            std::size_t c = 0;
            while (std::abs(spec.clamps[c].x_m - p.x_m) > tol) ++c;
            throw InputError(idx("clamps", c, "x_m"), "value " + format_value(p.x_m) + " crosses interfaces[" + std::to_string(i) +
                                                          "] where the leaves' profiles leave a gap of " + format_value(taper_gap) +
                                                          " m (they are stacked at the seat, x = " + format_value(spec.rigid_body.x_m) +
                                                          " m): a clamp needs the leaves' sections there as thick as at the seat");
        }
        if (p.kind == PairKind::clamp && p.initial_gap_m > 0.0)
            throw InputError(idx("interfaces", i, "initial_gap_m"),
                             "value " + format_value(p.initial_gap_m) +
                                 " is not allowed where a clamp crosses the interface: a clamp closes the gap (use 0)");
        p.initial_gap_m += detail::free_shape_m(spec, static_cast<int>(i), p.x_m) -
                           detail::free_shape_m(spec, static_cast<int>(i) + 1, p.x_m);  // free camber
        pairs.push_back(p);
    }
}

/// The probe pair's index in `pairs` (-1: none): the given probe, else the first clamp on
/// interface 0 within the meshed region.
int probe_pair_index(const ModelSpec& spec, const Present& present, double x_hi, double tol,
                     const std::vector<double>& nodes_x, const std::vector<PairSpec>& pairs) {
    ProbeSpec probe;
    bool have_probe = false;
    if (spec.probe) {
        probe = *spec.probe;
        have_probe = true;
    } else if (spec.leaves.size() > 1) {
        double best = std::numeric_limits<double>::infinity();
        for (const auto& cl : spec.clamps)
            if (present(0, cl.x_m) && present(1, cl.x_m) && cl.x_m < best && cl.x_m <= x_hi + tol) best = cl.x_m;
        if (std::isfinite(best)) {
            probe = ProbeSpec{0, best};
            have_probe = true;
        }
    }
    int found = -1;
    if (have_probe) {
        const int n = node_at(nodes_x, probe.x_m, tol);
        for (std::size_t k = 0; k < pairs.size(); ++k)
            if (pairs[k].interface_index == probe.interface_index && pairs[k].node == n) found = static_cast<int>(k);
    }
    return found;
}

}  // namespace

Model Model::build(ModelSpec spec) {
    Model m;
    const auto& leaves = spec.leaves;
    if (leaves.empty()) throw InputError("leaves", "the stack has no leaf: at least 1 is required");

    // --- the spec's checks, in the order of its keys ----------------------------------
    const auto [x_min, x_max] = validate_leaves(spec);
    detail::validate_free_shapes(spec);
    const double extent = x_max - x_min;
    const double tol = 1e-9 * std::max(extent, std::abs(x_max));
    m.x_tol_ = tol;
    validate_interfaces(spec, tol);
    const auto present = [&](std::size_t leaf, double x) {
        return x >= leaves[leaf].x_start_m - tol && x <= leaf_end(leaves[leaf]) + tol;
    };
    m.tied_ = validate_rigid_body(spec, present);
    validate_clamps(spec, tol, present);
    validate_mesh(spec, extent);
    const bool half = spec.symmetry == Symmetry::half;
    if (half) validate_half_model(spec, m.tied_, tol);
    const double x_hi = half ? spec.rigid_body.x_m : x_max;
    detail::validate_clips(spec, tol, present);
    validate_probe(spec, present, x_hi, tol);

    // --- the mesh and each leaf's node range -------------------------------------------
    m.adjustments_ = merge_close_clamps(spec, tol);
    m.nodes_x_ = node_grid(spec, tol, x_hi);
    const int nn = static_cast<int>(m.nodes_x_.size());
    for (const auto& l : leaves) {
        m.first_node_.push_back(node_at(m.nodes_x_, l.x_start_m, tol));
        m.last_node_.push_back(std::min(nn - 1, node_at(m.nodes_x_, leaf_end(l), tol)));
    }
    m.attach_node_ = node_at(m.nodes_x_, spec.rigid_body.x_m, tol);

    // --- centroid heights, candidate pairs, the probe pair, the clips' pairs -------------
    const std::vector<double> ts = seat_thicknesses(spec);
    m.y_centroid_ = centroid_heights(spec, ts, m.tied_);
    for (std::size_t i = 0; i + 1 < leaves.size(); ++i) add_interface_pairs(spec, m, i, ts, m.pairs_);
    m.probe_pair_ = probe_pair_index(spec, present, x_hi, tol, m.nodes_x_, m.pairs_);
    detail::add_clip_pairs(spec, m.nodes_x_, tol, m.pairs_);  // after the probe's: never the probe pair
    m.spec_ = std::move(spec);
    return m;
}

FrictionMeshRatio friction_mesh_ratio(const Model& model) {
    const ModelSpec& spec = model.spec();
    const double tol = model.x_tolerance_m();
    FrictionMeshRatio best;
    for (int i = 0; i < static_cast<int>(spec.interfaces.size()); ++i) {
        const InterfaceSpec& f = spec.interfaces[i];
        if (f.law != InterfaceLaw::coulomb || f.friction_coefficient <= 0.0) continue;
        std::vector<double> x;
        double arm_m = 0.0;  // the largest over the pairs (a profile's local thicknesses)
        for (const PairSpec& c : model.candidate_pairs())
            if (c.interface_index == i) {
                x.push_back(c.x_m);
                arm_m = std::max(arm_m, 0.5 * (leaf_thickness_m(spec.leaves[i], c.x_m) + leaf_thickness_m(spec.leaves[i + 1], c.x_m)));
            }
        std::sort(x.begin(), x.end());
        double h = std::numeric_limits<double>::infinity();
        for (std::size_t j = 1; j < x.size(); ++j)
            if (x[j] - x[j - 1] > tol) h = std::min(h, x[j] - x[j - 1]);
        if (!std::isfinite(h)) continue;  // fewer than two pairs: no neighbour to trade forces with
        const bool elastic = f.contact == InterfaceContact::elastic;
        double l = elastic ? interface_layer(spec, i).decay_length_m : 0.0;
        if (elastic && (!spec.leaves[i].profile.x_m.empty() || !spec.leaves[i + 1].profile.x_m.empty()))
            for (double xp : x) l = std::min(l, interface_layer(spec, i, xp).decay_length_m);  // the shortest over the pairs
        const double kappa = f.friction_coefficient * arm_m / std::max(h, l);
        if (kappa > best.ratio) best = {kappa, i, h, f.friction_coefficient * arm_m, l, elastic};
    }
    return best;
}

std::string friction_mesh_advice(const Model& model) {
    const ModelSpec& spec = model.spec();
    char buf[768];
    // Elastic interfaces: bounded ratio on every mesh, but the worst combination of slip
    // directions has a gain of about 1.43 mu (measured; model.hpp), 1 from mu ~ 0.7 on.
    for (std::size_t i = 0; i < spec.interfaces.size(); ++i) {
        const InterfaceSpec& f = spec.interfaces[i];
        if (f.contact != InterfaceContact::elastic || f.law != InterfaceLaw::coulomb || f.friction_coefficient < 0.7)
            continue;
        std::snprintf(buf, sizeof buf,
                      "interface %zu has the elastic law with mu = %.3g: from mu of about 0.7 on, the worst combination "
                      "of slip directions (a gain of about 1.43 mu) can make the incremental Coulomb problem ill-posed "
                      "on any mesh; a contact solve may then fail to settle (docs/contact-solvers.md)",
                      i, f.friction_coefficient);
        return buf;
    }
    const FrictionMeshRatio r = friction_mesh_ratio(model);
    if (r.ratio < 1.0) return {};
    std::snprintf(buf, sizeof buf,
                  "the friction-mesh ratio mu (t_i + t_i+1) / (2 h) is %.3g on interface %d (pair spacing h = %.4g m): "
                  "from about 1 on, the incremental Coulomb problem of this mesh can have several solutions and the "
                  "exact solver's fixed point on the friction limits settles slowly or not at all "
                  "(docs/contact-solvers.md); pairs spaced more than %.4g m apart there (mesh.element_length_m), a "
                  "mu below %.4g, or the elastic interface law (interfaces[%d].contact = \"elastic\", --interface elastic on the "
                  "command line, which spreads the couple over the layer's decay length) bring it below 1",
                  r.ratio, r.interface_index, r.pair_spacing_m, r.spacing_for_one_m,
                  spec.interfaces[r.interface_index].friction_coefficient / r.ratio, r.interface_index);
    return buf;
}

}  // namespace stackbeam
