// What the choice of a stepper reads from the system (stack_properties.hpp).
#include "time/stack_properties.hpp"

namespace stackbeam::detail {

bool has_leaf_mass(const System& system) {
    for (const auto& leaf : system.model().spec().leaves)
        if (leaf.density_kg_per_m3 != 0.0) return true;
    return false;
}

bool has_mode_changes(const System& system) {
    for (const auto& pr : system.pairs())
        if (pr.kind != PairKind::bonded && pr.friction_coefficient != 0.0) return true;
    return false;
}

int first_rigid_pair(const System& system) {
    const Eigen::VectorXd& c = system.layer_compliance_m_per_n();
    for (int kk = 0; kk < static_cast<int>(system.pairs().size()); ++kk) {
        const auto& cp = system.pairs()[kk];
        if ((cp.row_n >= 0 && !(c[cp.row_n] > 0.0)) || (cp.row_t >= 0 && !(c[cp.row_t] > 0.0))) return kk;
    }
    return -1;
}

}  // namespace stackbeam::detail
