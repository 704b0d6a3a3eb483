// Mode "cvode" with leaf inertia on stacks with friction and elastic interfaces: the whole
// massive stack in CVODE (cvode_massive.hpp, docs/time-integration.md "Mode cvode with
// leaf mass", docs/decisions/015-massive-stack-under-cvode.md).
//
// With an elastic layer on every contact row (system.hpp: s = G z + C_L p - d) each contact
// force is a function of the displacements z once the pair's mode is known:
//     closed normal / sticking tangential row:  p_i = (d_i - G_i z) / c_i    (s_i = 0)
//     slipping row:  p_t = sigma mu tau(p_n)     (paper eq. 8 with the current tau)
//     open row:      p = 0
// so between events the stack obeys a smooth, stiff, linear ODE on the reduced DOFs,
//     M z'' + K z = G^T p(z),   p(z) = P z + p0,   i.e.   M z'' + K_eff z = G^T p0,
// K_eff = K - G^T P (non-symmetric where pairs slip), with M the consistent mass of the
// leaves and R (System::mass_reduced). Nothing is massless, so no contact point can move
// without inertia: a gap closes without an impact and every force is continuous in time
// except where a slipping pair reverses (its force jumps from +mu tau to -mu tau; the layer
// energy released is booked as dissipated, as in the modal stepper).
//
// The events are those of the other event-driven steppers (event_driver.hpp) with the
// instantaneous compliance W = C_L (diagonal): at fixed z only the layer deflects, so the
// contact iteration deciding the modes at an event is per pair. Witnesses (positive while the
// modes hold, decreasing crossings): a closed pair's compression, an open pair's gap, a
// sticking pair's margin mu tau - |p_t|, a slipping pair's slider rate against its force.
// A pair at the slip/stick boundary (its force at the cone's edge, p_t = sigma mu tau): at
// fixed z and z' its sigma-slip rate u and its stick force's rate into the cone are one
// quantity, d(mu tau - sigma p_t)/dt = sigma u / c_t in stick (the layer's compliance c_t): where
// the slip's rate contradicts the slip (sigma u > 0) the stick force moves inside the cone, where
// it agrees the stick force leaves it. So exactly one of stick and sigma-slip holds at first
// order, and neither needs a force jump. The look-ahead decides at second order where u ~ 0;
// where its decision is a sigma-slip whose rate at the event's state contradicts it, the pair
// sticks (correct_decision), and slips again only at a root of its stick witness. Only a pair
// not at that edge of its cone slips with a jump, its sign following its rate. (The old rule
// reversed every contradicted slip, a force jump of 2 mu tau: a pair that stopped on its cone
// then reversed at every rate root, soak seeds 14 and 25, decision 074.) A stuck pair's margin
// covers its forces' round-off (force_round_off_n).
//
// Structural damping (SimulationOptions::damping, off by default): C = alpha M + beta K of the
// leaves and R, its work int v^T C v dt a state of its own (StepRecord::damping_energy_j). The
// layer's normal dashpots (damping.layer_normal_time_s tau_L, off by default; decision 071): on
// each closed normal row i with a layer a dashpot eta_i = tau_L / c_i [N s/m] in parallel with
// its spring, the force -eta_i ds_i/dt = -eta_i G_i z', i.e. G_i^T eta_i G_i added to the mode's
// damping matrix (Cd); its work joins the damping energy. The forces p, the witnesses and the
// mode decisions are the springs' (a pair opens when its spring's force reaches 0).
//
// Loadings (loading.hpp) with the leaves' own inertia: q(t) = e_w F(t)/f - (g + y_b''(t)) l on the
// right-hand side (ReducedLoad; l = System::vertical_inertia_kg(): the leaves' weight and R's, and
// in the frame of the supports the inertial force of a base acceleration on every mass); gravity
// starts from the static equilibrium of the whole stack under its own weight and R's. The rig
// (prescribed displacement) imposes w(t) on R's DOF by a reaction lambda e_w chosen so that
// w'' = w_p''(t): z'' = M^-1 (r + lambda e_w), lambda = (w_p'' - (M^-1 r)_w) / (M^-1)_ww, the rig's
// force on the meshed part including R's inertia and the leaves' (the load cell between R and the
// spring reads lambda - m w_p''). The external work W' = q^T v (rig: lambda w') is a state.
// The windup rig (loading.hpp; decision 069) imposes theta_R(t) the same way on a set of prescribed
// DOFs H (theta_R, and w where the vertical rig holds it too): z'' = M^-1 (r + E_H lambda) with
// U_HH lambda = z_H''(t) - (M^-1 r)_H, U = M^-1 E_H (prescribe_accelerations); quasi-static as
// newmark's: R's inertia (m on w and u_R, J) is out of M (System::mass_reduced(false)); its work
// W' = q^T v + lambda^T z_H'. Seat loads with the vertical rig take the same form (H = {w}: their
// work q^T v besides the rig's). The vertical rig alone keeps its single-DOF form above.
//
// At an event the driver makes the decided modes hold at the event's state itself
// (settle_at_state): the look-ahead may keep a pair closed that is still in tension at y (its
// gap of c p closing within the look-ahead); that pair opens, and root-finding finds its closure.
// Without it the per-step check found such pairs at every step after the restart (measured:
// 10,519 of 11,562 events in the first ms of the steel friction case, steps of 3e-11 s).
//
// CVODE: BDF (order <= 2: higher orders are unstable on the lightly damped oscillatory
// modes, as for the bonded stack), Newton. The Newton matrix I - gamma J of
// y = [z, v, D, D_c], J = [0 I; -M^-1 K_eff -M^-1 C], is solved exactly by block elimination,
//     (M + gamma C + gamma^2 K_eff) x_v = M r_v - gamma K_eff r_z,   x_z = r_z + gamma x_v,
// one sparse LU of that banded n x n matrix (Eigen::SparseLU; M^-1 K_eff is dense, so a KLU
// or band matrix of J itself would not be sparse), handed to CVODE as a matrix-embedded
// linear solver (CvodeSession::use_embedded_newton: psetup factorises, psolve solves).
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "stackbeam/contact/modes.hpp"
#include "fe/tied_shape.hpp"
#include "stackbeam/errors.hpp"
#include "time/cvode/cvode_massive.hpp"
#include "time/stack_properties.hpp"
#include "time/cvode/cvode_modes.hpp"
#include "time/cvode/event_driver.hpp"
#include "time/contact_state.hpp"
#include "time/record.hpp"
#include "time/reduced_load.hpp"
#include "time/rig_reaction.hpp"
#include "time/static_stages.hpp"

