// The sparse contact path: the exact solver's active-set method on
//     K z = b + G^T p,  s = G z - d       (SparseContactProblem, contact.hpp)
// without ever forming the dense W = G K^-1 G^T.
//
// Design (why a saddle-point system per set of modes):
//  - For a set of modes the contact conditions are linear: held rows (closed normal,
//    stuck tangential, bonded) impose G_S z = d_S; slipping rows carry a force affine in
//    their pair's normal force, p_t = e_t + D p_n; open / free rows carry p = e = 0.
//    With z and p_S as unknowns this is one sparse system
//        [ K     -G_S^T - G_slip^T D ] [z  ]   [b + G^T e]
//        [ G_S    0                  ] [p_S] = [d_S      ]
//    whose size and fill grow linearly with the number of elements (the contact rows
//    are local: each touches the DOFs of two leaves at one node). It is not symmetric
//    when a slip row is coupled to its normal force, and it is indefinite, so it is
//    factorised by a sparse LU (Eigen::SparseLU, COLAMD ordering: no extra package).
//  - The factorisation depends only on the modes; it is kept and reused while they
//    stay, like the dense solver's LU. Within one set of modes the solution is affine in
//    the right-hand side; on the closed-form stepper only b (the rigid body's load,
//    one entry) changes from step to step, and e, d_S only when the modes or anchors
//    do. So two back-solves per set of modes ({unit b entry} and {e, d_S}) are cached
//    and a step whose modes stay costs O(n) (a linear combination, one product with G),
//    not a back-solve.
//  - The diagonal of W scales force violations to metres, exactly as in the dense
//    solver (so both take the same decisions). It is computed once per (K, G) from a
//    sparse Cholesky factor K = P^T L L^T P as W_ii = ||L^-1 P g_i||^2, in blocks of
//    columns. This is the one part whose cost is not linear (about m times the
//    factor's fill); it is done once per run.
//  - Mode switching (violations, block principal pivoting, Murty's rule) is the code
//    of the dense solver (active_set.hpp). The dense solver turns to a Tresca fixed
//    point on a dense box QP after max_active_set_iterations passes; here the passes
//    simply continue (up to kMaxPasses, each one a sparse factorisation), and if they
//    still do not settle, the dense problem is built (to_dense()) and the dense exact
//    solver finishes the step: correct, but O(m^2) memory; reported as fell_back.
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <cstring>

#include "active_set.hpp"
#include "contact_solvers.hpp"
#include "stackbeam/contact.hpp"
#include "stackbeam/errors.hpp"

