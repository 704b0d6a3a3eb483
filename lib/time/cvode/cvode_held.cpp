// Mode "cvode" with leaf inertia, bonded and frictionless stacks (cvode_held.hpp, docs/time-integration.md).
#include "time/cvode/cvode_held.hpp"

#include <sunmatrix/sunmatrix_band.h>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <cmath>
#include <string>

#include "stackbeam/errors.hpp"
#include "time/contact_state.hpp"
#include "time/record.hpp"
#include "fe/tied_shape.hpp"
#include "time/cvode/sundials.hpp"
#include "time/initial_state.hpp"

namespace stackbeam::detail {

struct CvodeHeldStepper::Impl {
    Impl(const System& system, const SimulationOptions& options) : sys(system), opt(options) {}
    Impl(const Impl&) = delete;
    Impl& operator=(const Impl&) = delete;
    const System& sys;
    SimulationOptions opt;
    int n = 0, r = 0;
    Eigen::SparseMatrix<double> K, M;
    std::vector<int> held;     // the held contact rows (bonded: both; mu = 0: the normal one), rigid ones
    // Held rows with an elastic layer (system.hpp) are springs of stiffness 1/c_L in K instead:
    // K = K_leaves + G_L^T D G_L, load f_L = G_L^T D d_L, their force p_L = -D (G_L z - d_L).
    std::vector<int> springs;  // those rows
    Eigen::SparseMatrix<double> GL;  // their rows of G
    Eigen::VectorXd DL, dL;    // their stiffness 1/c_L [N/m] and offsets [m]
    Eigen::VectorXd fL;        // G_L^T D d_L [N]
    Eigen::MatrixXd Gd;        // the held contact rows of G, dense [-]
    Eigen::VectorXd dC;        // their offsets [m]
    double F_ref = 1.0;        // force scale of the release check [N]
    Eigen::MatrixXd N;         // orthonormal basis of null(G), n x r
    Eigen::VectorXd zp;        // particular solution of G z = d [m]
    Eigen::MatrixXd Phi;       // mass-normalised modes of (N^T K N, N^T M N): q = Phi xi
    Eigen::VectorXd om;        // their circular frequencies [rad/s]
    Eigen::MatrixXd NPhi;      // N Phi: z = z_p + NPhi xi
    Eigen::VectorXd g;         // modal load -Phi^T N^T K z_p
    Eigen::LDLT<Eigen::MatrixXd> GGt;  // G G^T, for the contact forces
    ContactProblem laws;       // the pairs (for the record's pair states)
    Eigen::VectorXd p_out, rel_out;  // contact forces [N] and relative positions G z [m] (all rows) at the output
    double e0 = 0.0;
    long out_index = 0, num_out = 0;
    StepRecord rec;
    CvodeStats st;