namespace stackbeam::detail {

namespace {

using SpMat = Eigen::SparseMatrix<double>;
using RowSpMat = Eigen::SparseMatrix<double, Eigen::RowMajor>;

}  // namespace

struct CvodeMassiveStepper::Impl final : EventDriver, ContactEventHooks {
    Impl(const System& system, const InitialState& start);

    SpMat K, M, Gt;
    SpMat C;                  // structural damping alpha M + beta K [N s/m] (empty: none)
    // The elastic layer's normal dashpots (SimulationOptions::damping.layer_normal_time_s tau_L):
    // eta_i = tau_L / c_i [N s/m] on each normal row i with a layer (0 elsewhere and without tau_L)
    Eigen::VectorXd eta_n;
    // the damping of the current modes: C plus G_i^T eta_i G_i of every closed normal row [N s/m]
    SpMat Cd;
    bool damped_ = false;     // Cd has an entry
    bool damped() const { return damped_; }
    RowSpMat Grow;            // G, row-major [-]
    RowSpMat Gabs;            // |G_ij| (force_round_off_n) [-]
    Eigen::VectorXd cL;       // layer compliance per contact row [m/N]
    Eigen::SimplicialLDLT<SpMat> mass;  // M
    std::unique_ptr<ReducedLoad> load;  // q(t) of the loading (none for initial conditions and the rig)
    bool rig = false;                   // w prescribed (LoadingKind::prescribed_displacement)
    Eigen::VectorXd u_w;                // M^-1 e_w [1/kg] (the rig's reaction per unit force)
    mutable double rig_lambda_rhs = 0.0;  // the rig's lambda [N] at the last right-hand side (its Newton row)
    // the windup rig: the prescribed DOFs H (ascending: theta_R, then w with the vertical rig), their
    // motions, U = M^-1 E_H, the reactions lambda [N m, N] at the last right-hand side; R's mass on w in M
    bool windup = false, held_rig = false;  // held_rig: the prescribed DOFs' form (the windup rig, or seat loads with the vertical rig)
    std::vector<int> held;
    std::vector<const TimeFunction*> held_f;
    Eigen::MatrixXd U_h;
    mutable Eigen::VectorXd held_lambda_rhs;
    double m_on_w = 0.0;  // [kg, whole spring]: 0 under the windup rig
    /// z_H''(t) [rad/s^2, m/s^2] of the prescribed DOFs.
    Eigen::VectorXd held_acceleration(double t_s) const {
        Eigen::VectorXd a(static_cast<Eigen::Index>(held.size()));
        for (std::size_t h = 0; h < held.size(); ++h) a[static_cast<Eigen::Index>(h)] = held_f[h]->second_derivative(t_s);
        return a;
    }
    // the current modes: p = P z + p0, s + d = Hs z + hs, M z'' = -Keff z + b0
    RowSpMat P, Hs;
    SpMat Keff;
    Eigen::VectorXd p0, hs, b0;
    std::vector<int> slip_rows;
    // the Newton matrix M + gamma C + gamma^2 K_eff of the current modes
    Eigen::SparseLU<SpMat, Eigen::COLAMDOrdering<int>> nlu;
    double gamma_lu = -1.0;