namespace stackbeam {

using SpMat = Eigen::SparseMatrix<double>;

void SparseContactProblem::validate() const {
    const int n = static_cast<int>(K.rows());
    if (K.cols() != n) throw InputError("problem.K", "must be square");
    if (G.cols() != n)
        throw InputError("problem.G", "has " + std::to_string(G.cols()) + " columns: must match K (" + std::to_string(n) + ")");
    if (G.rows() != d.size())
        throw InputError("problem.G", "has " + std::to_string(G.rows()) + " rows: must match d (" + std::to_string(d.size()) + ")");
    if (b.size() != n) throw InputError("problem.b", "must have one entry per row of K");
    if (!b.allFinite()) throw InputError("problem.b", "has a non-finite entry");
    // the pair laws: checked by ContactProblem::validate on a problem of the same size
    ContactProblem laws;
    laws.W = Eigen::MatrixXd::Zero(size(), size());
    laws.q = d;
    laws.pairs = pairs;
    laws.tau_rule = tau_rule;
    laws.tau_previous_n = tau_previous_n;
    laws.validate();
}

ContactProblem SparseContactProblem::to_dense() const {
    Eigen::SimplicialLLT<SpMat> llt(K);
    if (llt.info() != Eigen::Success) throw InputError("problem.K", "is not positive definite");
    ContactProblem pr;
    const Eigen::MatrixXd X = llt.solve(Eigen::MatrixXd(G.transpose()));
    pr.W = G * X;
    pr.W = 0.5 * (pr.W + pr.W.transpose()).eval();
    pr.q = G * llt.solve(b) - d;
    pr.pairs = pairs;
    pr.tau_rule = tau_rule;
    pr.tau_previous_n = tau_previous_n;
    return pr;
}

namespace {
bool same_matrix(const SpMat& a, const SpMat& b) {
    if (a.rows() != b.rows() || a.cols() != b.cols() || a.nonZeros() != b.nonZeros()) return false;
    if (!a.isCompressed() || !b.isCompressed()) return false;
    const auto nnz = static_cast<std::size_t>(a.nonZeros());
    return std::memcmp(a.valuePtr(), b.valuePtr(), nnz * sizeof(double)) == 0 &&
           std::memcmp(a.innerIndexPtr(), b.innerIndexPtr(), nnz * sizeof(int)) == 0 &&
           std::memcmp(a.outerIndexPtr(), b.outerIndexPtr(), (a.outerSize() + 1) * sizeof(int)) == 0;
}

// Passes after the first max_active_set_iterations before the dense fallback; each
// pass may factorise. Block principal pivoting with Murty's rule as the safeguard
// settles in a few passes on the transitions seen in the leaf-spring runs.
constexpr int kMaxPasses = 60;
constexpr int kBudget = 3;          // as in the dense solver
constexpr double kAccept = 1e-3;    // as in the dense solver: threshold kAccept x tolerance

struct SingularModes {};            // a set of modes whose saddle-point system is singular

bool same_laws(const std::vector<ContactPair>& a, const std::vector<ContactPair>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t k = 0; k < a.size(); ++k)
        if (a[k].kind != b[k].kind || a[k].friction_coefficient != b[k].friction_coefficient ||
            a[k].preload_n != b[k].preload_n || a[k].row_n != b[k].row_n || a[k].row_t != b[k].row_t)
            return false;
    return true;
}
}  // namespace

struct SparseContactSolver::Impl {
    SolverOptions options;
    // structure of the last problem
    SpMat K, G;
    Eigen::SimplicialLLT<SpMat, Eigen::Lower, Eigen::AMDOrdering<int>> k_llt;
    Eigen::VectorXd diag;                // diagonal of W
    double g_norm_inf = 0.0;             // max row sum of |G|
    ContactProblem laws;                 // pairs and tau rule; W empty, q zero (sizes only)
    detail::ModeSet modes;
    detail::ModeLinearization lin;
    // factorisation of the current modes
    std::vector<signed char> lu_key;
    Eigen::SparseLU<SpMat, Eigen::COLAMDOrdering<int>> lu;
    bool lu_ok = false;
    std::vector<int> pos;                // row -> index in lin.S, or -1
    // cached back-solves of the current factorisation
    int unit_dof = -1;                   // x_unit solves [e_unit_dof; 0]
    Eigen::VectorXd x_unit;
    Eigen::VectorXd const_e, const_dS;   // x_const solves [G^T e; d_S] for these e, d_S
    Eigen::VectorXd x_const;
    bool const_ok = false;
    Eigen::VectorXd s, x, rhs;

    void reset_structure(const SparseContactProblem& pr) {
        pr.validate();
        K = pr.K;
        G = pr.G;
        K.makeCompressed();
        G.makeCompressed();
        k_llt.compute(K);
        if (k_llt.info() != Eigen::Success) throw InputError("problem.K", "is not positive definite");
        // diag(G K^-1 G^T) = column norms of L^-1 P G^T, in blocks of columns
        const int m = pr.size();
        diag.resize(m);
        const SpMat PGt = k_llt.permutationP() * SpMat(G.transpose());
        constexpr int kBlock = 64;
        Eigen::MatrixXd Y;
        for (int j0 = 0; j0 < m; j0 += kBlock) {
            const int nb = std::min(kBlock, m - j0);
            Y = Eigen::MatrixXd(PGt.middleCols(j0, nb));
            k_llt.matrixL().solveInPlace(Y);
            diag.segment(j0, nb) = Y.colwise().squaredNorm().transpose();
        }
        g_norm_inf = 0.0;
        const SpMat absG = G.cwiseAbs();
        const Eigen::VectorXd rows = absG * Eigen::VectorXd::Ones(G.cols());
        if (m > 0) g_norm_inf = rows.maxCoeff();
        laws.W.resize(0, 0);
        laws.q = Eigen::VectorXd::Zero(m);
        laws.pairs = pr.pairs;
        lu_key.clear();
        lu_ok = false;
        const_ok = false;
        unit_dof = -1;
        modes.nmode.clear();
    }

