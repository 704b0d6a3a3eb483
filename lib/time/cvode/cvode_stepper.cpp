// Mode "cvode": CVODE between contact events, root-finding on every transition,
// the contact iteration deciding the modes at events and checking every accepted
// step (the event driver, event_driver.hpp). The physics and the witness functions are
// stated in cvode_stepper.hpp; here: the state y = [w, w', D (, W_e)] and its mode algebra.
#include "stackbeam/time/cvode_stepper.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

#include "stackbeam/contact/modes.hpp"
#include "time/cvode/cvode_modes.hpp"
#include "time/cvode/cvode_massless.hpp"
#include "time/cvode/event_driver.hpp"
#include "time/initial_state.hpp"
#include "time/record.hpp"
#include "stackbeam/errors.hpp"

namespace stackbeam {
namespace {

// Pair modes: those of the active-set solvers (contact/modes.hpp).
using modes::SLIP_NEG;
using modes::SLIP_POS;
using modes::STICK;
using detail::kLookahead;

}  // namespace

bool ContactEvent::is_stick_slip() const {
    auto fr = [](const std::string& s) { return s == "stick" || s == "slip+" || s == "slip-"; };
    return fr(from) && fr(to);
}

struct CvodeStepper::Impl final : detail::EventDriver, detail::ContactEventHooks {
    const Eigen::MatrixXd& C;  // C' [m/N]
    Eigen::VectorXd c;         // coupling [-]
    double k = 0, m = 0;       // R's spring [N/m] and mass [kg] of the meshed part
    Loading load;              // the loading (loading.hpp), prepared
    /// External force on R of the meshed part at t [N] (loading.hpp: F/f - m g - m y_b'').
    double fe(double t_s) const { return load.external_force_n(t_s, body_mass_kg()) / spring_factor(); }

    // the current mode set: p(w) = P w + r, s(w) = hs w + bs, m w'' = a1 w + a0,
    // D' = -w' (diss_a w + diss_b)
    Eigen::VectorXd P, r, hs, bs;
    double a1 = 0, a0 = 0, diss_a = 0, diss_b = 0;
    Eigen::PartialPivLU<Eigen::MatrixXd> lu;

    // Seat loads S(t) = [M - H h; H] [N m, N] on theta_R, u_R (loading.hpp; decision 069), condensed as
    // closed-form's (System::SeatCondensation): s = C'p + c w + B S - d, R's force on the stack
    // k w - c^T p + g^T S, the seat's motion [theta_R; u_R] = B^T p - g w + F S. In a mode set the forces
    // and relative positions gain a known function of time, p = P w + r + PS S(t), s = hs w + bs + hS S(t)
    // (hS = C'PS + B), and m w'' = a1 w + a0 + aS^T S(t) + F_v(t) (aS = PS^T c - g). The witnesses then
    // depend on t: t joins the state (y[kTime], t' = 1) so that every hook that reads the state (the
    // driver's forces(y), relative(y), its bisection on CVODE's dense output, the look-ahead) reads S at
    // the state's own time. Without seat loads none of this is built and the state is as before.
    static constexpr int kTime = 4;  // y = [w, w', D, W_e, t] with seat loads
    bool seat = false;
    System::SeatCondensation sc;
    Eigen::MatrixXd PS, hS;           // rows x 2
    Eigen::Vector2d aS = Eigen::Vector2d::Zero();
    std::vector<int> slip_rows;       // tangential rows of the slipping pairs (the friction power)
    /// S(t) [N m, N], its rate S'(t) and S''(t) (0 where the shape has none: triangle's turning points).
    Eigen::Vector2d seat_load(double t_s) const { return {load.seat_moment_n_m_at(t_s), load.longitudinal_force_n_at(t_s)}; }
    Eigen::Vector2d seat_rate(double t_s) const {
        const double Hd = load.longitudinal_force_n ? load.longitudinal_force_n->derivative(t_s) : 0.0;
        const double Md = load.seat_moment_n_m ? load.seat_moment_n_m->derivative(t_s) : 0.0;
        return {Md - Hd * load.longitudinal_force_height_m, Hd};
    }
    Eigen::Vector2d seat_acceleration(double t_s) const {
        const double Hdd = load.longitudinal_force_n ? load.longitudinal_force_n->second_derivative(t_s) : 0.0;
        const double Mdd = load.seat_moment_n_m ? load.seat_moment_n_m->second_derivative(t_s) : 0.0;
        return {Mdd - Hdd * load.longitudinal_force_height_m, Hdd};
    }
    Eigen::Vector2d seat_load(const State& y) const { return seat ? seat_load(y[kTime]) : Eigen::Vector2d::Zero(); }
    /// The seat's motion [theta_R; u_R] [rad, m] at w with forces p and seat loads S.
    Eigen::Vector2d seat_motion(const Vec& p, double w, const Eigen::Vector2d& S) const {
        return (p.size() > 0 ? Eigen::Vector2d(sc.B.transpose() * p) : Eigen::Vector2d::Zero()) - sc.g * w + sc.F * S;
    }