    /// CVODE's tolerances: displacements and rotations to atol_m, velocities to omega_t atol_m,
    /// the dissipated, damping and external energies to rtol of the initial energy (y0: z0, v0).
    void tolerances(const State& y0, Eigen::Ref<Vec> A) const override {
        const int nd = ndof();
        const auto z0 = y0.head(nd);
        const auto v0 = y0.segment(nd, nd);
        const double omega_t = scales().omega_rad_per_s, L_ref = scales().L_ref_m;
        A.head(nd).setConstant(options().cvode.atol_m);
        A.segment(nd, nd).setConstant(omega_t * options().cvode.atol_m);
        const double e_meshed = 0.5 * v0.dot(M * v0) + 0.5 * z0.dot(K * z0) +
                                0.5 * system().tied_stiffness_n_per_m() / spring_factor() * L_ref * L_ref;
        A[2 * nd] = A[2 * nd + 1] = A[2 * nd + 2] = std::max(1e-300, options().cvode.rtol * e_meshed);
    }

    // ---- modes ------------------------------------------------------------------

    void build_mode(const ModeLinearization& lin) override {
        const int n = rows();
        const Eigen::VectorXd& d = anchors();
        std::vector<int> pos(static_cast<std::size_t>(n), -1);
        for (std::size_t i = 0; i < lin.S.size(); ++i) pos[static_cast<std::size_t>(lin.S[i])] = static_cast<int>(i);
        std::vector<Eigen::Triplet<double>> tp;
        p0 = lin.e;
        // held rows: c_i p_i + G_i z - d_i = 0 (W = C_L is diagonal: no coupling to other rows)
        for (int row : lin.S) {
            const double c = cL[row];
            if (!(c > 0.0)) throw failure("contact row " + std::to_string(row) + " has no elastic layer");
            for (RowSpMat::InnerIterator it(Grow, row); it; ++it) tp.emplace_back(row, it.col(), -it.value() / c);
            p0[row] = d[row] / c;
        }
        // slipping rows: p_t = e_t + coef p_n
        for (std::size_t a = 0; a < lin.coupled.size(); ++a) {
            const int rt = lin.coupled[a].first, rn = lin.coupled[a].second;
            if (pos[static_cast<std::size_t>(rn)] < 0) continue;
            const double coef = lin.coef[a], c = cL[rn];
            for (RowSpMat::InnerIterator it(Grow, rn); it; ++it) tp.emplace_back(rt, it.col(), -coef * it.value() / c);
            p0[rt] = lin.e[rt] + coef * p0[rn];
        }
        P.resize(n, ndof());
        P.setFromTriplets(tp.begin(), tp.end());
        const RowSpMat CP = cL.asDiagonal() * P;
        Hs = Grow + CP;
        hs = cL.cwiseProduct(p0);
        Keff = K - SpMat(Gt * P);
        Keff.makeCompressed();
        b0 = Gt * p0;
        // the layer's normal dashpots on the closed rows: the force -eta_i ds_i/dt = -eta_i G_i z'
        // on row i, in parallel with its spring (Kelvin-Voigt); its work is damping (D_c)
        std::vector<Eigen::Triplet<double>> td;
        for (int row : lin.S)
            if (eta_n.size() > 0 && eta_n[row] > 0.0)
                for (RowSpMat::InnerIterator a(Grow, row); a; ++a)
                    for (RowSpMat::InnerIterator b(Grow, row); b; ++b)
                        td.emplace_back(a.col(), b.col(), eta_n[row] * a.value() * b.value());
        Cd.resize(ndof(), ndof());
        Cd.setFromTriplets(td.begin(), td.end());
        if (C.size() > 0 && C.nonZeros() > 0) Cd += C;
        Cd.makeCompressed();
        damped_ = Cd.nonZeros() > 0;
        slip_rows.clear();
        for (int kk = 0; kk < num_pairs(); ++kk) {
            const int rt = pairs()[kk].row_t;
            if (rt >= 0 && (modes().tmode[kk] == SLIP_POS || modes().tmode[kk] == SLIP_NEG)) slip_rows.push_back(rt);
        }
        // the Newton matrix's pattern (M + K_eff: the same for every gamma)
        SpMat A = M + Keff;
        if (damped()) A += Cd;
        prescribe_w_row(A);
        nlu.analyzePattern(A);
        gamma_lu = -1.0;
    }