    /// s = G z - d for z = K^-1 (b + G^T p).
    Eigen::VectorXd positions_of(const SparseContactProblem& pr, const Eigen::VectorXd& p, Eigen::VectorXd& z) {
        z = k_llt.solve(pr.b + G.transpose() * p);
        return G * z - pr.d;
    }

    /// Solves the linear problem of the current modes into p and z; returns 1 if it factorised.
    int solve_modes(const SparseContactProblem& pr, Eigen::VectorXd& p, Eigen::VectorXd& z) {
        const int n = static_cast<int>(K.rows()), m = pr.size();
        modes.linearize(laws, lin);
        const auto& S = lin.S;
        const int ms = static_cast<int>(S.size());
        pos.assign(m, -1);
        for (int i = 0; i < ms; ++i) pos[S[i]] = i;
        int factorised = 0;
        std::vector<signed char> key = modes.key();
        if (key != lu_key) {
            // [K, -G_S^T - G_slip^T D; G_S, 0]
            std::vector<Eigen::Triplet<double>> t;
            t.reserve(static_cast<std::size_t>(K.nonZeros() + 4 * G.nonZeros()));
            for (int j = 0; j < n; ++j)
                for (SpMat::InnerIterator it(K, j); it; ++it) t.emplace_back(it.row(), it.col(), it.value());
            const SpMat Gt = G.transpose();  // column r = contact row r
            for (int i = 0; i < ms; ++i) {
                for (SpMat::InnerIterator it(Gt, S[i]); it; ++it) {
                    t.emplace_back(it.row(), n + i, -it.value());
                    t.emplace_back(n + i, it.row(), it.value());
                }
            }
            for (std::size_t a = 0; a < lin.coupled.size(); ++a) {
                const int col = pos[lin.coupled[a].second];
                if (col < 0) continue;  // the normal row is not held: its force is fixed (e)
                for (SpMat::InnerIterator it(Gt, lin.coupled[a].first); it; ++it)
                    t.emplace_back(it.row(), n + col, -lin.coef[a] * it.value());
            }
            SpMat A(n + ms, n + ms);
            A.setFromTriplets(t.begin(), t.end());
            A.makeCompressed();
            lu.compute(A);
            lu_ok = lu.info() == Eigen::Success;
            lu_key = std::move(key);
            const_ok = false;
            unit_dof = -1;
            factorised = 1;
        }
        if (!lu_ok) throw SingularModes{};
        // right-hand side [b + G^T e; d_S] = b-part + constant part
        Eigen::VectorXd dS(ms);
        for (int i = 0; i < ms; ++i) dS[i] = pr.d[S[i]];
        if (!const_ok || const_e != lin.e || const_dS != dS) {
            rhs.setZero(n + ms);
            rhs.head(n) = G.transpose() * lin.e;
            rhs.tail(ms) = dS;
            x_const = lu.solve(rhs);
            const_e = lin.e;
            const_dS = dS;
            const_ok = true;
        }
        // b: one nonzero entry (the closed-form stepper's load on the rigid body) is a
        // multiple of a cached unit solve; anything else is solved directly.
        int nz = -1, count = 0;
        for (int i = 0; i < n; ++i)
            if (pr.b[i] != 0.0) {
                nz = i;
                ++count;
            }
        if (count == 0) {
            x = x_const;
        } else if (count == 1) {
            if (unit_dof != nz) {
                rhs.setZero(n + ms);
                rhs[nz] = 1.0;
                x_unit = lu.solve(rhs);
                unit_dof = nz;
            }
            x = x_const + pr.b[nz] * x_unit;
        } else {
            rhs.setZero(n + ms);
            rhs.head(n) = pr.b;
            x = x_const + lu.solve(rhs);
        }
        z = x.head(n);
        p = lin.e;
        for (int i = 0; i < ms; ++i) p[S[i]] = x[n + i];
        modes.put_slip_forces(laws, p);  // p_t = e_t + D p_n, written with the friction-limit formula
        return factorised;
    }

