// Free camber of the leaves and rebound clips (lib/model/assembly.hpp, model.hpp).
#include "model/assembly.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "stackbeam/errors.hpp"

namespace stackbeam {

double free_curvature_per_m(const LeafSpec& leaf) {
    if (leaf.free_radius_m != 0.0) return 1.0 / leaf.free_radius_m;
    return 8.0 * leaf.free_camber_m / (leaf.length_m * leaf.length_m);
}

bool has_free_camber(const ModelSpec& spec) {
    for (const auto& l : spec.leaves)
        if (l.free_camber_m != 0.0 || l.free_radius_m != 0.0) return true;
    return false;
}

bool needs_assembly(const ModelSpec& spec) {
    bool interference = false;
    for (const auto& f : spec.interfaces) interference = interference || f.initial_gap_m < 0.0;
    return interference || has_free_camber(spec) || !spec.clips.empty();
}

namespace detail {

namespace {
std::string field(const char* array, std::size_t i, const char* key) {
    return std::string(array) + "[" + std::to_string(i) + "]." + key;
}
}  // namespace

void validate_free_shapes(const ModelSpec& spec) {
    for (std::size_t i = 0; i < spec.leaves.size(); ++i) {
        const LeafSpec& l = spec.leaves[i];
        const double H = l.free_camber_m, R = l.free_radius_m;
        if (!std::isfinite(H) || std::abs(H) > 0.1 * l.length_m)
            throw InputError(field("leaves", i, "free_camber_m"),
                             "value " + format_value(H) + " is not allowed: the arc height must be finite and within +-" +
                                 format_value(0.1 * l.length_m) + " m (a tenth of the leaf length: small-deflection theory) [m]");
        if (!std::isfinite(R) || (R != 0.0 && std::abs(R) < 1.25 * l.length_m))
            throw InputError(field("leaves", i, "free_radius_m"),
                             "value " + format_value(R) + " is not allowed: the free radius must be finite and 0 (flat) or "
                                 "|R| >= " + format_value(1.25 * l.length_m) +
                                 " m (1.25 x the leaf length, an arc height of at most a tenth of it) [m]");
        if (H != 0.0 && R != 0.0)
            throw InputError(field("leaves", i, "free_radius_m"),
                             "value " + format_value(R) + " is not allowed together with free_camber_m = " + format_value(H) +
                                 ": give the free camber as an arc height or as a radius, not both");
    }
}

double free_shape_m(const ModelSpec& spec, int leaf, double x_m) {
    const double dx = x_m - spec.rigid_body.x_m;
    return 0.5 * free_curvature_per_m(spec.leaves[static_cast<std::size_t>(leaf)]) * dx * dx;
}

Interference interference_source(const ModelSpec& spec, int interface_index, double x_m) {
    // The offset's parts that can be negative (the taper's cannot: Model::build refuses an
    // overlap of the profiles that a positive gap does not cover): the interface's gap, the
    // upper leaf's free shape (ends down: < 0) and the lower leaf's, negated (ends up: < 0).
    const int a = interface_index, b = a + 1;
    const auto camber = [&](int leaf) {
        const LeafSpec& l = spec.leaves[static_cast<std::size_t>(leaf)];
        return field("leaves", static_cast<std::size_t>(leaf), l.free_radius_m != 0.0 ? "free_radius_m" : "free_camber_m");
    };
    const auto value = [&](int leaf) {
        const LeafSpec& l = spec.leaves[static_cast<std::size_t>(leaf)];
        return l.free_radius_m != 0.0 ? l.free_radius_m : l.free_camber_m;
    };
    const double gap = spec.interfaces[static_cast<std::size_t>(a)].initial_gap_m;
    Interference worst{field("interfaces", static_cast<std::size_t>(a), "initial_gap_m"), gap, gap};
    const Interference upper{camber(a), value(a), free_shape_m(spec, a, x_m)};
    const Interference lower{camber(b), value(b), -free_shape_m(spec, b, x_m)};
    for (const Interference& part : {upper, lower})
        if (part.part_m < worst.part_m) worst = part;
    return worst;
}

void validate_clips(const ModelSpec& spec, double tol_m,
                    const std::function<bool(std::size_t, double)>& present) {
    const int nleaf = static_cast<int>(spec.leaves.size());
    const bool half = spec.symmetry == Symmetry::half;
    const double xr = spec.rigid_body.x_m;
    for (std::size_t c = 0; c < spec.clips.size(); ++c) {
        const ClipSpec& cl = spec.clips[c];
        if (cl.first_leaf < 0 || cl.first_leaf >= nleaf - 1)
            throw InputError(field("clips", c, "first_leaf"), "value " + std::to_string(cl.first_leaf) +
                                                                  " is not allowed: a leaf index 0.." + std::to_string(nleaf - 2) +
                                                                  " (a leaf with one below it)");
        if (cl.last_leaf <= cl.first_leaf || cl.last_leaf >= nleaf)
            throw InputError(field("clips", c, "last_leaf"), "value " + std::to_string(cl.last_leaf) + " is not allowed: a leaf index " +
                                                                 std::to_string(cl.first_leaf + 1) + ".." + std::to_string(nleaf - 1) +
                                                                 " (below first_leaf = " + std::to_string(cl.first_leaf) + ")");
        if (!std::isfinite(cl.clearance_m) || cl.clearance_m <= 0.0)
            throw InputError(field("clips", c, "clearance_m"),
                             "value " + format_value(cl.clearance_m) +
                                 " is not allowed: must be finite and > 0 [m] (a clip without clearance is a clamp: use [[clamps]])");
        if (!std::isfinite(cl.stiffness_n_per_m) || cl.stiffness_n_per_m <= 0.0)
            throw InputError(field("clips", c, "stiffness_n_per_m"),
                             "value " + format_value(cl.stiffness_n_per_m) + " is not allowed: must be finite and > 0 [N/m]");
        if (!std::isfinite(cl.x_m))
            throw InputError(field("clips", c, "x_m"), "value " + format_value(cl.x_m) + " is not allowed: must be finite");
        for (int l = cl.first_leaf; l <= cl.last_leaf; ++l)
            if (!present(static_cast<std::size_t>(l), cl.x_m))
                throw InputError(field("clips", c, "x_m"), "value " + format_value(cl.x_m) + " is off leaves[" + std::to_string(l) +
                                                               "]: the clip must lie on every leaf it straps");
        if (std::abs(cl.x_m - xr) <= tol_m)
            throw InputError(field("clips", c, "x_m"), "value " + format_value(cl.x_m) +
                                                           " is at the rigid body's seat, which already ties the leaves: move the clip");
    }
    for (std::size_t c = 0; c < spec.clips.size(); ++c) {  // across clips, once each one's own values are valid
        const ClipSpec& cl = spec.clips[c];
        if (half) {  // each clip needs its twin (the meshed half holds one of them)
            bool mirrored = false;
            for (const ClipSpec& o : spec.clips)
                mirrored = mirrored || (std::abs(o.x_m - (2.0 * xr - cl.x_m)) <= tol_m && o.first_leaf == cl.first_leaf &&
                                        o.last_leaf == cl.last_leaf && o.clearance_m == cl.clearance_m &&
                                        o.stiffness_n_per_m == cl.stiffness_n_per_m);
            if (!mirrored)
                throw InputError(field("clips", c, "x_m"), "the half model needs each clip mirrored about x = " + format_value(xr) +
                                                               " m with the same leaves, clearance and stiffness");
        }
        for (std::size_t d = 0; d < c; ++d)
            if (std::abs(spec.clips[d].x_m - cl.x_m) <= tol_m)
                throw InputError(field("clips", c, "x_m"), "value " + format_value(cl.x_m) + " duplicates clips[" + std::to_string(d) +
                                                               "]: clips must be at distinct positions");
    }
}

void add_clip_pairs(const ModelSpec& spec, const std::vector<double>& nodes_x, double tol_m, std::vector<PairSpec>& pairs) {
    for (std::size_t c = 0; c < spec.clips.size(); ++c) {
        const ClipSpec& cl = spec.clips[c];
        int node = -1;
        for (std::size_t n = 0; n < nodes_x.size(); ++n)
            if (std::abs(nodes_x[n] - cl.x_m) <= tol_m) node = static_cast<int>(n);
        if (node < 0) continue;  // outside the meshed half
        PairSpec p;
        p.interface_index = cl.first_leaf;
        p.node = node;
        p.x_m = nodes_x[static_cast<std::size_t>(node)];
        p.kind = PairKind::coulomb;
        p.clip_index = static_cast<int>(c);
        // opening of the strap = sum of the gaps d_i + v_i - v_i+1 = sum d_i + v_first - v_last <= clearance
        // Each strapped gap is its interface's pair at the clip's node, whose offset holds every part
        // of it: the interface's gap, the taper's gap of profiled leaves and the free shapes'.
        double offsets = 0.0;
        const std::size_t interface_pairs = pairs.size();
        for (int i = cl.first_leaf; i < cl.last_leaf; ++i) {
            std::size_t k = 0;
            while (k < interface_pairs && (pairs[k].clip_index >= 0 || pairs[k].interface_index != i || pairs[k].node != node)) ++k;
            if (k == interface_pairs)  // validate_clips: every strapped leaf reaches the clip
                throw std::logic_error("add_clip_pairs: no pair of interface " + std::to_string(i) + " at clips[" +
                                       std::to_string(c) + "]");
            offsets += pairs[k].initial_gap_m;
        }
        p.initial_gap_m = cl.clearance_m - offsets;
        // the strap's stretch: a compliance on the row, which also keeps C' positive definite
        // (the row is the strapped interfaces' normal rows summed, negated)
        p.normal_compliance_m_per_n = 1.0 / cl.stiffness_n_per_m;
        pairs.push_back(p);
    }
}

}  // namespace detail
}  // namespace stackbeam