    /// The rig: R's row of the Newton matrix becomes e_w^T (x_vw = r_vw: w'' does not depend on
    /// the state). Compresses A.
    void prescribe_w_row(SpMat& A) const {
        if (held_rig) {  // every prescribed DOF's row
            std::vector<char> is_held(static_cast<std::size_t>(A.rows()), 0);
            for (const int h : held) is_held[static_cast<std::size_t>(h)] = 1;
            A.prune([&is_held](const Eigen::Index& row, const Eigen::Index&, const double&) {
                return !is_held[static_cast<std::size_t>(row)];
            });
            for (const int h : held) A.coeffRef(h, h) = 1.0;
        } else if (rig) {
            const int w = w_dof();
            A.prune([w](const Eigen::Index& row, const Eigen::Index&, const double&) { return row != w; });
            A.coeffRef(w, w) = 1.0;
        }
        A.makeCompressed();
    }

    /// The forces of the current modes at z: P z + p0, the slipping rows then p_t = sigma mu tau(p_n)
    /// from that p_n by the friction limit's own formula (put_slip_forces). P's slip rows give the
    /// same value in exact arithmetic, but summed in another order: each of p_n = (d_n - G_n z) / c
    /// and P_t z cancels positions of ~1e-2 m to a layer deflection of ~1e-9 m, and the two
    /// roundings left a slipping pair's force ~1e-9 (relative) inside its own cone. The per-step
    /// check then read it as sticking, its slip since the last step as the incremental problem's
    /// error, and stopped the run at a "missed event" that kept every mode (4,033 restarts of
    /// soak seed 23's 4,377 events; decision 078).
    Vec forces_z(const Eigen::Ref<const Eigen::VectorXd>& z) const {
        Vec p = P * z + p0;
        modes().put_slip_forces(laws(), p);
        return p;
    }
    Vec forces(const State& y) const override { return forces_z(y.head(ndof())); }
    Vec relative(const State& y) const override { return Hs * y.head(ndof()) + hs; }
    Vec relative_at_event(const State& y, const Vec& p_cur) const override {
        return Grow * y.head(ndof()) + cL.cwiseProduct(p_cur);
    }
    Vec motion(const State& y) const override { return Grow * y.head(ndof()); }

    /// z'' = M^-1 (G^T p0 + q(t) - K_eff z - C z' + lambda e_w) [m/s^2, rad/s^2] of the current
    /// modes; lambda [N, meshed part] the rig's reaction (0 without a rig), returned in `rig_n`.
    /// The windup rig: every prescribed DOF's reaction in `held_n` (theta_R's first; w's, the last, in rig_n).
    Vec acceleration(double t_s, const Eigen::Ref<const Eigen::VectorXd>& z, const Eigen::Ref<const Eigen::VectorXd>& v,
                     double* rig_n = nullptr, Eigen::VectorXd* held_n = nullptr) const {
        Eigen::VectorXd r = b0 - Keff * z;
        if (!load->none()) r += load->at(t_s);
        if (damped()) r -= Cd * v;
        Eigen::VectorXd a = mass.solve(r);
        if (held_rig) {
            const Eigen::VectorXd lambda = prescribe_accelerations(a, U_h, held, held_acceleration(t_s));
            if (rig_n) *rig_n = rig ? lambda[lambda.size() - 1] : 0.0;
            if (held_n) *held_n = lambda;
        } else if (rig) {
            const double lambda = prescribe_w_acceleration(a, u_w, options().loading.displacement_m.second_derivative(t_s));
            if (rig_n) *rig_n = lambda;
        } else if (rig_n) {
            *rig_n = 0.0;
        }
        return a;
    }

    /// The motion at an output for the stresses (event_driver.hpp): z'' of the current modes at
    /// (t, z, v), the frame's g + y_b''(t), the structural damping.
    LeafMotion leaf_motion(double t_s, const State& y, const Vec&) const override {
        const int nd = ndof();
        LeafMotion m;
        m.velocity = y.segment(nd, nd);
        m.acceleration = acceleration(t_s, y.head(nd), y.segment(nd, nd));
        m.frame_acceleration_m_per_s2 = options().loading.gravity_m_per_s2 + load->base_acceleration(t_s);
        m.damping = options().damping;
        return m;
    }

