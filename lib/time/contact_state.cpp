// The contact bookkeeping the modes share (contact_state.hpp).
#include "time/contact_state.hpp"

#include <algorithm>

namespace stackbeam {

void detail::reanchor(const ContactLaws& laws, const Eigen::VectorXd& p, const Eigen::VectorXd& rel,
                      Eigen::VectorXd& d) {
    for (std::size_t j = 0; j < laws.pairs.size(); ++j) {
        const auto& pr = laws.pairs[j];
        if (pr.row_t < 0 || pr.kind == PairKind::bonded) continue;
        if (pair_state(laws, static_cast<int>(j), p) != PairState::stick) d[pr.row_t] = rel[pr.row_t];
    }
}

void detail::set_previous_step_limits(ContactLaws& problem, const Eigen::VectorXd& p) {
    for (int j = 0; j < static_cast<int>(problem.pairs.size()); ++j) {
        const auto& pr = problem.pairs[j];
        const double pn = pr.row_n >= 0 ? p[pr.row_n] : 0.0;
        problem.tau_previous_n[j] = pr.kind == PairKind::clamp ? std::max(0.0, pr.preload_n - pn) : std::max(0.0, -pn);
    }
}

std::vector<int> detail::closed_rows(const std::vector<ContactPair>& pairs, const Eigen::VectorXd& rel,
                                     const Eigen::VectorXd& d) {
    std::vector<int> tied;
    for (const auto& pr : pairs) {
        bool closed = true;
        if (pr.row_n >= 0) {
            const bool bilateral = pr.kind != PairKind::coulomb;
            closed = bilateral || rel[pr.row_n] - d[pr.row_n] > -1e-12;
            if (closed) tied.push_back(pr.row_n);
        }
        if (closed && pr.row_t >= 0 && (pr.kind == PairKind::bonded || pr.friction_coefficient > 0.0))
            tied.push_back(pr.row_t);
    }
    return tied;
}

}  // namespace stackbeam
