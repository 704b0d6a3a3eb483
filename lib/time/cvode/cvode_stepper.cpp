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
#include "time/cvode/event_driver.hpp"
#include "time/record.hpp"
#include "time/initial_state.hpp"
#include "stackbeam/errors.hpp"

namespace stackbeam {
namespace {

// Pair modes: those of the active-set solvers (active_set.hpp).
using detail::CLOSED;
using detail::FREE;
using detail::SLIP_NEG;
using detail::SLIP_POS;
using detail::STICK;
using detail::kForceMargin;
using detail::kLookahead;
using detail::kMotionMargin;

}  // namespace

bool ContactEvent::is_stick_slip() const {
    auto fr = [](const std::string& s) { return s == "stick" || s == "slip+" || s == "slip-"; };
    return fr(from) && fr(to);
}

struct CvodeStepper::Impl final : detail::EventDriver {
    const Eigen::MatrixXd& C;  // C' [m/N]
    Eigen::VectorXd c;         // coupling [-]
    double k = 0, m = 0;
    Loading load;              // the loading (loading.hpp), prepared
    double m_whole = 0;        // R's whole mass [kg]
    /// External force on R of the meshed part at t [N] (loading.hpp: F/f - m g - m y_b'').
    double fe(double t_s) const { return load.external_force_n(t_s, m_whole) / f; }
    // ODE size nstate: [w, w', D], plus the external work W_e when a loading exerts a force
    // (under the paper's initial conditions it is identically zero and left out, so
    // that CVODE's error norm, an RMS over the states, is the same as without it).
    double omega_ref = 1;

    // the current mode set: p(w) = P w + r, s(w) = hs w + bs, m w'' = a1 w + a0,
    // D' = -w' (diss_a w + diss_b)
    Eigen::VectorXd P, r, hs, bs;
    double a1 = 0, a0 = 0, diss_a = 0, diss_b = 0;
    Eigen::PartialPivLU<Eigen::MatrixXd> lu;

    Impl(const System& s, const SimulationOptions& o) : EventDriver(s, o, "cvode mode"), C(s.compliance_held()) {}

    // ---- modes -------------------------------------------------------------------

    /// Factorises the linear conditions of the current modes (cvode_stepper.hpp).
    /// Unknowns are the forces of the held rows S (closed normal, stuck tangential:
    /// s_row = 0, i.e. (C'p)_row = d_row - c_row w); the others follow from them:
    /// open and free rows carry 0, a slipping row p_t = sigma mu tau, affine in its
    /// pair's normal force (coulomb: -p_n; clamp: F_c - p_n). So p = T p_S + e and
    ///     (C'_S: T) p_S = d_S - c_S w - C'_S: e,
    /// an |S| x |S| LU (|S| is small when most pairs are open or slipping).
    void build_mode() override {
        detail::ModeLinearization lin;
        modes.linearize(chk_problem, lin);
        const std::vector<int>& S = lin.S;
        std::vector<int> pos(n, -1);
        const int ms = static_cast<int>(S.size());
        for (int i = 0; i < ms; ++i) pos[S[i]] = i;
        // p = T p_S + e: T as (row, column, coefficient) triplets
        Eigen::MatrixXd CT = Eigen::MatrixXd::Zero(n, ms);  // C' T, all rows
        const Eigen::VectorXd& e = lin.e;
        struct Link { int row, col; double coef; };
        std::vector<Link> T;
        for (int i = 0; i < ms; ++i) T.push_back({S[i], i, 1.0});
        for (std::size_t i = 0; i < lin.coupled.size(); ++i)
            if (pos[lin.coupled[i].second] >= 0) T.push_back({lin.coupled[i].first, pos[lin.coupled[i].second], lin.coef[i]});
        for (const auto& l : T) CT.col(l.col) += l.coef * C.col(l.row);
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
            if (!x1.allFinite() || !x0.allFinite())
                throw SolverError("cvode mode: the contact conditions of the current modes are singular at t = " +
                                      format_value(t) + " s",
                                  stats.steps, t, 0.0);
        }
        P = Eigen::VectorXd::Zero(n);
        r = e;
        for (const auto& l : T) {
            P[l.row] += l.coef * x1[l.col];
            r[l.row] += l.coef * x0[l.col];
        }
        hs = CT * x1 + c;       // C'P + c
        bs = CT * x0 + Ce - d;  // C'r - d
        a1 = c.dot(P) - k;
        a0 = c.dot(r);
        diss_a = diss_b = 0.0;
        for (int kk = 0; kk < np; ++kk) {
            const int rt = pairs()[kk].row_t;
            if (rt >= 0 && (tmode[kk] == SLIP_POS || tmode[kk] == SLIP_NEG)) {
                diss_a += P[rt] * hs[rt];
                diss_b += r[rt] * hs[rt];
            }
        }
        ++stats.mode_factorizations;
        ++facts_since;
    }