    /// The external power [W, meshed part] at (t, v) with acceleration-side rig force lambda.
    double external_power(double t_s, const Eigen::Ref<const Eigen::VectorXd>& v, double lambda) const {
        if (rig) return lambda * v[w_dof()];
        return load->none() ? 0.0 : load->at(t_s).dot(v);
    }
    /// The windup rig's: q^T v + lambda^T v_H [W, meshed part].
    double held_power(double t_s, const Eigen::Ref<const Eigen::VectorXd>& v, const Eigen::VectorXd& lambda) const {
        double pw = load->none() ? 0.0 : load->at(t_s).dot(v);
        for (std::size_t h = 0; h < held.size(); ++h) pw += lambda[static_cast<Eigen::Index>(h)] * v[held[h]];
        return pw;
    }

    void witnesses(const State& y, double* g) const override {
        const auto z = y.head(ndof());
        const auto v = y.segment(ndof(), ndof());
        const Eigen::VectorXd& d = anchors();
        const Vec round_off = force_round_off_n(z);
        witnesses_from(
            forces_z(z), [&](int row) { return Hs.row(row).dot(z) + hs[row] - d[row]; },
            [&](int row) { return Hs.row(row).dot(v); }, g, &round_off);
    }

    /// The round-off of each row's force at z [N]: a held row's p_i = (d_i - G_i z) / c_i is a
    /// difference of terms G_ij z_j / c_i far larger than p_i on a stiff layer (soak seed 14: sum
    /// |G_n z| / c_n = 6.3e10 N for p_n = -289 N, so eps times it, 1.4e-5 N, is 1e-8 F_ref), and a
    /// slipping row's mu p_n carries its normal row's. kRoundOffTerms eps (|G_i| |z| + |d_i|) / c_i
    /// bounds it: a sum of n terms is rounded to ~sqrt(n) eps sum |terms| (rows of 8-16 terms;
    /// measured 0.22 eps sum |terms| at seed 14's stick entry). Decision 074.
    Vec force_round_off_n(const Eigen::Ref<const Eigen::VectorXd>& z) const {
        constexpr double kRoundOffTerms = 4.0;
        const Vec sum = Gabs * z.cwiseAbs() + anchors().cwiseAbs();
        return (kRoundOffTerms * std::numeric_limits<double>::epsilon()) * sum.cwiseQuotient(cL);
    }

    /// The look-ahead: the contact points move by ~kLookahead L_ref and the forces by
    /// ~kLookahead F_ref (as the modal stepper), on the second-order Taylor expansion.
    Vec look_ahead(double te, const State& y, const Vec&) const override {
        const int ndof = this->ndof();
        const auto z = y.head(ndof);
        const auto v = y.segment(ndof, ndof);
        const Eigen::VectorXd a = acceleration(te, z, v);
        const double target = kLookahead * scales().L_ref_m;
        const double vmax = (Grow * v).lpNorm<Eigen::Infinity>(), amax = (Grow * a).lpNorm<Eigen::Infinity>();
        double delta = std::numeric_limits<double>::infinity();
        if (vmax > 0.0) delta = std::min(delta, target / vmax);
        if (amax > 0.0) delta = std::min(delta, std::sqrt(2.0 * target / amax));
        const double prate = (P * v).lpNorm<Eigen::Infinity>();
        if (prate > 0.0) delta = std::min(delta, kLookahead * scales().F_ref_n / prate);
        if (!std::isfinite(delta)) delta = 0.0;
        // The third-order term: z^(3) = M^-1 (q'(t) - K_eff z' - C z'') of the current modes (the
        // rig's w^(3) taken as 0). It decides where the lower orders vanish at the contact points: a
        // start from static equilibrium (z'' = 0) with the leaves moving in the tied shape (no slider
        // rate), where a pair left at the friction cone's edge by the static solve would otherwise be
        // decided by round-off.
        Eigen::VectorXd r3 = -(Keff * v);
        if (damped()) r3 -= Cd * a;
        if (!load->none()) {
            const double h = 1e-7;  // [s] q'(t) by central differences (smooth loadings)
            r3 += (load->at(te + h) - load->at(te - h)) / (2.0 * h);
        }
        Eigen::VectorXd jerk = mass.solve(r3);
        if (held_rig) prescribe_accelerations(jerk, U_h, held, Eigen::VectorXd::Zero(static_cast<Eigen::Index>(held.size())));
        else if (rig) prescribe_w_acceleration(jerk, u_w, 0.0);
        const double jmax = (Grow * jerk).lpNorm<Eigen::Infinity>();
        if (jmax > 0.0)
            delta = std::min(delta > 0.0 ? delta : std::numeric_limits<double>::infinity(), std::cbrt(6.0 * target / jmax));
        Vec yl = y;
        yl.head(ndof) = z + delta * v + 0.5 * delta * delta * a + delta * delta * delta / 6.0 * jerk;
        yl.segment(ndof, ndof) = v + delta * a + 0.5 * delta * delta * jerk;
        return yl;
    }

