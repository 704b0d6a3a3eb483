// The Tresca fixed point of the sparse path (transitions.hpp): the dense solver's fixed
// point on the friction limits (active_set.hpp, detail::tresca_fixed_point) with each box
// QP solved on the sparse stiffness (box_qp_methods.hpp).
#include <vector>

#include "contact/sparse/qp/box_qp_methods.hpp"
#include "contact/sparse/transitions/transitions.hpp"

namespace stackbeam::detail::sparse {

namespace {
constexpr int kTrescaIterations = 100;  // as in the dense solver
}  // namespace

/// Fixed point on the friction limits, as in the dense solver (contact/exact.cpp): each
/// pass solves the problem with the limits frozen (Tresca), a box-constrained convex QP;
/// the limits are updated from its normal forces until they settle to kAccept x tolerance
/// (in metres); its final working set gives the modes.
///
/// Each box QP: block principal pivoting first (few factorisations where it settles: the
/// small problems); if it does not settle in its 50 passes, the interior-point method
/// (15-45 iterations on every box QP measured, however degenerate; 10 identical leaves x
/// 100 from rest: 34 instead of 50 factorisations per step with the Tresca fixed point
/// alone, docs/decisions/006-interior-point-box-qp.md); the monotone primal method (one factorisation per working-set
/// change, cannot cycle) if neither does. Each method starts from the QP's own start.
bool tresca_fixed_point(SparsePath& path, const Step& step, Eigen::VectorXd& p, Eigen::VectorXd& z, SolveResult& r) {
    const SparseStiffness& st = path.stiffness();
    const Eigen::VectorXd& d = step.d;
    const int n = static_cast<int>(d.size());
    const double accept = kAccept * path.options.tolerance_m;
    std::vector<BoxQpFn> methods;
    switch (path.switches.box_qp) {
        case BoxQpMethod::pivoting: methods = {box_qp_pivoting, box_qp_interior_point, box_qp_primal}; break;
        case BoxQpMethod::interior_point: methods = {box_qp_interior_point, box_qp_pivoting, box_qp_primal}; break;
    }
    bool s_current = false;  // path.s = G z - d of the final z, made once when needed
    const bool settled = detail::tresca_fixed_point(
        path.modes, path.laws, n, p, accept, kTrescaIterations, path.options.tresca_anderson_depth,
        [&](const Eigen::VectorXd& lower, const Eigen::VectorXd& upper, std::vector<signed char>& at_bound) {
            ++r.tresca_iterations;
            const std::vector<signed char> start = at_bound;
            const Eigen::VectorXd p_start = p;
            const BoxQp box{step, lower, upper, accept};
            for (std::size_t i = 0; i + 1 < methods.size(); ++i) {
                if (methods[i](path, box, p, z, at_bound, r)) return true;
                at_bound = start;
                p = p_start;
            }
            return methods.back()(path, box, p, z, at_bound, r);
        },
        [&](int row) { return st.diag[row]; },
        [&](int row) {
            if (!s_current) path.s = st.Grow * z - d;
            s_current = true;
            return path.s[row];
        });
    if (settled && !s_current) path.s = st.Grow * z - d;
    return settled;
}

}  // namespace stackbeam::detail::sparse
