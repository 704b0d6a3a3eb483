// What the time-stepping modes share (step_record.hpp): the record's state part, the
// anchors, the previous step's friction limits and the static equilibrium.
#include "time/step_record.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/SparseCholesky>

#include "stackbeam/errors.hpp"

namespace stackbeam {

std::vector<PairRecord> detail::pair_records(const System& system, const ContactProblem& laws, const Eigen::VectorXd& p,
                                             const Eigen::VectorXd& rel) {
    std::vector<PairRecord> out(laws.pairs.size());
    const Eigen::VectorXd& d0 = system.initial_offsets_m();
    for (std::size_t k = 0; k < out.size(); ++k) {
        const ContactPair& pr = laws.pairs[k];
        const PairSpec& spec = system.pair_spec(static_cast<int>(k));
        PairRecord& r = out[k];
        r.pair = static_cast<int>(k);
        r.interface_index = spec.interface_index;
        r.x_m = spec.x_m;
        r.state = pair_state(laws, static_cast<int>(k), p);
        if (pr.row_n >= 0) {
            r.p_n_n = p[pr.row_n];
            r.gap_m = std::max(0.0, d0[pr.row_n] - rel[pr.row_n]);
        }
        if (pr.row_t >= 0) {
            r.p_t_n = p[pr.row_t];
            r.slip_m = rel[pr.row_t];
        }
    }
    return out;
}

void detail::reanchor(const ContactProblem& laws, const Eigen::VectorXd& p, const Eigen::VectorXd& rel,
                      Eigen::VectorXd& d) {
    for (std::size_t j = 0; j < laws.pairs.size(); ++j) {
        const auto& pr = laws.pairs[j];
        if (pr.row_t < 0 || pr.kind == PairKind::bonded) continue;
        if (pair_state(laws, static_cast<int>(j), p) != PairState::stick) d[pr.row_t] = rel[pr.row_t];
    }
}

void detail::set_previous_step_limits(ContactProblem& problem, const Eigen::VectorXd& p) {
    for (int j = 0; j < static_cast<int>(problem.pairs.size()); ++j) {
        const auto& pr = problem.pairs[j];
        const double pn = pr.row_n >= 0 ? p[pr.row_n] : 0.0;
        problem.tau_previous_n[j] = pr.kind == PairKind::clamp ? std::max(0.0, pr.preload_n - pn) : std::max(0.0, -pn);
    }
}

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

int detail::first_rigid_pair(const System& system) {
    const Eigen::VectorXd& c = system.layer_compliance_m_per_n();
    for (int kk = 0; kk < static_cast<int>(system.pairs().size()); ++kk) {
        const auto& cp = system.pairs()[kk];
        if ((cp.row_n >= 0 && !(c[cp.row_n] > 0.0)) || (cp.row_t >= 0 && !(c[cp.row_t] > 0.0))) return kk;
    }
    return -1;
}


Eigen::VectorXd detail::static_state(const System& system, const ContactProblem& laws, const Eigen::VectorXd& b,
                                     double w_held_m, const SimulationOptions& options, Eigen::VectorXd& p,
                                     Eigen::VectorXd& d, const std::string& what, SolveResult* result) {
    const Eigen::SparseMatrix<double>& K = system.stiffness_reduced();
    const Eigen::SparseMatrix<double>& G = system.contact_rows();
    const int nz = static_cast<int>(K.rows()), w_dof = nz - 1;
    const bool held = !std::isnan(w_held_m);
    SparseContactProblem st;
    if (held) {  // K_rr z_r = G_r^T p + b_r - K_rw w,  s = G_r z_r + G_w w + c_L p - d
        st.K = K.topLeftCorner(w_dof, w_dof);
        st.G = G.leftCols(w_dof);
        st.b = b.head(w_dof) - Eigen::VectorXd(K.block(0, w_dof, w_dof, 1)) * w_held_m;
        st.d = d - Eigen::VectorXd(G.col(w_dof)) * w_held_m;
    } else {
        st.K = K;
        st.G = G;
        st.b = b;
        st.d = d;
    }
    st.layer_compliance = sparse_layer(system);
    st.pairs = laws.pairs;
    st.tau_rule = laws.tau_rule;
    st.tau_previous_n = laws.tau_previous_n;
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
    SparseContactSolver solver(exact, options.sparse_tuning);
    Eigen::VectorXd z = Eigen::VectorXd::Zero(nz), zs;
    if (p.size() != system.num_components()) p = Eigen::VectorXd::Zero(system.num_components());
    const SolveResult r = solver.solve(st, p, zs);
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

void detail::fill_state(const System& system, const ContactProblem& laws, const Eigen::VectorXd& p, double w_m,
                        double w_dot_m_per_s, double strain_energy_j, double dissipated_energy_j, double e0_j,
                        const LoadState& load, StepRecord& r) {
    const double f = system.model().whole_spring_factor();
    r.w_m = w_m;
    r.w_dot_m_per_s = w_dot_m_per_s;
    const double cp = p.size() > 0 ? system.coupling().dot(p) : 0.0;
    r.spring_force_n = f * (system.stiffness_n_per_m() * w_m - cp);
    r.external_force_n = load.external_force_n;
    r.force_on_mass_n = load.prescribed ? load.force_on_mass_n : load.external_force_n - r.spring_force_n;
    r.base_displacement_m = load.base_displacement_m;
    r.external_work_j = load.external_work_j;
    // The probe pair may carry no tangential component (mu = 0, or fixed by a support):
    // its friction force is then zero. NaN only when the model has no probe at all.
    const int probe = system.probe_pair();
    const bool has_probe = system.model().probe_pair() >= 0;
    r.probe_friction_force_n = !has_probe ? std::numeric_limits<double>::quiet_NaN()
                               : (probe >= 0 && system.pairs()[probe].row_t >= 0) ? p[system.pairs()[probe].row_t]
                                                                                   : 0.0;
    r.n_stick = r.n_slip = r.n_open = 0;
    for (int k = 0; k < static_cast<int>(laws.pairs.size()); ++k) {
        const PairState s = pair_state(laws, k, p);
        if (s == PairState::stick) ++r.n_stick;
        else if (s == PairState::slip) ++r.n_slip;
        else ++r.n_open;
    }
    r.kinetic_energy_j = 0.5 * system.model().spec().rigid_body.mass_kg * w_dot_m_per_s * w_dot_m_per_s;
    r.strain_energy_j = strain_energy_j;
    r.dissipated_energy_j = dissipated_energy_j;
    r.energy_balance_error_j =
        e0_j + load.external_work_j - (r.kinetic_energy_j + r.strain_energy_j + r.dissipated_energy_j);
}

}  // namespace stackbeam