    void body_motion(const State& y, const Vec&, double& w, double& wd) const override {
        w = y[w_dof()];
        wd = y[ndof() + w_dof()];
    }

    /// A slipping pair slips against its slider rate (EventDriver::signs_follow_slip_rates); one
    /// whose force at y is at its cone on the decided slip's side and whose rate contradicts that
    /// slip sticks (file comment: the pair at the slip/stick boundary).
    void correct_decision(const State& y, const Vec& rel, std::vector<signed char>& nm,
                          std::vector<signed char>& tm) override {
        // the forces at y before the event: rel = G z + C_L p (relative_at_event; every row has a layer)
        const Vec p_cur = (rel - Grow * y.head(ndof())).cwiseQuotient(cL);
        const Vec round_off = force_round_off_n(y.head(ndof()));
        std::vector<signed char> side(static_cast<std::size_t>(num_pairs()), 0);
        for (int kk = 0; kk < num_pairs(); ++kk) {
            const ContactPair& cp = pairs()[kk];
            if (cp.row_t < 0 || cp.kind == PairKind::bonded || !(cp.friction_coefficient > 0.0)) continue;
            const double limit_n = cp.friction_coefficient * friction_normal_force(laws(), kk, p_cur);
            // at the edge within the stick witness's margin (witnesses_from with the forces' round-off)
            const double r = stick_round_off_n(kk, round_off);
            if (limit_n > 0.0 && std::abs(p_cur[cp.row_t]) >= limit_n - std::max(kForceMargin * scales().F_ref_n, r))
                side[static_cast<std::size_t>(kk)] = p_cur[cp.row_t] > 0.0 ? 1 : -1;
        }
        signs_follow_slip_rates(rel, nm, tm, [&] { return Vec(Hs * y.segment(ndof(), ndof())); }, &side);
    }

    /// A force jump at an event (a slip that reverses) releases the layer's energy
    /// p^T C_L p / 2 of the jump: friction work, booked as dissipated (z and z' are continuous).
    void after_event(const std::string& cause, const Vec& p_cur, const Vec& p_new) override {
        book_force_jump(cause, 0.5 * spring_factor() * (p_cur.dot(cL.cwiseProduct(p_cur)) - p_new.dot(cL.cwiseProduct(p_new))), p_cur,
                        p_new);
    }

    /// At fixed z only the diagonal layer is instantaneous: the state decides every pair.
    bool settle_at_state() const override { return true; }
    /// Every contact row has its own layer (p_i = (d_i - G_i z) / c_i on a held row).
    double own_layer_compliance_m_per_n(int row) const override { return cL[row]; }

    // ---- CVODE ------------------------------------------------------------------

    /// y = [z, z', D, D_c, W]: z' = v, v' = M^-1 (G^T p0 + q(t) - K_eff z - C v + lambda e_w), D' =
    /// friction power -sum_slip p_t ds_t/dt >= 0, D_c' = damping power v^T C v >= 0, W' = the
    /// loading's power q^T v (rig: lambda w') [W, meshed part].
    void derivatives(double t, const double* Y, double* D) const override {
        const int n_ = ndof();
        const Eigen::Map<const Eigen::VectorXd> z(Y, n_), v(Y + n_, n_);
        Eigen::Map<Eigen::VectorXd>(D, n_) = v;
        double lambda = 0.0;
        Eigen::Map<Eigen::VectorXd>(D + n_, n_) = acceleration(t, z, v, &lambda, held_rig ? &held_lambda_rhs : nullptr);
        rig_lambda_rhs = lambda;
        double pw = 0.0;
        for (int rt : slip_rows) pw -= (P.row(rt).dot(z) + p0[rt]) * Hs.row(rt).dot(v);
        D[2 * n_] = pw;
        D[2 * n_ + 1] = damped() ? v.dot(Cd * v) : 0.0;
        D[2 * n_ + 2] = held_rig ? held_power(t, v, held_lambda_rhs) : external_power(t, v, lambda);
    }

    /// Factorises M + gamma C + gamma^2 K_eff (the Newton matrix after block elimination).
    int newton_setup(double gamma) override {
        if (gamma == gamma_lu) return 0;
        SpMat A = M + (gamma * gamma) * Keff;
        if (damped()) A += gamma * Cd;
        prescribe_w_row(A);
        nlu.factorize(A);
        if (nlu.info() != Eigen::Success) {
            gamma_lu = -1.0;
            return 1;  // recoverable: CVODE retries with a smaller step
        }
        gamma_lu = gamma;
        return 0;
    }