    /// Builds R's operators (c, k, m, the loading) and starts the driver from the set-up stage.
    Impl(const System& s, const detail::InitialState& start)
        : EventDriver(s, start.options, "cvode mode"),
          C(s.compliance_held()),
          c(s.coupling()),
          k(s.stiffness_n_per_m()),
          m(s.mass_kg()),
          load(start.options.loading) {
        seat = load.has_seat_load();
        if (seat) sc = s.seat_condensation();
        detail::EventStart es;
        // ODE size: [w, w', D], plus the external work W_e when a loading exerts a force (under
        // the paper's initial conditions it is identically zero and left out, so that CVODE's
        // error norm, an RMS over the states, is the same as without it).
        // With seat loads also t (y[kTime], t' = 1: integrated exactly at every order).
        es.nstate = seat ? kTime + 1 : load.is_free() ? 3 : 4;
        es.y0 = Eigen::VectorXd::Zero(es.nstate);
        es.y0[0] = start.w0_m;
        es.y0[1] = start.wd0_m_per_s;
        es.scales = detail::event_scales(s, scale_inputs(start));
        es.compliance = C;
        // ||v|| of an exact active-set answer is LU round-off, ~cond(C') 1e-16 L_ref ~ 1e-11 L_ref;
        // 1e-10 L_ref accepts it and still resolves the look-ahead (1e-7 L_ref) a thousandfold.
        es.event_tolerance_m = 1e-10 * es.scales.L_ref_m;
        es.events = this;  // contact events (ContactEventHooks)
        es.resolve_initial_forces = false;  // the stage solved the forces with R held at w(0) (exact)
        // ... without seat loads: a seat load that does not start from 0 moves the stack from the
        // stage's state, so the forces are solved again with S(0) (the event problem at motion(y0)).
        if (seat && seat_load(0.0).squaredNorm() > 0.0) es.resolve_initial_forces = true;
        this->start(start, es);
    }

    /// The witness scales' inputs (event_driver.hpp): R's amplitude on the softest stack (no
    /// contact force) with the largest external force over the run (sampled, table points
    /// included; gravity: the static deflection), the stiffest frequency (everything tied).
    detail::ScaleInputs scale_inputs(const detail::InitialState& start) const {
        double fe_max = 0.0;
        const double t_end = options().t_end_s;
        for (int i = 0; i <= 4000; ++i) fe_max = std::max(fe_max, std::abs(fe(t_end * i / 4000.0)));
        for (double tp : load.force_n.times_s) fe_max = std::max(fe_max, std::abs(fe(tp)));
        const double k_tied = system().num_components() > 0 ? system().tied_stiffness_n_per_m() / spring_factor() : k;
        detail::ScaleInputs in;
        in.stiffness_n_per_m = std::max(k_tied, k);
        in.omega_rad_per_s = std::sqrt(std::max(k_tied, k) / m);
        in.omega_amplitude_rad_per_s = std::sqrt(k / m);
        in.w0_m = system().model().spec().rigid_body.initial_displacement_m;
        in.wd0_m_per_s = start.wd0_m_per_s;
        in.deflection_m = fe_max / k;
        return in;
    }

    // ---- modes -------------------------------------------------------------------

