#pragma once
// Internal to the mode solver's routes (linear/*.cpp): the forces of a set of modes from its
// held rows' forces, shared by the dispatch (mode_solver.cpp) and the routes.
#include "contact/sparse/linear/mode_solver.hpp"

namespace stackbeam::detail::sparse {

/// Each slipping row's force from its pair's normal force (held or fixed): p_t += coef p_n.
inline void add_slip_couplings(const modes::ModeLinearization& lin, Eigen::Ref<Eigen::VectorXd> p) {
    for (std::size_t a = 0; a < lin.coupled.size(); ++a) p[lin.coupled[a].first] += lin.coef[a] * p[lin.coupled[a].second];
}

/// Every contact row's force [N] from the held rows' pS: the fixed forces e, pS on the held
/// rows, the slip couplings.
inline void all_forces(const modes::ModeLinearization& lin, const Eigen::VectorXd& pS, Eigen::VectorXd& p) {
    p = lin.e;
    for (std::size_t i = 0; i < lin.S.size(); ++i) p[lin.S[i]] = pS[static_cast<Eigen::Index>(i)];
    add_slip_couplings(lin, p);
}

}  // namespace stackbeam::detail::sparse