    /// Solves (I - gamma J) x = r: the (z, v) block by elimination on the LU of newton_setup, the
    /// friction-power row by its linearisation at y.
    int newton_solve(double t, const double* Y, const double* R, double* X, double gamma) const override {
        if (gamma_lu < 0.0) return 1;
        const int n_ = ndof();
        const Eigen::Map<const Eigen::VectorXd> rz(R, n_), rvel(R + n_, n_);
        Eigen::VectorXd rhs_v = M * rvel - gamma * (Keff * rz);  // (M + g C + g^2 Keff) x_v
        if (held_rig)
            for (const int h : held) rhs_v[h] = rvel[h];           // z_H'' prescribed: x_vH = r_vH
        else if (rig)
            rhs_v[w_dof()] = rvel[w_dof()];                        // w'' prescribed: x_vw = r_vw
        const Eigen::VectorXd xvel = nlu.solve(rhs_v);
        const Eigen::VectorXd xz = rz + gamma * xvel;
        Eigen::Map<Eigen::VectorXd>(X, n_) = xz;
        Eigen::Map<Eigen::VectorXd>(X + n_, n_) = xvel;
        const Eigen::Map<const Eigen::VectorXd> z(Y, n_), v(Y + n_, n_);
        // d(pw) = -sum (P_t dz) (Hs_t v) + (P_t z + p0_t) (Hs_t dv)
        double dpw = 0.0;
        for (int rt : slip_rows)
            dpw -= P.row(rt).dot(xz) * Hs.row(rt).dot(v) + (P.row(rt).dot(z) + p0[rt]) * Hs.row(rt).dot(xvel);
        X[2 * n_] = R[2 * n_] + gamma * dpw;
        X[2 * n_ + 1] = R[2 * n_ + 1] + (damped() ? gamma * 2.0 * (Cd * v).dot(xvel) : 0.0);  // d(v^T C v)
        // d(q^T v) = q^T dv (the rig's lambda w': lambda dw' with the lambda of the last right-hand
        // side, lambda's own change left out of this row of the Newton matrix, which nothing else
        // depends on)
        X[2 * n_ + 2] = R[2 * n_ + 2] + gamma * (held_rig ? held_power(t, xvel, held_lambda_rhs)
                                                       : external_power(t, xvel, rig_lambda_rhs));
        return 0;
    }

    // ---- records ----------------------------------------------------------------

    /// The record at state Y: w = z_w; energies: kinetic z'^T M z' / 2 (leaves and R; the windup rig: the leaves' alone), strain
    /// z^T K z / 2 + p^T C_L p / 2 (leaves and layer), whole spring.
    /// z is the state's first part.
    Vec displacements(const State& Y, const Vec&) const override { return Y.head(ndof()); }