    /// Factorises the linear conditions of the current modes (cvode_stepper.hpp).
    /// Unknowns are the forces of the held rows S (closed normal, stuck tangential:
    /// s_row = 0, i.e. (C'p)_row = d_row - c_row w); the others follow from them:
    /// open and free rows carry 0, a slipping row p_t = sigma mu tau, affine in its
    /// pair's normal force (coulomb: -p_n; clamp: F_c - p_n). So p = T p_S + e and
    ///     (C'_S: T) p_S = d_S - c_S w - C'_S: e,
    /// an |S| x |S| LU (|S| is small when most pairs are open or slipping).
    void build_mode(const modes::ModeLinearization& lin) override {
        const int n = rows();
        const Eigen::VectorXd& d = anchors();
        const std::vector<int>& S = lin.S;
        const detail::ModeMap T(lin, n);  // p = T p_S + e
        const int ms = T.columns;
        const Eigen::MatrixXd CT = T.compliance_times(C);  // C' T, all rows
        const Eigen::VectorXd& e = lin.e;
        const Eigen::VectorXd Ce = C * e;
        Eigen::MatrixXd A(ms, ms);
        Eigen::VectorXd b1(ms), b0(ms);
        for (int i = 0; i < ms; ++i) {
            A.row(i) = CT.row(S[i]);
            b1[i] = -c[S[i]];
            b0[i] = d[S[i]] - Ce[S[i]];
        }
        Eigen::VectorXd x1 = Eigen::VectorXd::Zero(ms), x0 = Eigen::VectorXd::Zero(ms);
        if (ms > 0) {
            lu.compute(A);
            x1 = lu.solve(b1);
            x0 = lu.solve(b0);
            if (!x1.allFinite() || !x0.allFinite()) throw failure("the contact conditions of the current modes are singular");
        }
        P = Eigen::VectorXd::Zero(n);
        r = e;
        for (const auto& l : T.links) {
            P[l.row] += l.coef * x1[l.col];
            r[l.row] += l.coef * x0[l.col];
        }
        hs = CT * x1 + c;       // C'P + c
        bs = CT * x0 + Ce - d;  // C'r - d
        a1 = c.dot(P) - k;
        a0 = c.dot(r);
        diss_a = diss_b = 0.0;
        slip_rows.clear();
        for (int kk = 0; kk < num_pairs(); ++kk) {
            const int rt = pairs()[kk].row_t;
            if (rt >= 0 && (modes().tmode[kk] == SLIP_POS || modes().tmode[kk] == SLIP_NEG)) {
                diss_a += P[rt] * hs[rt];
                diss_b += r[rt] * hs[rt];
                slip_rows.push_back(rt);
            }
        }
        if (!seat) return;
        // the seat loads' columns: (C'_S: T) xS = -B_S, p += T xS S, s += (C' T xS + B) S
        Eigen::MatrixXd xS = Eigen::MatrixXd::Zero(ms, 2);
        if (ms > 0) {
            Eigen::MatrixXd bS(ms, 2);
            for (int i = 0; i < ms; ++i) bS.row(i) = -sc.B.row(S[i]);
            xS = lu.solve(bS);
            if (!xS.allFinite()) throw failure("the contact conditions of the current modes are singular");
        }
        PS = Eigen::MatrixXd::Zero(n, 2);
        for (const auto& l : T.links) PS.row(l.row) += l.coef * xS.row(l.col);
        hS = CT * xS + sc.B;
        aS = PS.transpose() * c - sc.g;
    }

    Eigen::VectorXd forces(double w) const { return P * w + r; }
    Vec forces(const State& y) const override { return seat ? Vec(forces(y[0]) + PS * seat_load(y)) : forces(y[0]); }
    Vec relative(const State& y) const override {
        return seat ? Vec(hs * y[0] + bs + anchors() + hS * seat_load(y)) : Vec(hs * y[0] + bs + anchors());
    }
    Vec relative_at_event(const State& y, const Vec& p_cur) const override {
        // in a built mode affine in w (O(n)), else (t = 0) from the forces
        return P.size() == rows() ? relative(y) : Vec(C * p_cur + motion(y));
    }
    Vec motion(const State& y) const override { return seat ? Vec(c * y[0] + sc.B * seat_load(y)) : Vec(c * y[0]); }
    /// The witnesses of cvode_stepper.hpp at (w, w'): s = hs w + bs, ds_t/dt = hs_t w' (with seat loads
    /// at (t, w, w'): s + hS S(t), ds_t/dt + hS_t S'(t)).
    void witnesses(const State& y, double* g) const override {
        const double w = y[0], wd = y[1];
        if (seat) {
            const Eigen::Vector2d S = seat_load(y), Sd = seat_rate(y[kTime]);
            witnesses_from(
                forces(y), [&](int row) { return hs[row] * w + bs[row] + hS.row(row).dot(S); },
                [&](int row) { return hs[row] * wd + hS.row(row).dot(Sd); }, g);
            return;
        }
        witnesses_from(
            forces(w), [&](int row) { return hs[row] * w + bs[row]; }, [&](int row) { return hs[row] * wd; }, g);
    }