    /// The held rows (bonded: both components; frictionless: the normal one): rigid ones held
    /// (Gd, dC), those with an elastic layer springs in K (K = K_leaves + G_L^T D G_L).
    void split_rows() {
        const auto& pairs = sys.pairs();
        for (std::size_t j = 0; j < pairs.size(); ++j) {
            const auto& pr = pairs[j];
            const Eigen::VectorXd& layer = sys.layer_compliance_m_per_n();
            for (int row : {pr.row_n, pr.kind == PairKind::bonded ? pr.row_t : -1}) {
                if (row < 0) continue;
                (layer[row] > 0.0 ? springs : held).push_back(row);
            }
        }
        K = sys.stiffness_reduced();
        {
            const int ns = static_cast<int>(springs.size());
            const Eigen::SparseMatrix<double, Eigen::RowMajor> Grow = sys.contact_rows();
            std::vector<Eigen::Triplet<double>> t;
            DL.resize(ns);
            dL.resize(ns);
            for (int k = 0; k < ns; ++k) {
                const int row = springs[k];
                for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(Grow, row); it; ++it)
                    t.emplace_back(k, static_cast<int>(it.col()), it.value());
                DL[k] = 1.0 / sys.layer_compliance_m_per_n()[row];
                dL[k] = sys.initial_offsets_m()[row];
            }
            GL.resize(ns, K.cols());
            GL.setFromTriplets(t.begin(), t.end());
            const Eigen::SparseMatrix<double> GLt = GL.transpose();
            if (ns > 0) K = (K + GLt * DL.asDiagonal() * GL).pruned();  // rigid stacks: K as it was
            fL = GLt * DL.cwiseProduct(dL);
        }
        M = sys.mass_reduced();
        n = static_cast<int>(K.rows());
        const int m = static_cast<int>(held.size());
        {
            const Eigen::MatrixXd Gall(sys.contact_rows());
            Gd.resize(m, n);
            dC.resize(m);
            for (int k = 0; k < m; ++k) {
                Gd.row(k) = Gall.row(held[k]);
                dC[k] = sys.initial_offsets_m()[held[k]];
            }
        }
        laws.pairs = pairs;
        laws.tau_previous_n = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(pairs.size()));
    }

    /// The null space N of the held rows, the particular solution z_p and the modes (Phi, om)
    /// of (N^T K N, N^T M N); throws InputError when the held stack has no free motion.
    void null_space_modes() {
        // null(G) from a QR of G^T: its last n - rank columns of Q
        const int m = static_cast<int>(held.size());
        const Eigen::VectorXd& d = dC;
        if (m > 0) {
            Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Gd.transpose());
            const int rank = static_cast<int>(qr.rank());
            r = n - rank;
            const Eigen::MatrixXd Q = qr.householderQ();
            N = Q.rightCols(r);
            GGt.compute(Gd * Gd.transpose());
            zp = Gd.transpose() * GGt.solve(d);
        } else {  // no contact pair: every DOF free
            r = n;
            N = Eigen::MatrixXd::Identity(n, n);
            zp = Eigen::VectorXd::Zero(n);
        }
        if (r < 1) throw InputError("mode", "value 'cvode' with leaf inertia: the held stack has no free motion");
        Mt = N.transpose() * (M * N);
        const Eigen::MatrixXd Kt = N.transpose() * (K * N);
        if (Eigen::LLT<Eigen::MatrixXd>(Mt).info() != Eigen::Success)
            throw InputError("leaves[].density_kg_per_m3", "mode cvode with leaf inertia needs every leaf massive (> 0)");
        Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(Kt, Mt);
        if (eig.info() != Eigen::Success || eig.eigenvalues().minCoeff() <= 0.0)
            throw SolverError("cvode mode (leaf inertia): the modal analysis of the held stack failed", 0, 0.0, 0.0);
        Phi = eig.eigenvectors();
        om = eig.eigenvalues().cwiseSqrt();
        g = springs.empty() ? Eigen::VectorXd(-Phi.transpose() * Eigen::VectorXd(N.transpose() * (K * zp)))
                            : Eigen::VectorXd(Phi.transpose() * Eigen::VectorXd(N.transpose() * (fL - K * zp)));
        NPhi = N * Phi;
    }
    Eigen::MatrixXd Mt;        // N^T M N

    std::unique_ptr<CvodeSession> cvode;

    // State in energy-norm modal coordinates, interleaved: y[2i] = om_i xi_i, y[2i+1] = xi_i'
    // (1/2 sum y^2 is the energy of the motion about z_p): y[2i]' = om_i y[2i+1],
    // y[2i+1]' = -om_i y[2i] + g_i. The Jacobian is constant and block diagonal (band 1, 1).
    static int rhs(sunrealtype, N_Vector yv, N_Vector ydot, void* data) {
        const auto* s = static_cast<const Impl*>(data);
        const double* Y = N_VGetArrayPointer(yv);
        double* D = N_VGetArrayPointer(ydot);
        for (int i = 0; i < s->r; ++i) {
            D[2 * i] = s->om[i] * Y[2 * i + 1];
            D[2 * i + 1] = -s->om[i] * Y[2 * i] + s->g[i];
        }
        return 0;
    }

    static int jac(sunrealtype, N_Vector, N_Vector, SUNMatrix Jm, void* data, N_Vector, N_Vector, N_Vector) {
        const auto* s = static_cast<const Impl*>(data);
        SUNMatZero(Jm);
        for (int i = 0; i < s->r; ++i) {
            SM_ELEMENT_B(Jm, 2 * i, 2 * i + 1) = s->om[i];
            SM_ELEMENT_B(Jm, 2 * i + 1, 2 * i) = -s->om[i];
        }
        return 0;
    }

    /// Modal coordinates xi, xi' of the state.
    void modal(Eigen::VectorXd& xi, Eigen::VectorXd& xid) const {
        const auto Y = cvode->y();
        xi.resize(r);
        xid.resize(r);
        for (int i = 0; i < r; ++i) {
            xi[i] = Y[2 * i] / om[i];
            xid[i] = Y[2 * i + 1];
        }
    }

    void fill(double t) {
        Eigen::VectorXd xi, xid;
        modal(xi, xid);
        const Eigen::VectorXd z = zp + NPhi * xi;
        const Eigen::VectorXd v = NPhi * xid;
        const Eigen::VectorXd a = NPhi * Eigen::VectorXd(g - om.cwiseProduct(om).cwiseProduct(xi));
        // the held components' forces: G^T p = M a + K z (least squares: exact on range(G^T))
        const Eigen::VectorXd pC = Gd.rows() > 0 ? Eigen::VectorXd(GGt.solve(Gd * Eigen::VectorXd(springs.empty() ? Eigen::VectorXd(M * a + K * z) : Eigen::VectorXd(M * a + K * z - fL))))
                                                 : Eigen::VectorXd();
        Eigen::VectorXd p = Eigen::VectorXd::Zero(sys.num_components());
        for (int k = 0; k < static_cast<int>(held.size()); ++k) p[held[k]] = pC[k];
        const Eigen::VectorXd spring_stretch = GL * z - dL;  // G_L z - d_L [m]
        for (int k = 0; k < static_cast<int>(springs.size()); ++k) p[springs[k]] = -DL[k] * spring_stretch[k];
        p_out = p;
        rel_out = relative_positions(sys, z, p);
        // a held unilateral pair must stay compressed (p_n <= 0): a release is an event,
        // not built yet with massive leaves
        for (const auto& pr : laws.pairs)
            if (pr.kind == PairKind::coulomb && pr.row_n >= 0 && p[pr.row_n] > 1e-6 * F_ref)
                throw SolverError("cvode mode (leaf inertia): a frictionless pair goes into tension (p_n = " +
                                      format_value(p[pr.row_n]) + " N) at t = " + format_value(t) +
                                      " s: contact events between massive leaves are not built yet, use mode newmark",
                                  out_index, t, 0.0);
        const double f = sys.model().whole_spring_factor();
        // leaves and layer: z^T K z / 2 - f_L^T z + d_L^T D d_L / 2 = z^T K_leaves z / 2 + (G_L z - d_L)^T D (G_L z - d_L) / 2
        const double strain = f * (0.5 * z.dot(K * z) - fL.dot(z) + 0.5 * dL.dot(DL.cwiseProduct(dL)));
        fill_state(sys, laws, p, z[n - 1], v[n - 1], strain, 0.0, e0, LoadState{}, rec);
        const double kinetic = 0.5 * f * v.dot(M * v);
        rec.leaf_kinetic_energy_j = kinetic - rec.kinetic_energy_j;
        rec.kinetic_energy_j = kinetic;
        rec.impact_loss_j = 0.0;
        rec.force_on_mass_n = sys.model().spec().rigid_body.mass_kg * a[n - 1];
        rec.energy_balance_error_j = e0 - (rec.kinetic_energy_j + rec.strain_energy_j);
        rec.t_s = t;
        rec.contact_iterations = 0;
        rec.factorizations = 0;
        rec.contact_residual_m = (Gd * z - dC).norm();
    }
};

