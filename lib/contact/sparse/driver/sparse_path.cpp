// The state shared by the units of the sparse contact path (sparse_path.hpp).
#include "contact/sparse/driver/sparse_path.hpp"

#include <algorithm>
#include <cmath>

#include "contact/solvers.hpp"
#include "contact/sparse/driver/trace.hpp"
#include "contact/sparse/transitions/transitions.hpp"

namespace stackbeam::detail::sparse {

namespace {
constexpr int kBudget = 3;  // passes without fewer violations before Murty's rule: as in the dense solver
}  // namespace

void SparsePath::reset(const SparseContactProblem& pr) {
    pr.validate();
    // the slip couplings the pairs can make (a friction pair's tangential row on its normal
    // row's force: ModeSet::linearize), for the fixed-pattern LU's pattern
    std::vector<std::pair<int, int>> couplings;
    for (const auto& c : pr.pairs)
        if (c.row_t >= 0 && c.row_n >= 0 && c.kind != PairKind::bonded) couplings.emplace_back(c.row_t, c.row_n);
    solver.reset(pr.K, pr.G, couplings);
    ipm_analysed = false;
    js_analysed = false;
    kept.reset();  // its columns are of the old (K, G)
    // KLU for the smoothing Newton method's Jacobian with few rigid rows (as the mode solver's
    // fixed_max_rigid_rows: a rigid row near its held mode has a zero diagonal there)
    const std::vector<int> layer = layer_dofs(pr.K, pr.G);
    const auto rigid = std::count(layer.begin(), layer.end(), -1);
    js_lu = make_pattern_lu(switches.fixed_pattern >= 2 && klu_built() && rigid <= ModeSolverTuning{}.fixed_max_rigid_rows
                                ? FixedPatternLu::klu
                                : FixedPatternLu::eigen,
                            switches.residual_refactor_check);
    const int m = pr.size();
    laws.W.resize(0, 0);
    laws.q = Eigen::VectorXd::Zero(m);
    laws.pairs = pr.pairs;
    modes.nmode.clear();
    lin_ok_ = false;
}

/// The saddle-point system is scaled symmetrically by the mode solver (z = Dz y with
/// Dz = diag(K)^-1/2, held row i by 1/||G_i Dz||): K mixes axial (EA/L ~ 1e8), bending
/// (EI/L^3 ~ 1e7) and rotational (EI/L ~ 1e3) entries and G is O(1), and unscaled the
/// LU's pivoting would lose digits. Each cached solve gets one step of iterative
/// refinement, so held rows come out at s = 0 to round-off.
int SparsePath::solve_modes(const Step& step, Eigen::VectorXd& p, Eigen::VectorXd& z) {
    // the linearisation depends on the modes and the tau rule (and, with the previous
    // step's rule, on tau_previous_n): kept while they stay (a step whose modes stay
    // makes none)
    const bool same = lin_ok_ && laws.tau_rule == TauRule::current && lin_tau_rule_ == laws.tau_rule &&
                      lin_nmode_ == modes.nmode && lin_tmode_ == modes.tmode;
    if (!same) {
        modes.linearize(laws, lin_);
        lin_key_ = solver_key(laws, modes);
        lin_nmode_ = modes.nmode;
        lin_tmode_ = modes.tmode;
        lin_tau_rule_ = laws.tau_rule;
        lin_ok_ = true;
    }
    // a set near the homotopy's kept base: on its factorisation and columns (docs/decisions/045)
    if (kept && solve_on_kept_base(*this, step, p, z)) {
        modes.put_slip_forces(laws, p);
        return 0;
    }
    // the trace counts the new-set solves of a set solved before (docs/decisions/038: none recurs)
    if (observer && observer->current && !solver.is_current(lin_key_)) observer->count_solve(lin_key_);
    const int f = solver.solve(lin_, lin_key_, step.b, step.d, p, z);
    modes.put_slip_forces(laws, p);  // p_t = e_t + D p_n, written with the friction-limit formula
    return f;
}

int SparsePath::count_violations(const Eigen::VectorXd& d, const Eigen::VectorXd& p, const Eigen::VectorXd& z) {
    s = stiffness().Grow * z - d;  // row-major: a gather per row, the same sums as G * z
    const double roundoff = stiffness().roundoff(d, z);
    return modes.count_violations(laws, p, s, diag(), std::max(kAccept * options.tolerance_m, roundoff));
}

bool SparsePath::passes(const Step& step, Eigen::VectorXd& p, Eigen::VectorXd& z, int max_passes, SolveResult& r) {
    return detail::active_set_passes(
        modes, laws, p, max_passes, kBudget, r, [&](Eigen::VectorXd& x) { return solve_modes(step, x, z); },
        [&](const Eigen::VectorXd& x) { return count_violations(step.d, x, z); });
}

bool passes_from_modes(SparsePath& path, const Step& step, Eigen::VectorXd& p, Eigen::VectorXd& z, SolveResult& r) {
    return path.passes(step, p, z, path.options.max_active_set_iterations, r);
}

/// The natural map F(p, s) of the contact laws (paper eq. 8; zero exactly where eq. 10's
/// error vector is), per component in metres (contact.hpp, natural_map), into `F`, and
/// optionally the modes of its generalised Jacobian at (p, s) into `modes`:
///   unilateral normal  F = w (p_n - min(0, p_n - s_n / w)):  closed (F = s_n) where
///                      p_n - s_n / w < 0, else open (F = w p_n);
///   tangential         F = w (p_t - clamp(a, -mu tau, mu tau)), a = p_t - s_t / w: stick
///                      (F = s_t) inside the limit, slip with sigma = sign(a) (F = w (p_t -
///                      sigma mu tau(p_n)), tau linearised as in ModeSet::linearize) outside,
///                      free (F = w p_t) where the pair is open or tau cannot be positive;
///   bilateral, bonded  F = s (held).
/// With w = W_kk (diag) both parts of each component are in metres, so the Newton step
/// of the modes (the linear problem solve_modes solves) zeroes F for those modes.
void SparsePath::natural_residual(const Eigen::VectorXd& p, const Eigen::VectorXd& s, Eigen::VectorXd& F,
                                  bool set_modes) {
    const Eigen::VectorXd& diag = this->diag();
    F = s;
    const bool prev = laws.tau_rule == TauRule::previous_step;
    for (int k = 0; k < static_cast<int>(laws.pairs.size()); ++k) {
        const auto& c = laws.pairs[k];
        bool closed = true;
        if (c.row_n >= 0 && c.kind == PairKind::coulomb) {
            const double w = diag[c.row_n], pn = p[c.row_n];
            const double a = pn - s[c.row_n] / w;
            F[c.row_n] = w * (pn - std::min(0.0, a));
            closed = a < 0.0;
            if (set_modes) modes.nmode[k] = closed ? modes::CLOSED : modes::OPEN;
        } else if (c.kind == PairKind::coulomb) {
            closed = false;  // no normal row: the unilateral pair has no normal force
        }
        if (c.row_t < 0) continue;
        if (c.kind == PairKind::bonded) {
            if (set_modes) modes.tmode[k] = modes::STICK;
            continue;
        }
        const double w = diag[c.row_t], pt = p[c.row_t];
        const double limit = c.friction_coefficient * friction_normal_force(laws, k, p);
        const double a = pt - s[c.row_t] / w;
        F[c.row_t] = w * (pt - std::clamp(a, -limit, limit));
        if (!set_modes) continue;
        // can the friction limit be positive in the Newton step's linearisation?
        bool carries = c.friction_coefficient > 0.0;
        if (c.kind == PairKind::coulomb) carries = carries && closed && (!prev || limit > 0.0);
        else if (c.kind == PairKind::clamp) carries = carries && (prev ? limit > 0.0 : c.preload_n - (c.row_n >= 0 ? p[c.row_n] : 0.0) > 0.0);
        signed char mode = modes::FREE;
        if (carries) {
            if (std::abs(a) < limit || a == 0.0) mode = modes::STICK;
            else mode = a > 0.0 ? modes::SLIP_POS : modes::SLIP_NEG;
        }
        modes.tmode[k] = mode;
        modes.make_consistent(laws, k);
    }
}

}  // namespace stackbeam::detail::sparse
