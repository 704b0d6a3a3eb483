#pragma once
// A one-leaf spring for the static checks of test_leaf_profiles and test_spring_ends.
#include "stackbeam/model/model.hpp"

namespace stackbeam::testing {

/// One leaf from x = 0 to length_m (thickness height_m: 0 for a profile to give it), the
/// rigid body (the load) at seat_x_m. A single leaf has no contact pair, so the stiffness at
/// the body is the leaf's own: System::free_stiffness_n_per_m(), deflection per unit load its inverse.
inline ModelSpec single_leaf(double length_m, double height_m, double width_m, double youngs_modulus_pa, SupportKind left,
                             SupportKind right, double seat_x_m, double element_length_m) {
    ModelSpec s;
    LeafSpec l;
    l.length_m = length_m;
    l.height_m = height_m;
    l.width_m = width_m;
    l.youngs_modulus_pa = youngs_modulus_pa;
    l.left_support = left;
    l.right_support = right;
    s.leaves = {l};
    s.rigid_body.mass_kg = 1.0;
    s.rigid_body.x_m = seat_x_m;
    s.mesh.element_length_m = element_length_m;
    return s;
}

}  // namespace stackbeam::testing
