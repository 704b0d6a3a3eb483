// The covering start of the homotopy (transitions.hpp, covering_start; docs/decisions/041).
#include <algorithm>

#include "contact/sparse/transitions/transitions.hpp"

namespace stackbeam::detail::sparse {

/// For modes M0 (path.modes) and their linear solution x1 = (p, z) at this step's data
/// (b, d), data (b0, d0) at which M0 holds and x* = (z, p*) is M0's solution: x* is x1 with
/// each failing condition of M0 put on its bound (p* and s* = G z - d0 the projections of p
/// and s onto M0's conditions): a closed pair's tension to 0, an open pair's penetration to
/// 0, a sticking pair's force into [-mu tau*, mu tau*], a slipping pair's slip against its
/// force to 0 (its force then follows p*_n by its equation), a clamp's normal force to its
/// preload where M0 says it holds (stick, slip) or lets go (free). Held rows keep s = 0 and
/// zero-force rows p = 0, so M0's equations hold at x* with
///     b0 = K z - G^T p* = b + G^T (p - p*),   d0 = d + (s - s*)   (s* = G z - d0):
/// the straight line from (b0, d0) to (b, d) is a homotopy whose start modes are valid
/// (Eaves / Lemke's covering vector, here chosen per row), and path_following follows it.
/// TauRule::current (path_following's rule).
void covering_start(const SparsePath& path, const Step& step, const Eigen::VectorXd& p, const Eigen::VectorXd& z,
                    Eigen::VectorXd& b0, Eigen::VectorXd& d0) {
    const SparseStiffness& st = path.stiffness();
    const ContactProblem& laws = path.laws;
    const modes::ModeSet& M = path.modes;
    const Eigen::VectorXd s = st.Grow * z - step.d;
    Eigen::VectorXd ps = p, ss = s;
    for (int k = 0; k < static_cast<int>(laws.pairs.size()); ++k) {
        const auto& c = laws.pairs[k];
        const int rn = c.row_n, rt = c.row_t;
        const bool clamp = c.kind == PairKind::clamp;
        if (rn >= 0 && modes::ModeSet::unilateral(c)) {
            if (M.nmode[k] == modes::CLOSED) ps[rn] = std::min(ps[rn], 0.0);  // no tension
            else if (M.nmode[k] == modes::OPEN) ss[rn] = std::min(ss[rn], 0.0);  // no penetration
        }
        if (rt < 0 || c.kind == PairKind::bonded || c.friction_coefficient == 0.0) continue;
        if (modes::ModeSet::unilateral(c) && M.tmode[k] == modes::FREE) continue;
        const double mu = c.friction_coefficient;
        if (clamp && rn >= 0) {  // a clamp's normal force: below its preload where it holds, above where free
            if (M.tmode[k] == modes::FREE) ps[rn] = std::max(ps[rn], c.preload_n);
            else ps[rn] = std::min(ps[rn], c.preload_n);
        }
        const double pn = rn >= 0 ? ps[rn] : 0.0;
        const double tau = clamp ? std::max(0.0, c.preload_n - pn) : std::max(0.0, -pn);
        switch (M.tmode[k]) {
            case modes::STICK: ps[rt] = std::clamp(ps[rt], -mu * tau, mu * tau); break;
            case modes::SLIP_POS:
            case modes::SLIP_NEG: {
                const double sigma = M.tmode[k] == modes::SLIP_POS ? 1.0 : -1.0;
                ps[rt] = sigma * mu * tau;                    // its equation, on p*_n
                ss[rt] = sigma * std::min(sigma * ss[rt], 0.0);  // slip against the force
                break;
            }
            default: break;
        }
    }
    b0 = st.K * z - st.Gt * ps;  // = b + G^T (p - p*) where K z = b + G^T p
    d0 = step.d + (s - ss);
}

}  // namespace stackbeam::detail::sparse