    /// R a short look-ahead on (cvode_stepper.hpp): |dw| = kLookahead L_ref along w' and w''.
    /// With seat loads the contact points also move by B S(t) (the event problem's motion): the
    /// look-ahead is then also at most kLookahead L_ref of that motion, |B S'| delta, and moves t.
    Vec look_ahead(double te, const State& y, const Vec& p_cur) const override {
        const double w = y[0], wd = y[1];
        const double wdd = (c.dot(p_cur) - k * w + fe(te) - (seat ? sc.g.dot(seat_load(y)) : 0.0)) / m;
        const double target = kLookahead * scales().L_ref_m;
        double delta = std::numeric_limits<double>::infinity();
        if (wd != 0.0) delta = std::min(delta, target / std::abs(wd));
        if (wdd != 0.0) delta = std::min(delta, std::sqrt(2.0 * target / std::abs(wdd)));
        if (seat && rows() > 0) {  // B S(t) along S' and S'' as w along w' and w'' (a load from rest has S' ~ 0)
            const double vS = (sc.B * seat_rate(y[kTime])).lpNorm<Eigen::Infinity>();
            const double aS_ = (sc.B * seat_acceleration(y[kTime])).lpNorm<Eigen::Infinity>();
            if (vS > 0.0) delta = std::min(delta, target / vS);
            if (aS_ > 0.0) delta = std::min(delta, std::sqrt(2.0 * target / aS_));
        }
        if (!std::isfinite(delta)) delta = 0.0;
        Vec yl = y;
        yl[0] = w + (wd * delta + 0.5 * wdd * delta * delta);
        yl[1] = wd + wdd * delta;
        if (seat) yl[kTime] = y[kTime] + delta;
        return yl;
    }

    void body_motion(const State& y, const Vec&, double& w, double& wd) const override {
        w = y[0];
        wd = y[1];
    }

    /// The massless leaves in equilibrium with the forces p and R at w = y[0] (the leaves carry no
    /// load of their own: gravity acts on R only).
    Vec displacements(const State& y, const Vec& p) const override {
        return seat ? system().reduced_displacements(p, y[0], seat_load(y)) : system().reduced_displacements(p, y[0]);
    }

    /// The massless layer stores no energy of its own: a force jump is only noted.
    void after_event(const std::string&, const Vec& p_cur, const Vec& p_new) override { note_force_jump(p_cur, p_new); }

    // ---- CVODE -------------------------------------------------------------------

    /// y = [w, w', D (, W_e)]: m w'' = a1 w + a0 + F_e(t), D' = -w' (diss_a w + diss_b), W_e' = F_e w'.
    /// With seat loads (t = y[kTime]): m w'' += aS^T S, D' = -sum_slip p_t ds_t/dt at (t, w, w'), the seat
    /// loads' power S^T d[theta_R; u_R]/dt into W_e (d/dt (B^T p - g w + F S), p' = P w' + PS S'), t' = 1.
    void derivatives(double tt, const double* yy, double* dy) const override {
        const double fe_t = fe(tt);
        if (seat) {
            const double w = yy[0], wd = yy[1];
            const Eigen::Vector2d S = seat_load(tt), Sd = seat_rate(tt);
            dy[0] = wd;
            dy[1] = (a1 * w + a0 + aS.dot(S) + fe_t) / m;
            double diss = 0.0;
            for (int rt : slip_rows) diss -= (P[rt] * w + r[rt] + PS.row(rt).dot(S)) * (hs[rt] * wd + hS.row(rt).dot(Sd));
            dy[2] = diss;
            const Eigen::Vector2d motion_rate = (rows() > 0 ? Eigen::Vector2d(sc.B.transpose() * (P * wd + PS * Sd))
                                                            : Eigen::Vector2d::Zero()) -
                                                sc.g * wd + sc.F * Sd;
            dy[3] = fe_t * wd + S.dot(motion_rate);
            dy[kTime] = 1.0;
            return;
        }
        dy[0] = yy[1];
        dy[1] = (a1 * yy[0] + a0 + fe_t) / m;
        dy[2] = -yy[1] * (diss_a * yy[0] + diss_b);
        if (nstate() > 3) dy[3] = fe_t * yy[1];  // power of the external force (meshed part)
    }

