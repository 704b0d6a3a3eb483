#pragma once
// Internal: the free camber of the leaves and the rebound clips (model.hpp, LeafSpec::free_camber_m,
// ClipSpec), validated and turned into contact offsets and clip rows for Model::build.
#include <functional>
#include <string>
#include <vector>

#include "stackbeam/model/model.hpp"

namespace stackbeam::detail {

/// Checks every leaf's free_camber_m / free_radius_m (InputError naming the field).
void validate_free_shapes(const ModelSpec& spec);

/// Free-shape height v0(x) [m] of leaf `leaf` (0 for a flat leaf): (x - x_R)^2 / 2 * curvature.
double free_shape_m(const ModelSpec& spec, int leaf, double x_m);

/// The part of a pair's offset that makes an interference there, for the message that names it:
/// the field as the user wrote it (interfaces[i].initial_gap_m, or the upper or lower leaf's
/// free_camber_m / free_radius_m), its value and its part of the offset at x [m] (the most negative).
struct Interference {
    std::string field;
    double value = 0.0;
    double part_m = 0.0;
};
Interference interference_source(const ModelSpec& spec, int interface_index, double x_m);

/// Checks the clips (InputError naming clips[c].field): `present(leaf, x)` tells whether a
/// leaf reaches x.
void validate_clips(const ModelSpec& spec, double tol_m,
                    const std::function<bool(std::size_t, double)>& present);

/// The clip rows as candidate pairs (appended after the interfaces' pairs, which `pairs` holds):
/// kind coulomb, mu 0, the offset clearance - sum of the strapped pairs' offsets at the clip's
/// node (each with its interface's gap, taper gap and free shapes' difference).
void add_clip_pairs(const ModelSpec& spec, const std::vector<double>& nodes_x, double tol_m,
                    std::vector<PairSpec>& pairs);

}  // namespace stackbeam::detail