CvodeHeldStepper::~CvodeHeldStepper() = default;

CvodeHeldStepper::CvodeHeldStepper(const System& system, const InitialState& start)
    : impl_(std::make_unique<Impl>(system, start.options)) {
    Impl& s = *impl_;
    s.split_rows();
    s.null_space_modes();

    // initial state: the tied static shape at w(0), the tied shape per unit w times w'(0)
    const Eigen::VectorXd z0 = tied_shape(s.K, system.contact_rows(), s.held, start.w0_m, system.initial_offsets_m());
    const Eigen::VectorXd v0 = start.wd0_m_per_s * tied_shape(s.K, system.contact_rows(), s.held, 1.0,
                                                              Eigen::VectorXd::Zero(system.num_components()));
    s.cvode = std::make_unique<CvodeSession>("cvode mode (leaf inertia)", 2 * s.r);
    {
        // xi = Phi^T Mt q (Phi^T Mt Phi = I), q = N^T (z - z_p)
        const Eigen::VectorXd xi = s.Phi.transpose() * (s.Mt * Eigen::VectorXd(s.N.transpose() * (z0 - s.zp)));
        const Eigen::VectorXd xid = s.Phi.transpose() * (s.Mt * Eigen::VectorXd(s.N.transpose() * v0));
        auto Y = s.cvode->y();
        for (int i = 0; i < s.r; ++i) {
            Y[2 * i] = s.om[i] * xi[i];
            Y[2 * i + 1] = xid[i];
        }
    }
    // atol, the same on every component (energy-norm units, sqrt(J) on the meshed part):
    // rtol sqrt(2 E0), so that the error is controlled relative to the whole motion's
    // energy (a leaf mode carrying 1e-8 of the energy is not resolved to rtol of its own
    // amplitude: BDF damps it), and at least the user's atol on w as an energy-norm
    // amplitude of the body's mode, sqrt(m) omega atol_m.
    const auto& body = system.model().spec().rigid_body;
    const double omega = std::sqrt(system.tied_stiffness_n_per_m() / body.mass_kg);
    s.F_ref = system.tied_stiffness_n_per_m() / system.model().whole_spring_factor() *
              std::max(std::abs(body.initial_displacement_m) + std::abs(body.initial_velocity_m_per_s) / omega, 1e-6);
    const double e_meshed = 0.5 * N_VDotProd(s.cvode->y_vector(), s.cvode->y_vector());
    s.cvode->atol().setConstant(std::max(std::sqrt(system.mass_kg()) * omega * s.opt.cvode.atol_m,
                                         s.opt.cvode.rtol * std::sqrt(2.0 * e_meshed)));

    s.cvode->create(CV_BDF, &Impl::rhs, &s, s.opt.cvode.rtol);
    s.cvode->set_max_order(2);
    s.cvode->set_limits(s.opt.cvode.max_step_s);
    s.cvode->use_band_newton(1, 1, &Impl::jac);  // the Jacobian is block diagonal (2 x 2 blocks)

    s.num_out = static_cast<long>(std::ceil(s.opt.t_end_s / s.opt.dt_s - 1e-9));
    s.fill(0.0);
    s.e0 = s.rec.kinetic_energy_j + s.rec.strain_energy_j;
    s.rec.energy_balance_error_j = 0.0;
}

