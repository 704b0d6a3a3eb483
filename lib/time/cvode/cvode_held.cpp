// Mode "cvode" with leaf inertia, bonded and frictionless stacks (cvode_held.hpp, docs/time-integration.md).
#include "time/cvode/cvode_held.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "fe/tied_shape.hpp"
#include "stackbeam/errors.hpp"
#include "time/contact_state.hpp"
#include "time/record.hpp"

namespace stackbeam::detail {

struct CvodeHeldStepper::Impl final : EventDriver {
    Impl(const System& system, const InitialState& start);

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
    Eigen::MatrixXd N;         // orthonormal basis of null(G), n x r
    Eigen::VectorXd zp;        // particular solution of G z = d [m]
    Eigen::MatrixXd Phi;       // mass-normalised modes of (N^T K N, N^T M N): q = Phi xi
    Eigen::VectorXd om;        // their circular frequencies [rad/s]
    Eigen::MatrixXd NPhi;      // N Phi: z = z_p + NPhi xi
    Eigen::VectorXd g;         // modal load -Phi^T N^T K z_p
    Eigen::LDLT<Eigen::MatrixXd> GGt;  // G G^T, for the contact forces
    Eigen::MatrixXd Mt;        // N^T M N

    /// The held rows (bonded: both components; frictionless: the normal one): rigid ones held
    /// (Gd, dC), those with an elastic layer springs in K (K = K_leaves + G_L^T D G_L).
    void split_rows() {
        const auto& pairs = system().pairs();
        for (std::size_t j = 0; j < pairs.size(); ++j) {
            const auto& pr = pairs[j];
            const Eigen::VectorXd& layer = system().layer_compliance_m_per_n();
            for (int row : {pr.row_n, pr.kind == PairKind::bonded ? pr.row_t : -1}) {
                if (row < 0) continue;
                (layer[row] > 0.0 ? springs : held).push_back(row);
            }
        }
        K = system().stiffness_reduced();
        {
            const int ns = static_cast<int>(springs.size());
            const Eigen::SparseMatrix<double, Eigen::RowMajor> Grow = system().contact_rows();
            std::vector<Eigen::Triplet<double>> t;
            DL.resize(ns);
            dL.resize(ns);
            for (int k = 0; k < ns; ++k) {
                const int row = springs[k];
                for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(Grow, row); it; ++it)
                    t.emplace_back(k, static_cast<int>(it.col()), it.value());
                DL[k] = 1.0 / system().layer_compliance_m_per_n()[row];
                dL[k] = system().initial_offsets_m()[row];
            }
            GL.resize(ns, K.cols());
            GL.setFromTriplets(t.begin(), t.end());
            const Eigen::SparseMatrix<double> GLt = GL.transpose();
            if (ns > 0) K = (K + GLt * DL.asDiagonal() * GL).pruned();  // rigid stacks: K as it was
            fL = GLt * DL.cwiseProduct(dL);
        }
        M = system().mass_reduced();
        n = static_cast<int>(K.rows());
        const int m = static_cast<int>(held.size());
        {
            const Eigen::MatrixXd Gall(system().contact_rows());
            Gd.resize(m, n);
            dC.resize(m);
            for (int k = 0; k < m; ++k) {
                Gd.row(k) = Gall.row(held[k]);
                dC[k] = system().initial_offsets_m()[held[k]];
            }
        }
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

    /// The state at t = 0: the tied static shape at w(0), moving in the tied shape per unit w
    /// times w'(0), in the energy-norm modal coordinates below.
    Vec initial_state(const InitialState& start) const {
        const System& sys = system();
        const Eigen::VectorXd z0 = tied_shape(K, sys.contact_rows(), held, start.w0_m, sys.initial_offsets_m());
        const Eigen::VectorXd v0 =
            start.wd0_m_per_s * tied_shape(K, sys.contact_rows(), held, 1.0, Eigen::VectorXd::Zero(sys.num_components()));
        // xi = Phi^T Mt q (Phi^T Mt Phi = I), q = N^T (z - z_p)
        const Eigen::VectorXd xi = Phi.transpose() * (Mt * Eigen::VectorXd(N.transpose() * (z0 - zp)));
        const Eigen::VectorXd xid = Phi.transpose() * (Mt * Eigen::VectorXd(N.transpose() * v0));
        Vec Y(2 * r);
        for (int i = 0; i < r; ++i) {
            Y[2 * i] = om[i] * xi[i];
            Y[2 * i + 1] = xid[i];
        }
        return Y;
    }

    // ---- the ODE (EventDriver's hooks) ---------------------------------------------------

    // State in energy-norm modal coordinates, interleaved: y[2i] = om_i xi_i, y[2i+1] = xi_i'
    // (1/2 sum y^2 is the energy of the motion about z_p): y[2i]' = om_i y[2i+1],
    // y[2i+1]' = -om_i y[2i] + g_i. The Jacobian is constant and block diagonal (band 1, 1).
    void derivatives(double, const double* Y, double* D) const override {
        for (int i = 0; i < r; ++i) {
            D[2 * i] = om[i] * Y[2 * i + 1];
            D[2 * i + 1] = -om[i] * Y[2 * i] + g[i];
        }
    }

    int band_jacobian(double, const State&, BandMatrixView J) const override {
        for (int i = 0; i < r; ++i) {
            J(2 * i, 2 * i + 1) = om[i];
            J(2 * i + 1, 2 * i) = -om[i];
        }
        return 0;
    }