    void tolerances(const State&, Eigen::Ref<Vec> at) const override {
        const double atol = options().cvode.atol_m;
        at[0] = atol;                                  // w [m]
        at[1] = atol * scales().omega_rad_per_s;       // w' [m/s]
        at[2] = atol * scales().F_ref_n;               // D [J]
        if (nstate() > 3) at[3] = atol * scales().F_ref_n;  // external work [J]
        if (seat) at[kTime] = atol / scales().L_ref_m / scales().omega_rad_per_s;  // t [s] (exact: t' = 1)
    }

    // ---- records -----------------------------------------------------------------

    StepRecord make_record(double tau, const State& y, Vec& p, Vec&) const override {
        const int n = rows();
        const double f = spring_factor();
        const double w = y[0], wd = y[1], D = y[2], We = nstate() > 3 ? y[3] : 0.0;
        p = n > 0 ? forces(y) : Vec();
        // U = (p^T C' p + k w^2) / 2 on the meshed part, with C'p = s + d - c w = hs w + bs + d - c w (O(n));
        // with seat loads U = z^T K z / 2 = (p^T (s + d) + f_R w + S^T [theta_R; u_R]) / 2 (K z = G^T p + e_w f_R
        // + E S, SeatCondensation's s, f_R and motion; the full model, f = 1).
        const Eigen::Vector2d S = seat_load(y);
        const Eigen::Vector2d seat_at = seat ? seat_motion(p, w, S) : Eigen::Vector2d::Zero();
        const double strain =
            seat ? 0.5 * ((n > 0 ? p.dot(relative(y) - c * w) : 0.0) + k * w * w + sc.g.dot(S) * w + S.dot(seat_at))
                 : 0.5 * f * ((n > 0 ? p.dot(hs * w + bs + anchors() - c * w) : 0.0) + k * w * w);
        StepRecord rec;
        detail::LoadState ls;
        ls.external_force_n = f * fe(tau);
        ls.external_work_j = f * We;
        ls.base_displacement_m = load.base_displacement_m(tau);
        detail::fill_state(system(), laws(), p, w, wd, strain, f * D, initial_energy_j(), ls, rec);
        if (seat) {  // R's force on the stack with the seat loads (SeatCondensation), and the seat's records
            rec.spring_force_n += sc.g.dot(S);
            rec.force_on_mass_n = rec.external_force_n - rec.spring_force_n;
            rec.seat_moment_n_m = S[0];
            rec.seat_rotation_rad = seat_at[0];
            rec.seat_axial_m = seat_at[1];
        }
        return rec;
    }
};

CvodeStepper::CvodeStepper(const System& system, const SimulationOptions& options)
    : impl_(std::make_unique<Impl>(system, detail::initial_state("cvode-massless", system, options))) {}

CvodeStepper::CvodeStepper(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

std::unique_ptr<Stepper> CvodeStepperAccess::build(const System& system, const detail::InitialState& start) {
    return std::unique_ptr<Stepper>(new CvodeStepper(std::make_unique<CvodeStepper::Impl>(system, start)));
}

CvodeStepper::~CvodeStepper() = default;

const StepRecord& CvodeStepper::advance() { return impl_->advance(); }
const StepRecord& CvodeStepper::current() const noexcept { return impl_->current(); }
long CvodeStepper::num_outputs() const noexcept { return impl_->num_outputs(); }
long CvodeStepper::record_index() const noexcept { return impl_->record_index(); }
std::vector<PairRecord> CvodeStepper::pairs() const {
    const Impl& s = *impl_;
    const Eigen::VectorXd& p = s.contact_forces();
    if (p.size() == 0) return s.pair_records_at(Eigen::VectorXd());
    Eigen::VectorXd rel = s.C * p + s.c * s.current().w_m;
    if (s.seat) rel += s.sc.B * s.seat_load(s.current().t_s);  // s + d = C'p + c w + B S (SeatCondensation)
    return s.pair_records_at(rel);
}
std::vector<LeafNodes> CvodeStepper::nodes() const { return impl_->nodes_at_output(); }
Stresses CvodeStepper::stresses() const { return compute_stresses(impl_->system(), impl_->displacements_at_output(), pairs()); }
RunReport CvodeStepper::report() const { return impl_->report(); }
const Eigen::VectorXd& CvodeStepper::contact_forces() const noexcept { return impl_->contact_forces(); }
const std::vector<ContactEvent>& CvodeStepper::events() const noexcept { return impl_->events(); }
const CvodeStats& CvodeStepper::stats() const noexcept { return impl_->stats(); }
const System& CvodeStepper::system() const noexcept { return impl_->system(); }

}  // namespace stackbeam