const StepRecord& CvodeHeldStepper::advance() {
    Impl& s = *impl_;
    ++s.out_index;
    const double tout = s.out_index * s.opt.dt_s;
    double t = 0.0;
    s.cvode->advance(tout, CV_NORMAL, s.opt.cvode.max_steps, t);
    const CvodeCounters& cc = s.cvode->counters();
    s.st.steps = cc.steps;
    s.st.rhs_evaluations = cc.rhs_evaluations;
    s.st.jacobian_evaluations = cc.jacobian_evaluations;
    s.st.linear_setups = cc.linear_setups;
    s.fill(tout);
    return s.rec;
}

const StepRecord& CvodeHeldStepper::current() const noexcept { return impl_->rec; }
const CvodeStats& CvodeHeldStepper::stats() const noexcept { return impl_->st; }
long CvodeHeldStepper::record_index() const noexcept { return impl_->out_index; }
std::vector<PairRecord> CvodeHeldStepper::pairs() const {
    return pair_records(impl_->sys, impl_->laws, impl_->p_out, impl_->rel_out);
}
std::vector<LeafNodes> CvodeHeldStepper::nodes() const {
    const Impl& s = *impl_;
    Eigen::VectorXd xi, xid;
    s.modal(xi, xid);
    return s.sys.leaf_nodes(s.zp + s.NPhi * xi);
}
RunReport CvodeHeldStepper::report() const {
    RunReport rep;
    rep.mode = Mode::cvode;
    rep.cvode = impl_->st;
    rep.steps = impl_->st.steps;
    return rep;
}

}  // namespace stackbeam::detail