    Eigen::VectorXd forces(double w) const { return P * w + r; }
    Vec forces(const State& y) const override { return forces(y[0]); }
    Vec relative(const State& y) const override { return hs * y[0] + bs + d; }
    Vec relative_at_event(const State& y, const Vec& p_cur) const override {
        // in a built mode affine in w (O(n)), else (t = 0) from the forces
        return P.size() == n ? relative(y) : Vec(C * p_cur + c * y[0]);
    }
    Vec motion(const State& y) const override { return c * y[0]; }
    void witnesses(const State& y, double* g) const override { witnesses(y[0], y[1], g); }

    /// Witness functions at (w, w'): positive while the modes hold.
    void witnesses(double w, double wd, double* g) const {
        for (std::size_t i = 0; i < slots.size(); ++i) {
            const int kk = slots[i].pair;
            const auto& cp = pairs()[kk];
            const auto pn = [&] { return cp.row_n >= 0 ? P[cp.row_n] * w + r[cp.row_n] : 0.0; };
            double v = 1.0;
            double margin = kForceMargin;
            if (slots[i].normal) {
                if (cp.kind == PairKind::coulomb) {
                    if (nmode[kk] == CLOSED) {
                        v = -pn() / F_ref;
                    } else {
                        v = -(hs[cp.row_n] * w + bs[cp.row_n]) / L_ref;
                        margin = kMotionMargin;
                    }
                } else {  // clamp: engaged while p_n < F_c
                    v = tmode[kk] == FREE ? (pn() - cp.preload_n) / F_ref : (cp.preload_n - pn()) / F_ref;
                }
            } else {
                const int rt = cp.row_t;
                const double pt = P[rt] * w + r[rt];
                switch (tmode[kk]) {
                    case STICK: {
                        const double tau_n = cp.kind == PairKind::clamp ? std::max(0.0, cp.preload_n - pn()) : -pn();
                        v = (cp.friction_coefficient * tau_n - std::abs(pt)) / F_ref;
                        break;
                    }
                    case SLIP_POS: v = -hs[rt] * wd / V_ref; margin = kMotionMargin; break;
                    case SLIP_NEG: v = hs[rt] * wd / V_ref; margin = kMotionMargin; break;
                    default: v = 1.0; break;
                }
            }
            g[i] = v + margin;
        }
    }

    /// R a short look-ahead on (cvode_stepper.hpp): |dw| = kLookahead L_ref along w' and w''.
    Vec look_ahead(double te, const State& y, const Vec& p_cur) const override {
        const double w = y[0], wd = y[1];
        const double wdd = (c.dot(p_cur) - k * w + fe(te)) / m;
        const double target = kLookahead * L_ref;
        double delta = std::numeric_limits<double>::infinity();
        if (wd != 0.0) delta = std::min(delta, target / std::abs(wd));
        if (wdd != 0.0) delta = std::min(delta, std::sqrt(2.0 * target / std::abs(wdd)));
        if (!std::isfinite(delta)) delta = 0.0;
        Vec yl = y;
        yl[0] = w + (wd * delta + 0.5 * wdd * delta * delta);
        yl[1] = wd + wdd * delta;
        return yl;
    }

    void body_motion(const State& y, const Vec&, double& w, double& wd) const override {
        w = y[0];
        wd = y[1];
    }

    /// The massless leaves in equilibrium with the forces p and R at w = y[0] (the leaves carry no
    /// load of their own: gravity acts on R only).
    Vec displacements(const State& y, const Vec& p) const override { return sys.reduced_displacements(p, y[0]); }

    void after_event(const std::string&, const Vec& p_cur, const Vec& p_new) override {
        if (n > 0) stats.max_force_jump_n = std::max(stats.max_force_jump_n, (p_new - p_cur).lpNorm<Eigen::Infinity>());
    }

    // ---- CVODE -------------------------------------------------------------------

    static int rhs(sunrealtype tt, N_Vector yv, N_Vector ydot, void* user) {
        const auto* self = static_cast<const Impl*>(static_cast<const detail::EventDriver*>(user));
        const double* yy = N_VGetArrayPointer(yv);
        double* dy = N_VGetArrayPointer(ydot);
        const double fe = self->fe(tt);
        dy[0] = yy[1];
        dy[1] = (self->a1 * yy[0] + self->a0 + fe) / self->m;
        dy[2] = -yy[1] * (self->diss_a * yy[0] + self->diss_b);
        if (self->nstate > 3) dy[3] = fe * yy[1];  // power of the external force (meshed part)
        return 0;
    }

    // ---- records -----------------------------------------------------------------

    StepRecord make_record(double tau, const State& y, Vec& p, Vec&) const override {
        const double w = y[0], wd = y[1], D = y[2], We = nstate > 3 ? y[3] : 0.0;
        p = n > 0 ? forces(w) : Vec();
        // U = (p^T C' p + k w^2) / 2 on the meshed part, with C'p = s + d - c w = hs w + bs + d - c w (O(n))
        const double strain = 0.5 * f * ((n > 0 ? p.dot(hs * w + bs + d - c * w) : 0.0) + k * w * w);
        StepRecord rec;
        detail::LoadState ls;
        ls.external_force_n = f * fe(tau);
        ls.external_work_j = f * We;
        ls.base_displacement_m = load.base_displacement_m(tau);
        detail::fill_state(sys, chk_problem, p, w, wd, strain, f * D, e0, ls, rec);
        return rec;
    }

};