    StepRecord make_record(double tau, const State& Y, Vec& p, Vec& rel) const override {
        const int ndof = this->ndof(), w_dof = this->w_dof();
        const double f = spring_factor(), m_body = body_mass_kg();  // (R's weight: its whole mass, also under the windup rig)
        const auto z = Y.head(ndof);
        const auto v = Y.segment(ndof, ndof);
        p = forces_z(z);
        rel = Grow * z + cL.cwiseProduct(p);
        double lambda = 0.0;
        Eigen::VectorXd held_n;
        const Eigen::VectorXd a = acceleration(tau, z, v, &lambda, &held_n);
        const double strain = 0.5 * f * (z.dot(K * z) + p.dot(cL.cwiseProduct(p)));
        LoadState ls;  // the loading's force on R, whole spring, and the external work
        const Loading& L = options().loading;
        ls.external_force_n = rig ? f * lambda - m_on_w * a[w_dof] : L.external_force_n(tau, m_body);
        ls.external_work_j = f * Y[2 * ndof + 2];
        ls.base_displacement_m = L.base_displacement_m(tau);
        StepRecord rec;
        fill_state(system(), laws(), p, z[w_dof], v[w_dof], strain, f * Y[2 * ndof] + jump_dissipation_j(),
                   initial_energy_j(), ls, rec);
        finish_inertia_record(rec, 0.5 * f * v.dot(M * v), m_on_w * a[w_dof], f * Y[2 * ndof + 1]);
        if (windup) rec.leaf_kinetic_energy_j = rec.kinetic_energy_j;  // M without R's mass: the leaves' alone
        // R's balance m w'' = F - spring force; the rig: the load cell between R and the spring reads
        // the force on the spring, lambda - m w'' (the leaves' inertia included)
        rec.spring_force_n = rig ? rec.external_force_n : rec.external_force_n - rec.force_on_mass_n;
        // the seat (full model; loading.hpp): theta_R, u_R and the applied moment M - H h
        const int theta = system().seat_rotation_dof(), axial = system().seat_axial_dof();
        rec.seat_rotation_rad = theta >= 0 ? z[theta] : 0.0;
        rec.seat_axial_m = axial >= 0 ? z[axial] : 0.0;
        rec.seat_moment_n_m = L.seat_moment_n_m_at(tau) + (windup ? held_n[0] : 0.0);  // and the windup rig's reaction
        return rec;
    }
};

CvodeMassiveStepper::Impl::Impl(const System& system, const InitialState& start)
    : EventDriver(system, start.options, "cvode mode (massive leaves)"),
      K(system.stiffness_reduced()),
      M(system.mass_reduced(!start.options.loading.windup_rig())),  // the windup rig: R's inertia out (quasi-static)
      Gt(system.contact_rows().transpose()),
      Grow(system.contact_rows()),
      Gabs(Grow.cwiseAbs()),
      cL(system.layer_compliance_m_per_n()),
      load(std::make_unique<ReducedLoad>(system, start.options.loading)),
      rig(start.rig) {
    if (options().damping.active()) {
        C = options().damping.rayleigh_alpha_per_s * M + options().damping.rayleigh_beta_s * K;
        C.makeCompressed();
    }
    if (options().damping.layer_normal_time_s > 0.0) {
        eta_n = Eigen::VectorXd::Zero(cL.size());
        for (const ContactPair& cp : system.pairs()) {
            if (cp.row_n >= 0 && cL[cp.row_n] > 0.0) eta_n[cp.row_n] = options().damping.layer_normal_time_s / cL[cp.row_n];
        }
    }
    mass.compute(M);
    if (mass.info() != Eigen::Success || !(mass.vectorD().minCoeff() > 0.0))
        throw SolverError(who() + ": the mass matrix is not positive definite", 0, 0.0, 0.0);
    if (rig) u_w = mass.solve(Eigen::VectorXd::Unit(ndof(), w_dof()));
    const Loading& L = options().loading;
    windup = L.windup_rig();
    held_rig = windup || (rig && L.has_seat_load());  // the seat loads' work: q^T v besides the rig's
    m_on_w = windup ? 0.0 : body_mass_kg();
    if (held_rig) {
        if (windup) {
            held = {system.seat_rotation_dof()};
            held_f = {&*L.seat_rotation_rad};
        }
        if (rig) {
            held.push_back(w_dof());
            held_f.push_back(&L.displacement_m);
        }
        U_h.resize(ndof(), static_cast<Eigen::Index>(held.size()));
        for (std::size_t h = 0; h < held.size(); ++h)
            U_h.col(static_cast<Eigen::Index>(h)) = mass.solve(Eigen::VectorXd::Unit(ndof(), held[h]));
        held_lambda_rhs = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(held.size()));
    }
    EventStart es;
    es.nstate = 2 * ndof() + 3;
    // the initial state (as mode newmark, initial_state.hpp): the assembly and the static
    // equilibrium under the weight of everything, the leaves in the static shape with R held at
    // w(0) (the rig: w_p(0)), moving with R in the tied shape per unit w times w'(0)
    es.y0 = Eigen::VectorXd::Zero(es.nstate);
    es.y0.head(ndof()) = start.z;
    es.y0.segment(ndof(), ndof()) = start.v0;
    es.scales = event_scales(system, leaf_mass_scale_inputs(system, options().loading));
    // the instantaneous compliance: only the layer (z is held by the leaves' inertia)
    es.compliance = cL.asDiagonal();
    // (a stack without contact rows, a single leaf, has no events: any positive tolerance)
    es.event_tolerance_m = cL.size() > 0 ? 1e-9 * es.scales.F_ref_n * cL.maxCoeff() : 1e-12;
    es.gap_margin = std::max(kMotionMargin, 10.0 * es.event_tolerance_m / es.scales.L_ref_m);
    es.stiff_max_order = 2;  // BDF order <= 2, Newton on newton_setup / newton_solve (file comment)
    es.events = this;  // contact events (ContactEventHooks)
    es.pair_chatter_limit = true;  // its contact points vibrate on the layer (kMaxPairSwitches)
    this->start(start, es);
}

CvodeMassiveStepper::CvodeMassiveStepper(const System& system, const InitialState& start)
    : EventStepper(std::make_unique<Impl>(system, start)) {}

}  // namespace stackbeam::detail