    /// atol, the same on every component (energy-norm units, sqrt(J) on the meshed part):
    /// rtol sqrt(2 E0), so that the error is controlled relative to the whole motion's
    /// energy (a leaf mode carrying 1e-8 of the energy is not resolved to rtol of its own
    /// amplitude: BDF damps it), and at least the user's atol on w as an energy-norm
    /// amplitude of the body's mode, sqrt(m) omega atol_m.
    void tolerances(const State& y0, Eigen::Ref<Vec> atol) const override {
        double two_e = 0.0;  // 2 E0 on the meshed part, summed in order (as N_VDotProd)
        for (Eigen::Index i = 0; i < y0.size(); ++i) two_e += y0[i] * y0[i];
        atol.setConstant(std::max(std::sqrt(system().mass_kg()) * scales().omega_rad_per_s * options().cvode.atol_m,
                                  options().cvode.rtol * std::sqrt(two_e)));
    }

    /// Modal coordinates xi, xi' of the state.
    void modal(const State& Y, Eigen::VectorXd& xi, Eigen::VectorXd& xid) const {
        xi.resize(r);
        xid.resize(r);
        for (int i = 0; i < r; ++i) {
            xi[i] = Y[2 * i] / om[i];
            xid[i] = Y[2 * i + 1];
        }
    }

    /// The motion at an output for the stresses (event_driver.hpp): a = N Phi (g - Omega^2 xi), as
    /// make_record's (G^T p = M a + K z - f_L); no loading, no damping here.
    LeafMotion leaf_motion(double, const State& Y, const Vec&) const override {
        Eigen::VectorXd xi, xid;
        modal(Y, xi, xid);
        LeafMotion m;
        m.acceleration = NPhi * Eigen::VectorXd(g - om.cwiseProduct(om).cwiseProduct(xi));
        return m;
    }

    /// z = z_p + N Phi xi.
    Vec displacements(const State& Y, const Vec&) const override {
        Eigen::VectorXd xi, xid;
        modal(Y, xi, xid);
        return zp + NPhi * xi;
    }

    /// The record at Y: the held components' forces from the motion (G^T p = M a + K z - f_L),
    /// the springs' from their stretch; energies of the leaves, the layer and R, whole spring.
    /// A held unilateral pair in tension beyond 1e-6 F_ref is a SolverError (file comment).
    StepRecord make_record(double tau, const State& Y, Vec& p, Vec& rel) const override {
        const System& sys = system();
        Eigen::VectorXd xi, xid;
        modal(Y, xi, xid);
        const Eigen::VectorXd z = zp + NPhi * xi;
        const Eigen::VectorXd v = NPhi * xid;
        const Eigen::VectorXd a = NPhi * Eigen::VectorXd(g - om.cwiseProduct(om).cwiseProduct(xi));
        // the held components' forces: G^T p = M a + K z (least squares: exact on range(G^T))
        const Eigen::VectorXd pC = Gd.rows() > 0 ? Eigen::VectorXd(GGt.solve(Gd * Eigen::VectorXd(springs.empty() ? Eigen::VectorXd(M * a + K * z) : Eigen::VectorXd(M * a + K * z - fL))))
                                                 : Eigen::VectorXd();
        p = Eigen::VectorXd::Zero(sys.num_components());
        for (int k = 0; k < static_cast<int>(held.size()); ++k) p[held[k]] = pC[k];
        const Eigen::VectorXd spring_stretch = GL * z - dL;  // G_L z - d_L [m]
        for (int k = 0; k < static_cast<int>(springs.size()); ++k) p[springs[k]] = -DL[k] * spring_stretch[k];
        rel = detail::relative_positions(sys, z, p);
        // a held unilateral pair must stay compressed (p_n <= 0): a release is an event,
        // not built yet with massive leaves
        for (const auto& pr : laws().pairs)
            if (pr.kind == PairKind::coulomb && pr.row_n >= 0 && p[pr.row_n] > 1e-6 * scales().F_ref_n)
                throw SolverError(who() + ": a frictionless pair goes into tension (p_n = " + format_value(p[pr.row_n]) +
                                      " N) at t = " + format_value(tau) +
                                      " s: contact events between massive leaves are not built yet, use mode newmark",
                                  steps(), tau, 0.0);
        const double f = spring_factor();
        // leaves and layer: z^T K z / 2 - f_L^T z + d_L^T D d_L / 2 = z^T K_leaves z / 2 + (G_L z - d_L)^T D (G_L z - d_L) / 2
        const double strain = f * (0.5 * z.dot(K * z) - fL.dot(z) + 0.5 * dL.dot(DL.cwiseProduct(dL)));
        StepRecord rec;
        fill_state(sys, laws(), p, z[n - 1], v[n - 1], strain, 0.0, initial_energy_j(), LoadState{}, rec);
        finish_inertia_record(rec, 0.5 * f * v.dot(M * v), body_mass_kg() * a[n - 1]);
        rec.contact_residual_m = (Gd * z - dC).norm();  // the driver's without events (EventStart::events)
        return rec;
    }
};

CvodeHeldStepper::Impl::Impl(const System& system, const InitialState& start)
    : EventDriver(system, start.options, "cvode mode (leaf inertia)") {
    split_rows();
    null_space_modes();
    EventStart es;
    es.nstate = 2 * r;
    es.y0 = initial_state(start);
    es.scales = event_scales(system, leaf_mass_scale_inputs(system, options().loading));
    es.stiff_max_order = 2;                     // BDF order <= 2 (file comment)
    es.newton = NewtonSolver::band;             // the Jacobian is block diagonal (2 x 2 blocks)
    es.band_upper = es.band_lower = 1;
    this->start(start, es);                     // es.events null: every pair held for good
}

CvodeHeldStepper::CvodeHeldStepper(const System& system, const InitialState& start)
    : EventStepper(std::make_unique<Impl>(system, start)) {}

}  // namespace stackbeam::detail