CvodeStepper::CvodeStepper(const System& system, const SimulationOptions& options)
    : CvodeStepper(system, detail::initial_state("cvode-massless", system, options)) {}

CvodeStepper::CvodeStepper(const System& system, const detail::InitialState& start)
    : impl_(std::make_unique<Impl>(system, start.options)) {
    Impl& s = *impl_;
    s.c = system.coupling();
    s.k = system.stiffness_n_per_m();
    s.m = system.mass_kg();
    s.load = start.options.loading;
    s.m_whole = system.model().spec().rigid_body.mass_kg;
    s.nstate = s.load.is_free() ? 3 : 4;
    // The largest external force over the run (sampled; table points included) sets a
    // displacement scale F_e/k for the witnesses (gravity: the static deflection).
    double fe_max = 0.0;
    for (int i = 0; i <= 4000; ++i) fe_max = std::max(fe_max, std::abs(s.fe(s.opt.t_end_s * i / 4000.0)));
    for (double tp : s.load.force_n.times_s) fe_max = std::max(fe_max, std::abs(s.fe(tp)));

    // Scales of the run: the amplitude of R on the softest stack (no contact force),
    // the stiffest frequency (everything tied), the largest clamp preload.
    const double k_tied = system.num_components() > 0 ? system.tied_stiffness_n_per_m() / s.f : s.k;
    const double omega_free = std::sqrt(s.k / s.m);
    s.omega_ref = std::sqrt(std::max(k_tied, s.k) / s.m);
    s.L_ref = std::abs(system.model().spec().rigid_body.initial_displacement_m) +
              std::abs(start.wd0_m_per_s) / omega_free + fe_max / s.k;
    if (!(s.L_ref > 0.0)) s.L_ref = 1e-3;  // at rest: nothing moves; any scale will do
    double preload = 0.0;
    for (const auto& cp : system.pairs()) preload = std::max(preload, cp.preload_n);
    s.F_ref = std::max(preload, std::max(k_tied, s.k) * s.L_ref);
    s.V_ref = s.omega_ref * s.L_ref;

    s.init_grid();  // as the closed-form mode's steps
    s.init_slots();
    // ||v|| of an exact active-set answer is LU round-off, ~cond(C') 1e-16 L_ref ~ 1e-11 L_ref;
    // 1e-10 L_ref accepts it and still resolves the look-ahead (1e-7 L_ref) a thousandfold.
    s.init_problems(system.compliance_held(), 1e-10 * s.L_ref);

    // The initial state (gravity's static step, R held at w(0): initial_state.hpp), then the modes.
    s.d = start.d;
    detail::modes_from_solution(s.chk_problem, start.p, 1e-12 * s.F_ref, s.nmode, s.tmode);
    s.cvode = std::make_unique<detail::CvodeSession>(s.who, s.nstate);
    auto y0 = s.cvode->y();
    y0[0] = start.w0_m;
    y0[1] = start.wd0_m_per_s;
    s.decide_modes(0.0, y0, start.p, "start");
    auto at = s.cvode->atol();
    at[0] = s.opt.cvode.atol_m;                 // w [m]
    at[1] = s.opt.cvode.atol_m * s.omega_ref;   // w' [m/s]
    at[2] = s.opt.cvode.atol_m * s.F_ref;       // D [J]
    if (s.nstate > 3) at[3] = s.opt.cvode.atol_m * s.F_ref;  // external work [J]
    s.start_cvode(&Impl::rhs);
    s.start_record(s.cvode->y());
}

CvodeStepper::~CvodeStepper() = default;

const StepRecord& CvodeStepper::advance() { return impl_->advance(); }
const StepRecord& CvodeStepper::current() const noexcept { return impl_->current(); }
long CvodeStepper::num_outputs() const noexcept { return impl_->n_out; }
long CvodeStepper::record_index() const noexcept { return impl_->record_index(); }
std::vector<PairRecord> CvodeStepper::pairs() const {
    const Impl& s = *impl_;
    return s.pair_records_at(s.p_out.size() > 0 ? Eigen::VectorXd(s.C * s.p_out + s.c * s.record.w_m) : Eigen::VectorXd());
}
std::vector<LeafNodes> CvodeStepper::nodes() const { return impl_->nodes_at_output(); }
RunReport CvodeStepper::report() const { return impl_->report(); }
const Eigen::VectorXd& CvodeStepper::contact_forces() const noexcept { return impl_->p_out; }
const std::vector<ContactEvent>& CvodeStepper::events() const noexcept { return impl_->events; }
const CvodeStats& CvodeStepper::stats() const noexcept { return impl_->stats; }
const System& CvodeStepper::system() const noexcept { return impl_->sys; }

}  // namespace stackbeam
