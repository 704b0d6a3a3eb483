// The continuation on the offsets of the sparse path (transitions.hpp).
#include <algorithm>
#include <vector>

#include "contact/sparse/transitions.hpp"

namespace stackbeam::detail::sparse {

namespace {
constexpr int kContinuationPasses = 6;              // active-set passes per continuation sub-step
constexpr double kContinuationMinStep = 1.0 / 256;  // smallest continuation sub-step (of the step's change)

/// One continuation sub-step: the problem (b, d) from the solution p, z of a nearby one,
/// by the active-set passes from the modes at (p, s), then by the semismooth Newton
/// method. On failure p, z and the modes are those on entry.
bool continuation_substep(SparsePath& path, const Step& step, Eigen::VectorXd& p, Eigen::VectorXd& z,
                          SolveResult& r) {
    const SparseStiffness& st = path.stiffness();
    const Eigen::VectorXd& d = step.d;
    const Eigen::VectorXd p_keep = p, z_keep = z;
    const std::vector<signed char> nmode_keep = path.modes.nmode, tmode_keep = path.modes.tmode;
    ++r.continuation_steps;
    bool ok = false;
    try {
        path.modes.init(path.laws, p, st.Grow * z - d);
        ok = path.passes(step, p, z, kContinuationPasses, r);
        if (!ok) {
            p = p_keep;
            z = z_keep;
            ok = semismooth_newton(path, step, p, z, r) && path.passes(step, p, z, path.options.max_active_set_iterations, r);
        }
    } catch (const SingularModes&) {
        path.solver.forget();
        ok = false;
    }
    if (!ok) {
        p = p_keep;
        z = z_keep;
        path.modes.nmode = nmode_keep;
        path.modes.tmode = tmode_keep;
    }
    return ok;
}
}  // namespace

/// Continuation (homotopy) for a transition no Newton method settles from the step's
/// start. The step's forces p (projected on the admissible set) solve the problem with the
/// offsets d0 = G z0 - s_c, where z0 = K^-1 (b + G^T p) and s_c is the nearest relative
/// position the laws allow at p (a closed or stuck component at s = 0, an open one at its
/// gap). Along d(a) = d0 + a (d - d0), a from 0 to 1, the solution moves continuously
/// (piecewise linearly while no pair changes mode); each sub-step from a to a + h is
/// solved by the active-set passes from the modes at a, then, if they do not settle, by
/// the semismooth Newton method from the solution at a; h doubles after a success and
/// halves after a failure. The answer at a = 1 solves the step's own problem (the same
/// passes confirm it), so continuation changes the way, not the result.
/// Measured (docs/decisions/005-continuation-on-offsets.md): on 10 identical leaves x 100 elements it settled every
/// transition both Newton methods gave up on (5 of 300 steps), in 2-4 sub-steps each,
/// where the Tresca fixed point had cost up to 3,621 factorisations. It does not help where the step starts
/// from rest with every pair at zero force and zero gap (10 identical leaves x 400): the
/// problem is then positively homogeneous in a but for the clamps' preload, so the
/// first sub-step is as hard as the whole step however short.
/// Returns false when h falls below kContinuationMinStep.
bool continuation(SparsePath& path, const Step& step, Eigen::VectorXd& p, Eigen::VectorXd& z, SolveResult& r) {
    const SparseStiffness& st = path.stiffness();
    const Eigen::VectorXd &b = step.b, &d = step.d;
    const int np = static_cast<int>(path.laws.pairs.size());
    for (int k = 0; k < np; ++k) {
        const ContactPair& c = path.laws.pairs[k];
        if (c.row_n >= 0 && detail::ModeSet::unilateral(c)) p[c.row_n] = std::min(p[c.row_n], 0.0);
        if (c.row_t >= 0 && c.kind != PairKind::bonded) {
            const double limit = c.friction_coefficient * friction_normal_force(path.laws, k, p);
            p[c.row_t] = std::clamp(p[c.row_t], -limit, limit);
        }
    }
    Eigen::VectorXd sc = st.positions(b, d, p, z);
    for (int k = 0; k < np; ++k) {
        const ContactPair& c = path.laws.pairs[k];
        if (c.row_n >= 0)
            sc[c.row_n] = detail::ModeSet::unilateral(c) && p[c.row_n] >= 0.0 ? std::min(0.0, sc[c.row_n]) : 0.0;
        if (c.row_t >= 0) sc[c.row_t] = 0.0;
    }
    const Eigen::VectorXd d0 = st.Grow * z - sc;
    double a = 0.0, h = 0.5;
    while (a < 1.0) {
        if (h < kContinuationMinStep) return false;
        const double at = std::min(1.0, a + h);
        const Eigen::VectorXd d_at = d0 + at * (d - d0);
        const bool ok = continuation_substep(path, Step{b, d_at}, p, z, r);
        if (ok) {
            a = at;
            h = std::min(1.0, 2.0 * h);
        } else {
            h *= 0.5;
        }
    }
    path.s = st.Grow * z - d;
    return true;
}

}  // namespace stackbeam::detail::sparse
