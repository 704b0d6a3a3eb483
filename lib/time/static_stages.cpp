// The quasi-static solves before t = 0 (static_stages.hpp).
#include "time/static_stages.hpp"

#include <cmath>

#include <Eigen/SparseCholesky>

#include "stackbeam/errors.hpp"
#include "time/contact_state.hpp"

namespace stackbeam {

detail::StaticState detail::massless_static_state(const System& system, const ContactLaws& laws, double force_n,
                                                  ContactPath path, StepContactSolver& solver, Eigen::VectorXd& p,
                                                  Eigen::VectorXd& d, const std::string& what) {
    const double k = system.stiffness_n_per_m();
    const Eigen::VectorXd& c = system.coupling();
    const int w_dof = system.num_reduced_dofs() - 1;
    StaticState out;
    if (system.num_components() == 0) {
        out.w_m = force_n / k;
        out.z = system.reduced_displacements(p, out.w_m);
        return out;
    }
    // One load parameter u = [1], the load itself in the forms (so that both take it exactly):
    // dense W = C' + c c^T / k, q = c F / k - d (R's balance k w - c^T p = F eliminated), z from
    // p and w = (F + c^T p) / k; sparse K z = F e_w + G^T p, s = G z + c_L p - d on every DOF.
    StepSystem sys;
    sys.rows = system.num_components();
    sys.dense = [&] {
        DenseStepForm f;
        f.W = system.compliance_held() + (1.0 / k) * c * c.transpose();
        f.Q = c * (force_n / k);
        f.displacements = [&system, &c, k, force_n](const Eigen::VectorXd&, const Eigen::VectorXd& pp) {
            return system.reduced_displacements(pp, (force_n + c.dot(pp)) / k);
        };
        return f;
    };
    sys.sparse = [&] {
        SparseStepForm f;
        f.K = system.stiffness_reduced();
        f.G = system.contact_rows();
        f.layer_compliance = sparse_layer(system);
        f.B.resize(w_dof + 1, 1);
        f.B.insert(w_dof, 0) = force_n;
        f.B.makeCompressed();
        return f;
    };
    StepProblem pr;
    static_cast<ContactLaws&>(pr) = laws;
    pr.op = std::make_shared<const ContactOperator>(sys, path, SolverKind::exact);
    pr.u = Eigen::VectorXd::Ones(1);
    pr.d = d;
    out.solve = solver.solve(pr, p, out.z);
    if (!out.solve.converged) throw SolverError(what + ": " + out.solve.message, 0, 0.0, out.solve.residual_m);
    reanchor(laws, p, relative_positions(system, out.z, p), d);
    out.w_m = out.z[w_dof];
    return out;
}

StepSystem detail::held_body_system(const System& system) {
    StepSystem sys;
    sys.rows = system.num_components();
    sys.dense = [&system] {
        DenseStepForm f;
        f.W = system.compliance_held();
        f.Q = system.coupling();
        f.displacements = [&system](const Eigen::VectorXd& u, const Eigen::VectorXd& p) {  // z_r
            const Eigen::VectorXd z = system.reduced_displacements(p, u[0]);
            return Eigen::VectorXd(z.head(z.size() - 1));
        };
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

Eigen::VectorXd detail::static_state(const System& system, const ContactLaws& laws, const Eigen::VectorXd& b,
                                     double w_held_m, const SimulationOptions& options, Eigen::VectorXd& p,
                                     Eigen::VectorXd& d, const std::string& what, SolveResult* result) {
    const int nz = system.num_reduced_dofs(), w_dof = nz - 1;
    const bool held = !std::isnan(w_held_m);
    const Eigen::SparseMatrix<double>& K = system.stiffness_reduced();
    const Eigen::SparseMatrix<double>& G = system.contact_rows();
    // the stiffness form: with R held, K_rr z_r = G_r^T p + b_r - K_rw w, s = G_r z_r + G_w w + c_L p - d
    SparseStepForm form;
    Eigen::VectorXd b_form, d_form;
    if (held) {
        form.K = K.topLeftCorner(w_dof, w_dof);
        form.G = G.leftCols(w_dof);
        const Eigen::VectorXd krw_w = Eigen::VectorXd(K.block(0, w_dof, w_dof, 1)) * w_held_m;
        b_form = b.size() > 0 ? Eigen::VectorXd(b.head(w_dof) - krw_w) : Eigen::VectorXd(-krw_w);
        d_form = d - Eigen::VectorXd(G.col(w_dof)) * w_held_m;
    } else {
        form.K = K;
        form.G = G;
        b_form = b.size() > 0 ? b : Eigen::VectorXd::Zero(K.rows());
        d_form = d;
    }
    form.layer_compliance = sparse_layer(system);
    if (system.num_components() == 0) {  // no contact: K z = b (R held: on z_r)
        Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(form.K);
        Eigen::VectorXd z = Eigen::VectorXd::Constant(nz, held ? w_held_m : 0.0);
        if (held) z.head(w_dof) = ldlt.solve(b_form);
        else z = ldlt.solve(b_form);
        if (result) *result = SolveResult{};
        return z;
    }
    SolverOptions exact = options.solver;
    exact.kind = SolverKind::exact;
    // the stiffness form whatever the model's size (a one-off solve): the operator forced sparse
    StepSystem sys;
    sys.rows = system.num_components();
    sys.sparse = [&form] { return form; };
    StepProblem pr;
    pr.op = std::make_shared<const ContactOperator>(sys, ContactPath::sparse, SolverKind::exact);
    static_cast<ContactLaws&>(pr) = laws;
    pr.u = b_form;
    pr.d = d_form;
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

bool detail::static_stages(const System& system, const ContactLaws& laws, const Eigen::VectorXd& weight,
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