    int count_violations(const SparseContactProblem& pr, const Eigen::VectorXd& p, const Eigen::VectorXd& z) {
        s = G * z - pr.d;
        const double roundoff = 1e-13 * (pr.d.lpNorm<Eigen::Infinity>() + g_norm_inf * z.lpNorm<Eigen::Infinity>());
        return modes.count_violations(laws, p, s, diag, std::max(kAccept * options.tolerance_m, roundoff));
    }
};

SparseContactSolver::SparseContactSolver(const SolverOptions& options) : impl_(std::make_unique<Impl>()) {
    make_solver(options);  // validates the options
    if (options.kind != SolverKind::exact)
        throw InputError("solver.kind", std::string("value '") + to_string(options.kind) +
                                            "' is not available on the sparse contact path: it has the exact "
                                            "(active-set) solver only");
    impl_->options = options;
}

SparseContactSolver::~SparseContactSolver() = default;

const Eigen::VectorXd& SparseContactSolver::relative_positions() const { return impl_->s; }
const Eigen::VectorXd& SparseContactSolver::compliance_diagonal() const { return impl_->diag; }

SolveResult SparseContactSolver::solve(const SparseContactProblem& problem, Eigen::VectorXd& p, Eigen::VectorXd& z) {
    Impl& im = *impl_;
    const int m = problem.size();
    const int np = static_cast<int>(problem.pairs.size());
    if (!same_matrix(problem.K, im.K) || !same_matrix(problem.G, im.G) || !same_laws(im.laws.pairs, problem.pairs) ||
        im.laws.q.size() != m)
        im.reset_structure(problem);
    im.laws.tau_rule = problem.tau_rule;
    im.laws.tau_previous_n = problem.tau_previous_n;
    if (static_cast<int>(im.modes.nmode.size()) != np) {
        if (p.size() != m) p = Eigen::VectorXd::Zero(m);
        im.modes.init(im.laws, p, im.positions_of(problem, p, z));
    }
    SolveResult r;
    auto solve_modes = [&](Eigen::VectorXd& x) { return im.solve_modes(problem, x, z); };
    auto violations = [&](const Eigen::VectorXd& x) { return im.count_violations(problem, x, z); };
    // 1. From the previous step's modes; 2. more passes (each may factorise) if a transition
    //    needs them: block principal pivoting, Murty's least-index rule when it stalls.
    bool singular = false;
    try {
        r.converged = detail::active_set_passes(im.modes, im.laws, p, im.options.max_active_set_iterations, kBudget, r,
                                                solve_modes, violations) ||
                      detail::active_set_passes(im.modes, im.laws, p, kMaxPasses, kBudget, r, solve_modes, violations);
    } catch (const SingularModes&) {
        singular = true;  // a set of modes with dependent held rows: leave it to the dense solver
        im.lu_key.clear();
    }
    if (!r.converged) {
        // 3. Last resort: the dense problem and the dense exact solver (Tresca fixed point,
        //    Gauss-Seidel). O(m^2) memory; reported.
        const ContactProblem dense = problem.to_dense();
        SolverOptions o = im.options;
        SolveResult d = make_solver(o)->solve(dense, p);
        r.iterations += d.iterations;
        r.factorizations += d.factorizations;
        r.fell_back = true;
        r.converged = d.converged;
        if (!d.converged)
            r.message = std::string("sparse path: the active-set passes ") +
                        (singular ? "met a singular set of modes" : "did not settle") +
                        " and the dense fallback failed: " + d.message;
        im.s = im.positions_of(problem, p, z);
        im.modes.init(im.laws, p, im.s);
    }
    r.residual_m = error_vector(im.laws, p, im.s).norm();
    r.natural_residual_m = detail::natural_map_diag(im.laws, im.diag, p, im.s).norm();
    if (r.converged && !(r.residual_m < im.options.tolerance_m)) {
        r.converged = false;
        r.message = "sparse path (active set) ended with ||v|| = " + format_value(r.residual_m) +
                    " m above the tolerance " + format_value(im.options.tolerance_m) + " m (natural-map residual " +
                    format_value(r.natural_residual_m) + " m)";
    }
    return r;
}

}  // namespace stackbeam
