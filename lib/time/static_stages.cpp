// The quasi-static solves before t = 0 (static_stages.hpp).
#include "time/static_stages.hpp"

#include <cmath>

#include <Eigen/SparseCholesky>

#include "stackbeam/errors.hpp"
#include "time/contact_state.hpp"

namespace stackbeam {

detail::StaticState detail::static_equilibrium_dense(const System& system, const ContactProblem& laws, double force_n,
                                                     ContactSolver& solver, Eigen::VectorXd& p, Eigen::VectorXd& d,
                                                     const std::string& what) {
    const double k = system.stiffness_n_per_m();
    const Eigen::VectorXd& c = system.coupling();
    StaticState out;
    if (system.num_components() > 0) {
        ContactProblem st = laws;
        st.W = system.compliance_held() + (1.0 / k) * c * c.transpose();
        st.q = c * (force_n / k) - d;
        out.solve = solver.solve(st, p);
        if (!out.solve.converged) throw SolverError(what + ": " + out.solve.message, 0, 0.0, out.solve.residual_m);
        reanchor(st, p, Eigen::VectorXd(st.W * p + st.q + d), d);
    }
    out.w_m = (force_n + (system.num_components() > 0 ? c.dot(p) : 0.0)) / k;
    return out;
}

StepSystem detail::held_body_system(const System& system) {
    StepSystem sys;
    sys.rows = system.num_components();
    sys.dense = [&system] {
        DenseStepForm f;
        f.W = system.compliance_held();
        f.Q = system.coupling();
        return f;
    };
    sys.sparse = [&system] {
        const Eigen::SparseMatrix<double>& K = system.stiffness_reduced();
        const Eigen::SparseMatrix<double>& G = system.contact_rows();
        const int w_dof = static_cast<int>(K.rows()) - 1;
        SparseStepForm f;
        f.K = K.topLeftCorner(w_dof, w_dof);
        f.G = G.leftCols(w_dof);
        f.layer_compliance = sparse_layer(system);
        const Eigen::VectorXd minus_krw = -Eigen::VectorXd(K.block(0, w_dof, w_dof, 1));
        f.B = minus_krw.sparseView();
        f.E = Eigen::VectorXd(G.col(w_dof)).sparseView();
        return f;
    };
    return sys;
}

SparseContactProblem detail::sparse_problem(const System& system, const ContactProblem& laws, const Eigen::VectorXd& b,
                                            const Eigen::VectorXd& d, double w_held_m) {
    const Eigen::SparseMatrix<double>& K = system.stiffness_reduced();
    const Eigen::SparseMatrix<double>& G = system.contact_rows();
    const int w_dof = static_cast<int>(K.rows()) - 1;
    SparseContactProblem st;
    if (!std::isnan(w_held_m)) {  // K_rr z_r = G_r^T p + b_r - K_rw w,  s = G_r z_r + G_w w + c_L p - d
        st.K = K.topLeftCorner(w_dof, w_dof);
        st.G = G.leftCols(w_dof);
        const Eigen::VectorXd krw_w = Eigen::VectorXd(K.block(0, w_dof, w_dof, 1)) * w_held_m;
        st.b = b.size() > 0 ? Eigen::VectorXd(b.head(w_dof) - krw_w) : Eigen::VectorXd(-krw_w);
        st.d = d - Eigen::VectorXd(G.col(w_dof)) * w_held_m;
    } else {
        st.K = K;
        st.G = G;
        st.b = b.size() > 0 ? b : Eigen::VectorXd::Zero(K.rows());
        st.d = d;
    }
    st.layer_compliance = sparse_layer(system);
    st.pairs = laws.pairs;
    st.tau_rule = laws.tau_rule;
    st.tau_previous_n = laws.tau_previous_n;
    return st;
}

Eigen::VectorXd detail::static_state(const System& system, const ContactProblem& laws, const Eigen::VectorXd& b,
                                     double w_held_m, const SimulationOptions& options, Eigen::VectorXd& p,
                                     Eigen::VectorXd& d, const std::string& what, SolveResult* result) {
    const int nz = system.num_reduced_dofs(), w_dof = nz - 1;
    const bool held = !std::isnan(w_held_m);
    SparseContactProblem st = sparse_problem(system, laws, b, d, w_held_m);
    if (system.num_components() == 0) {  // no contact: K z = b (R held: on z_r)
        Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(st.K);
        Eigen::VectorXd z = Eigen::VectorXd::Constant(nz, held ? w_held_m : 0.0);
        if (held) z.head(w_dof) = ldlt.solve(st.b);
        else z = ldlt.solve(st.b);
        if (result) *result = SolveResult{};
        return z;
    }
    SolverOptions exact = options.solver;
    exact.kind = SolverKind::exact;
    // the stiffness form whatever the model's size (a one-off solve): the operator forced sparse
    StepSystem sys;
    sys.rows = system.num_components();
    sys.sparse = [&st] {
        SparseStepForm f;
        f.K = st.K;
        f.G = st.G;
        f.layer_compliance = st.layer_compliance;
        return f;
    };
    StepProblem pr;
    pr.op = std::make_shared<const ContactOperator>(sys, ContactPath::sparse, SolverKind::exact);
    pr.pairs = st.pairs;
    pr.tau_rule = st.tau_rule;
    pr.tau_previous_n = st.tau_previous_n;
    pr.u = st.b;
    pr.d = st.d;
    StepContactSolver solver(exact, options.sparse_tuning);
    Eigen::VectorXd z = Eigen::VectorXd::Zero(nz), zs;
    if (p.size() != system.num_components()) p = Eigen::VectorXd::Zero(system.num_components());
    const SolveResult r = solver.solve(pr, p, zs);
    if (result) *result = r;
    if (!r.converged) throw SolverError(what + ": " + r.message, 0, 0.0, r.residual_m);
    if (held) {
        z.head(w_dof) = zs;
        z[w_dof] = w_held_m;
    } else {
        z = zs;
    }
    reanchor(laws, p, relative_positions(system, z, p), d);
    return z;
}

bool detail::static_stages(const System& system, const ContactProblem& laws, const Eigen::VectorXd& weight,
                           const SimulationOptions& options, Eigen::VectorXd& z, Eigen::VectorXd& p, Eigen::VectorXd& d,
                           SolveResult* result) {
    const ModelSpec& spec = system.model().spec();
    bool ran = false;
    if (needs_assembly(spec) && system.num_components() > 0) {
        z = static_state(system, laws, Eigen::VectorXd::Zero(system.num_reduced_dofs()), std::nan(""), options, p, d,
                         "assembly of the cambered leaves", result);
        ran = true;
    }
    if (weight.size() > 0 && weight.lpNorm<Eigen::Infinity>() > 0.0) {
        z = static_state(system, laws, weight, std::nan(""), options, p, d,
                         "static equilibrium under gravity", result);
        ran = true;
    }
    return ran;
}

}  // namespace stackbeam
