// The event driver of the event-driven cvode steppers (event_driver.hpp; the method in
// cvode_stepper.hpp).
#include "time/cvode/event_driver.hpp"
#include "fe/tied_shape.hpp"
#include "stackbeam/model/loading.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "model/mesh_note.hpp"
#include "stackbeam/errors.hpp"
#include "time/contact_state.hpp"
#include "time/record.hpp"

namespace stackbeam::detail {

double largest_value(const TimeFunction& F) {
    double v = std::abs(F.mean) + F.amplitude;
    for (double x : F.values) v = std::max(v, std::abs(x));
    return v;
}

EventScales event_scales(const System& system, const ScaleInputs& in) {
    EventScales s;
    s.omega_rad_per_s = in.omega_rad_per_s;
    s.L_ref_m = std::abs(in.w0_m) + std::abs(in.wd0_m_per_s) / in.omega_amplitude_rad_per_s + in.deflection_m +
                in.motion_max_m;
    if (!(s.L_ref_m > 0.0)) s.L_ref_m = 1e-3;  // at rest: nothing moves; any scale will do
    s.V_ref_m_per_s = in.omega_rad_per_s * s.L_ref_m;
    double preload = 0.0;
    for (const auto& cp : system.pairs()) preload = std::max(preload, cp.preload_n);
    s.F_ref_n = std::max(preload, in.stiffness_n_per_m * s.L_ref_m);
    return s;
}

ScaleInputs leaf_mass_scale_inputs(const System& system, const Loading& L) {
    const auto& body = system.model().spec().rigid_body;
    const double k_t = system.tied_stiffness_n_per_m(), f = system.model().whole_spring_factor();
    ScaleInputs in;
    in.omega_rad_per_s = in.omega_amplitude_rad_per_s = std::sqrt(k_t / body.mass_kg);
    in.stiffness_n_per_m = k_t / f;
    in.w0_m = body.initial_displacement_m;
    in.wd0_m_per_s = body.initial_velocity_m_per_s;
    // [N, whole spring] / [N/m, whole spring]: the applied force's largest value and the weight of everything
    const double force_scale = (L.kind == LoadingKind::applied_force ? largest_value(L.force_n) : 0.0) +
                               f * L.gravity_m_per_s2 * system.vertical_inertia_kg().sum();
    in.deflection_m = force_scale / k_t;
    in.motion_max_m = L.kind == LoadingKind::base_excitation || L.kind == LoadingKind::prescribed_displacement
                          ? largest_value(L.displacement_m)
                          : 0.0;
    return in;
}

EventDriver::EventDriver(const System& system, const SimulationOptions& options, std::string who)
    : sys_(system),
      opt_(options),
      who_(std::move(who)),
      n_(system.num_components()),
      np_(static_cast<int>(system.pairs().size())),
      ndof_(system.num_reduced_dofs()),
      f_(system.model().whole_spring_factor()),
      m_body_(system.model().spec().rigid_body.mass_kg),
      d_(system.initial_offsets_m()),
      root_finding_(true) {}

EventDriver::~EventDriver() = default;

double EventDriver::seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

void EventDriver::finish_inertia_record(StepRecord& rec, double kinetic_j, double force_on_mass_n,
                                        double damping_energy_j) const {
    rec.leaf_kinetic_energy_j = kinetic_j - rec.kinetic_energy_j;
    rec.kinetic_energy_j = kinetic_j;
    rec.impact_loss_j = 0.0;
    rec.damping_energy_j = damping_energy_j;
    rec.force_on_mass_n = force_on_mass_n;
    rec.energy_balance_error_j = e0_ + rec.external_work_j -
                                 (kinetic_j + rec.strain_energy_j + rec.dissipated_energy_j + rec.damping_energy_j);
}

void EventDriver::init_grid() {
    dt_ = opt_.dt_s;
    n_out_ = static_cast<long>(std::ceil(opt_.t_end_s / dt_ - 1e-9));
    t_final_ = static_cast<double>(n_out_) * dt_;
}

void EventDriver::init_slots() {
    for (int kk = 0; kk < np_; ++kk) {
        const auto& cp = sys_.pairs()[kk];
        if (cp.kind == PairKind::bonded) continue;
        const bool friction = cp.row_t >= 0 && cp.friction_coefficient > 0.0;
        if (cp.kind == PairKind::coulomb && cp.row_n >= 0) slots_.push_back({kk, true});
        if (cp.kind == PairKind::clamp && friction && cp.row_n >= 0) slots_.push_back({kk, true});
        if (friction && (cp.kind == PairKind::clamp || cp.row_n >= 0)) slots_.push_back({kk, false});
    }
}

void EventDriver::init_problems(const Eigen::MatrixXd& W, double event_tolerance_m) {
    StepSystem sys;  // the dense form alone: W given, u the motion of the state (q = u - d)
    sys.rows = n_;
    sys.dense = [&W] {
        DenseStepForm f;
        f.W = W;
        return f;
    };
    chk_problem_.op = std::make_shared<const ContactOperator>(sys, opt_.contact_path, opt_.solver.kind);
    chk_problem_.pairs = sys_.pairs();
    chk_problem_.tau_rule = TauRule::current;
    chk_problem_.tau_previous_n = Vec::Zero(np_);
    ev_problem_ = chk_problem_;
    ev_tolerance_ = event_tolerance_m;
}

void EventDriver::start_cvode(const EventStart& s) {
    cvode_->create(s.stiff_max_order > 0 ? CV_BDF : CV_ADAMS, &EventDriver::rhs_of, this, opt_.cvode.rtol);
    if (s.stiff_max_order > 0) {
        if (s.newton == NewtonSolver::band) cvode_->use_band_newton(s.band_upper, s.band_lower, &EventDriver::band_jacobian_of);
        else cvode_->use_embedded_newton(&EventDriver::psetup_of, &EventDriver::psolve_of, this);
        cvode_->set_max_order(s.stiff_max_order);
    } else {
        cvode_->use_fixed_point();
    }
    cvode_->set_limits(opt_.cvode.max_step_s);
    cvode_->set_stop_time(stop_time());
    if (root_finding_ && !slots_.empty()) cvode_->set_roots(static_cast<int>(slots_.size()), &EventDriver::roots_of);
}

int EventDriver::rhs_of(sunrealtype t, N_Vector y, N_Vector ydot, void* user) {
    static_cast<const EventDriver*>(user)->derivatives(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot));
    return 0;
}

int EventDriver::roots_of(sunrealtype, N_Vector y, sunrealtype* g, void* user) {
    const auto* self = static_cast<const EventDriver*>(user);
    self->ev_->witnesses(Eigen::Map<const Vec>(N_VGetArrayPointer(y), self->nstate_), g);
    return 0;
}

int EventDriver::psetup_of(sunrealtype, N_Vector, N_Vector, sunbooleantype, sunbooleantype* jcur, sunrealtype gamma,
                           void* user) {
    *jcur = SUNTRUE;
    return static_cast<EventDriver*>(user)->newton_setup(gamma);
}

int EventDriver::psolve_of(sunrealtype t, N_Vector y, N_Vector, N_Vector r, N_Vector x, sunrealtype gamma,
                           sunrealtype, int, void* user) {
    return static_cast<const EventDriver*>(user)->newton_solve(t, N_VGetArrayPointer(y), N_VGetArrayPointer(r),
                                                                N_VGetArrayPointer(x), gamma);
}

int EventDriver::band_jacobian_of(sunrealtype t, N_Vector y, N_Vector, SUNMatrix J, void* user, N_Vector, N_Vector,
                                  N_Vector) {
    const auto* self = static_cast<const EventDriver*>(user);
    BandMatrixView view(J);
    if (view.set_zero() != SUNMAT_SUCCESS) return -1;
    return self->band_jacobian(t, Eigen::Map<const Vec>(N_VGetArrayPointer(y), self->nstate_), view);
}

int EventDriver::newton_setup(double) { return -1; }
int EventDriver::newton_solve(double, const double*, const double*, double*, double) const { return -1; }
int EventDriver::band_jacobian(double, const State&, BandMatrixView) const { return -1; }
void EventDriver::started(const State&) {}
void EventDriver::cross_loading_break(double, Vec&) {}

void EventDriver::rebuild() {
    ModeLinearization lin;
    modes_.linearize(chk_problem_, n_, lin);
    ev_->build_mode(lin);
    ++stats_.mode_factorizations;
    ++facts_since_;
}

SolverError EventDriver::failure(const std::string& what) const {
    return SolverError(who_ + ": " + what + " at t = " + format_value(t_) + " s", stats_.steps, t_, 0.0);
}

void EventDriver::start(const InitialState& stage, const EventStart& s) {
    root_finding_ = stage.root_finding;
    nstate_ = s.nstate;
    ev_ = s.events;
    scales_ = s.scales;
    gap_margin_ = s.gap_margin;
    pair_chatter_limit_ = s.pair_chatter_limit;
    stats_.retained_modes = s.retained_modes;
    stats_.modal_cutoff_rad_per_s = s.modal_cutoff_rad_per_s;
    init_grid();  // as the closed-form mode's steps
    for (double tb : s.loading_breaks_s)
        if (tb > 0.0 && tb < t_final_) breaks_.push_back(tb);
    init_problems(s.compliance, s.event_tolerance_m);
    d_ = stage.d;  // the anchors of the set-up stage (gravity's static step, R held at w(0))
    cvode_ = std::make_unique<CvodeSession>(who_, nstate_);
    cvode_->y() = s.y0;
    const Vec y0 = s.y0;
    if (ev_) decide_initial_modes(stage, s);  // without events the stage's modes hold throughout
    started(y0);
    tolerances(y0, cvode_->atol());
    record_ = record_at(0.0, y0, p_out_, rel_out_);
    y_out_ = y0;
    e0_ = record_.kinetic_energy_j + record_.strain_energy_j;
    record_.energy_balance_error_j = 0.0;
    start_cvode(s);
}

void EventDriver::decide_initial_modes(const InitialState& stage, const EventStart& s) {
    init_slots();
    chk_solver_ = std::make_unique<StepContactSolver>(opt_.solver);
    ev_solver_ = std::make_unique<StepContactSolver>(event_solver_options(opt_.solver, ev_tolerance_));
    const Vec& y0 = s.y0;
    Vec p = stage.p;
    if (s.resolve_initial_forces) {  // the event problem at the motion of y0, warm-started at the stage's forces
        const Vec motion = ev_->motion(y0);
        ev_problem_.u = motion;
        ev_problem_.d = d_;
        const SolveResult r0 = ev_solver_->solve(ev_problem_, p);
        // a residual within the problem's round-off is what its numbers resolve (round_off_m)
        if (!r0.converged && !(r0.residual_m <= round_off_m(motion, d_)))
            throw SolverError("initial contact state: " + r0.message, 0, 0.0, r0.residual_m);
    }
    modes_from_solution(chk_problem_, p, 1e-12 * scales_.F_ref_n, modes_.nmode, modes_.tmode);
    if (s.resolve_initial_forces) rebuild();
    decide_modes(0.0, y0, p, "start");
}

double EventDriver::round_off_m(const Vec& motion, const Vec& d) const {
    // The event problem s = W p + (G z - d) is built from relative positions of the size of the
    // stack's deflection (1e-2 m); each is rounded to eps |G z|, so its natural-map residual
    // cannot be resolved below ~eps sqrt(m) max(|G z|, |d|): measured 3-27 times that on soak
    // seeds 14, 18 and 25 (cvode-massive), whose tolerance 1e-9 F_ref max(c_L) (a stiff layer,
    // a small reference force) was 3.7e-17 to 4.4e-16 m, under the round-off.
    constexpr double kRoundOff = 100.0;
    if (motion.size() == 0) return 0.0;
    const double scale = std::max(motion.lpNorm<Eigen::Infinity>(), d.lpNorm<Eigen::Infinity>());
    return kRoundOff * std::numeric_limits<double>::epsilon() * std::sqrt(static_cast<double>(motion.size())) * scale;
}

StepRecord EventDriver::record_at(double tau, const State& y, Vec& p, Vec& rel) {
    StepRecord rec = make_record(tau, y, p, rel);
    rec.t_s = tau;
    rec.contact_iterations = static_cast<int>(iters_since_);
    rec.factorizations = static_cast<int>(facts_since_);
    if (ev_) rec.contact_residual_m = last_check_residual_;  // else the stepper's (EventStart::events)
    iters_since_ = facts_since_ = 0;
    return rec;
}

std::vector<PairRecord> EventDriver::pair_records_at(const Vec& rel) const {
    return detail::pair_records(sys_, chk_problem_, p_out_, rel);
}

void EventDriver::enter(const Vec& rel, const std::vector<signed char>& nm, const std::vector<signed char>& tm) {
    for (int kk = 0; kk < np_; ++kk) {
        const auto& cp = pairs()[kk];
        if (cp.row_t >= 0 && cp.kind != PairKind::bonded && tm[kk] == STICK && modes_.tmode[kk] != STICK)
            d_[cp.row_t] = rel[cp.row_t];
    }
    modes_.nmode = nm;
    modes_.tmode = tm;
}

void ContactEventHooks::correct_decision(const State&, const Vec&, std::vector<signed char>&, std::vector<signed char>&) {}

bool ContactEventHooks::settle_at_state() const { return false; }

double ContactEventHooks::own_layer_compliance_m_per_n(int) const { return 0.0; }

bool EventDriver::stick_at_cones(const Vec& p_cur, const std::vector<signed char>& tm) {
    // A pair that leaves an event stuck has the force p_cur at y (a pair stuck before keeps its
    // anchor; a pair that sticks now is anchored where it is, rel = G z + c p_cur). Where that
    // force lies past the pair's cone (a slip decided to stop whose force the look-ahead carried
    // past mu tau, or a stuck pair whose stick witness fired and that stays stuck), its stick
    // witness is negative at y itself: the next step's check fails at once, and the run crept by
    // the bisection's time tolerance per restart (soak seed 18: 200 restarts within 1e-10 s,
    // |p_t| 2e-6 above mu tau). The slider takes up the excess: the anchor moves by
    // c (sigma mu tau - p_t), the force sits on its cone, the layer's energy c (p_t^2 - (mu tau)^2) / 2
    // released is friction work (after_event books the force jump). Decision 078.
    bool moved = false;
    for (int kk = 0; kk < np_; ++kk) {
        const auto& cp = pairs()[kk];
        if (cp.row_t < 0 || cp.kind == PairKind::bonded || tm[kk] != STICK) continue;
        const double c = ev_->own_layer_compliance_m_per_n(cp.row_t);
        if (!(c > 0.0)) continue;
        const double limit = cp.friction_coefficient * friction_normal_force(chk_problem_, kk, p_cur);
        const double pt = p_cur[cp.row_t];
        if (!(std::abs(pt) > limit)) continue;
        d_[cp.row_t] += c * ((pt > 0.0 ? limit : -limit) - pt);
        moved = true;
    }
    return moved;
}

void EventDriver::in_candidate_modes(const Vec& rel, const std::vector<signed char>& nm,
                                     const std::vector<signed char>& tm, bool build, const std::function<void()>& body) {
    const Vec d_saved = d_;
    const std::vector<signed char> nm_saved = modes_.nmode, tm_saved = modes_.tmode;
    enter(rel, nm, tm);
    if (build) rebuild();
    body();
    d_ = d_saved;
    modes_.nmode = nm_saved;
    modes_.tmode = tm_saved;
}

bool EventDriver::apply_slot_transitions(const std::function<bool(std::size_t)>& take, const Vec& p,
                                         std::vector<signed char>& nm, std::vector<signed char>& tm) const {
    bool any = false;
    for (std::size_t i = 0; i < slots_.size(); ++i) {
        if (!take(i)) continue;
        const int kk = slots_[i].pair;
        const auto& cp = pairs()[kk];
        apply_transition(cp, slots_[i].normal, cp.row_t >= 0 ? p[cp.row_t] : 0.0, nm[kk], tm[kk]);
        any = true;
    }
    return any;
}

void EventDriver::signs_follow_slip_rates(const Vec& rel, std::vector<signed char>& nm, std::vector<signed char>& tm,
                                          const std::function<Vec()>& rate, const std::vector<signed char>* cone_side) {
    // A contradicted slip reverses (a force jump of 2 mu tau), unless the pair is at the edge of
    // its cone on that slip's side: there it sticks (cone_side).
    const auto stops = [&](int kk, int sign) { return cone_side != nullptr && (*cone_side)[kk] == sign; };
    for (int pass = 0; pass < 3; ++pass) {
        bool changed = false;
        in_candidate_modes(rel, nm, tm, true, [&] {
            const Vec r = rate();
            for (int kk = 0; kk < np_; ++kk) {
                const int rt = pairs()[kk].row_t;
                if (rt < 0) continue;
                if (tm[kk] == SLIP_POS && r[rt] > kMotionMargin * scales_.V_ref_m_per_s) {
                    tm[kk] = stops(kk, 1) ? STICK : SLIP_NEG;
                    changed = true;
                } else if (tm[kk] == SLIP_NEG && r[rt] < -kMotionMargin * scales_.V_ref_m_per_s) {
                    tm[kk] = stops(kk, -1) ? STICK : SLIP_POS;
                    changed = true;
                }
            }
        });
        if (!changed) break;
    }
}

double EventDriver::stick_round_off_n(int kk, const Vec& force_round_off) const {
    const auto& cp = pairs()[kk];
    double r = force_round_off[cp.row_t];
    if (cp.row_n >= 0) r += cp.friction_coefficient * force_round_off[cp.row_n];
    return r;
}

void EventDriver::witnesses_from(const Vec& p, const std::function<double(int)>& s_of,
                                 const std::function<double(int)>& rate_of, double* g, const Vec* force_round_off) const {
    for (std::size_t i = 0; i < slots_.size(); ++i) {
        const int kk = slots_[i].pair;
        const auto& cp = pairs()[kk];
        double val = 1.0, margin = kForceMargin;
        if (slots_[i].normal) {
            const double pn = p[cp.row_n];
            if (cp.kind == PairKind::coulomb) {
                if (modes_.nmode[kk] == CLOSED) {
                    val = -pn / scales_.F_ref_n;
                } else {
                    val = -s_of(cp.row_n) / scales_.L_ref_m;
                    margin = gap_margin_;
                }
            } else {
                val = modes_.tmode[kk] == FREE ? (pn - cp.preload_n) / scales_.F_ref_n : (cp.preload_n - pn) / scales_.F_ref_n;
            }
        } else {
            const int rt = cp.row_t;
            switch (modes_.tmode[kk]) {
                case STICK:
                    val = (cp.friction_coefficient * friction_normal_force(chk_problem_, kk, p) - std::abs(p[rt])) / scales_.F_ref_n;
                    if (force_round_off != nullptr)  // the margin no finer than the forces' round-off
                        margin = std::max(margin, stick_round_off_n(kk, *force_round_off) / scales_.F_ref_n);
                    break;
                case SLIP_POS: val = -rate_of(rt) / scales_.V_ref_m_per_s; margin = kMotionMargin; break;
                case SLIP_NEG: val = rate_of(rt) / scales_.V_ref_m_per_s; margin = kMotionMargin; break;
                default: val = 1.0; break;
            }
        }
        g[i] = val + margin;
    }
}

void EventDriver::book_force_jump(const std::string& cause, double loss, const Vec& p_cur, const Vec& p_new) {
    if (cause == "start") return;
    jump_dissipation_ += loss;
    stats_.min_jump_dissipation_j = std::min(stats_.min_jump_dissipation_j, loss);
    stats_.max_force_jump_n = std::max(stats_.max_force_jump_n, (p_new - p_cur).lpNorm<Eigen::Infinity>());
}

void EventDriver::note_force_jump(const Vec& p_cur, const Vec& p_new) {
    if (n_ > 0) stats_.max_force_jump_n = std::max(stats_.max_force_jump_n, (p_new - p_cur).lpNorm<Eigen::Infinity>());
}

void EventDriver::decide_modes(double te, const Vec& y, const Vec& p_cur, const std::string& cause,
                               const std::vector<int>* triggered) {
    const auto t_start = Clock::now();
    const double contact_before = stats_.contact_time_s;
    const Vec rel = ev_->relative_at_event(y, p_cur);  // s + d
    // Incremental problem a look-ahead away: stuck pairs keep their anchors, every
    // other pair is anchored where it is (paper, section 5).
    const Vec y_la = ev_->look_ahead(te, y, p_cur);
    Vec d_la = d_;
    for (int kk = 0; kk < np_; ++kk) {
        const auto& cp = pairs()[kk];
        if (cp.row_t >= 0 && cp.kind != PairKind::bonded && modes_.tmode[kk] != STICK) d_la[cp.row_t] = rel[cp.row_t];
    }
    const Vec motion_la = ev_->motion(y_la);
    ev_problem_.u = motion_la;
    ev_problem_.d = d_la;

    std::vector<signed char> nm, tm;
    bool decided = false;
    if (triggered != nullptr && n_ > 0) {
        nm = modes_.nmode;
        tm = modes_.tmode;
        apply_slot_transitions([&](std::size_t i) { return (*triggered)[i] != 0; }, p_cur, nm, tm);
        // restored either way: the log below compares with the old modes
        in_candidate_modes(rel, nm, tm, true, [&] {
            // the stop test of the contact iteration at the look-ahead, and every witness
            const Vec pl = ev_->forces(y_la);
            const double v = error_vector(ev_problem_, pl, Vec(ev_->relative(y_la) - d_la)).norm();
            std::vector<double> g(slots_.size());
            if (!slots_.empty()) ev_->witnesses(y_la, g.data());
            decided = v < ev_tolerance_ && std::all_of(g.begin(), g.end(), [](double x) { return x >= 0.0; });
        });
        ++stats_.contact_iterations;
        ++iters_since_;
    }
    // The modes of the exact solution of ev_problem (its q set), slip signs corrected.
    const auto decide_by_solving = [&](const std::string& where) {
        Vec p_sol = p_cur;
        const auto t_solve = Clock::now();
        const SolveResult res = ev_solver_->solve(ev_problem_, p_sol);
        stats_.contact_time_s += seconds_since(t_solve);
        stats_.contact_iterations += res.iterations;
        iters_since_ += res.iterations;
        if (!res.converged && !(res.residual_m <= round_off_m(motion_la, d_la)))
            throw SolverError(who_ + ": the contact iteration " + where + " at t = " + format_value(t_) + " s (" + cause +
                                  ") did not converge: " + res.message + mesh_note(sys_.model()),
                              stats_.steps, t_, res.residual_m);
        modes_from_solution(chk_problem_, p_sol, 1e-12 * scales_.F_ref_n, nm, tm);
        ev_->correct_decision(y, rel, nm, tm);
    };
    if (!decided) decide_by_solving("deciding the modes");
    if (cause != "start" && engage_clamps_by_slider_rate(y, rel, nm, tm)) decided = false;

    // A stepper whose state decides every pair by itself (settle_at_state: the massive stack,
    // where only the layer is instantaneous) restarts only in modes that hold at y itself: a
    // witness the decided modes leave negative at y (a pair the look-ahead keeps closed that is
    // still in tension at y, its gap closing within the look-ahead) takes its transition, so
    // that root-finding, not the per-step check, finds the next one. Each such transition makes
    // its witness positive at y (closed in tension -> open with the gap c p; penetrating ->
    // closed in compression; over the cone -> slipping; a reversing slip -> sticking at its force).
    // Every other stepper does this at a missed event (cause "check": the per-step check found
    // the modes no longer holding): there the look-ahead's decision can leave a witness negative
    // at y, and a restart at y in those modes fails the next step's check at once, whose
    // bisection then finds the "event" again at y plus its time tolerance: the run creeps by
    // ~1e-12 s per restart until the step limit (the paper's friction case under cvode stalled
    // so at t = 21.96 s: a slip reversal decided at the look-ahead, slip- -> slip+ on a pair
    // with a small normal force, moved a stuck pair's force past its cone by 1.4e-8 F_ref at y;
    // docs/decisions/056). The modal stepper measured the look-ahead's decisions 2.3x closer to
    // the massive stack at root events, so a root event keeps them (test_cvode_modal).
    if ((ev_->settle_at_state() || cause == "check") && !slots_.empty()) {
        std::vector<double> g(slots_.size());
        for (int pass = 0; pass < kSettlePasses; ++pass) {
            bool changed = false;
            in_candidate_modes(rel, nm, tm, pass > 0 || !decided, [&] {
                ev_->witnesses(y, g.data());
                changed = apply_slot_transitions([&](std::size_t i) { return g[i] < 0.0; }, ev_->forces(y), nm, tm);
            });
            decided = true;  // the factorisation is of (nm, tm)
            if (!changed) break;
            decided = false;  // (nm, tm) changed after the last factorisation
            ++stats_.settled_transitions;
        }
        // Not settled in kSettlePasses (a coupled contact layer, the modal stepper's W = G R G^T:
        // one pair's transition moves the others' forces): the modes of the contact problem at y
        // itself (stuck pairs at their anchors, the others anchored where they are), which hold
        // at y by construction, slip signs from the rates as after the look-ahead's decision.
        if (!decided) {
            bool holds = false;
            in_candidate_modes(rel, nm, tm, true, [&] {
                ev_->witnesses(y, g.data());
                holds = std::all_of(g.begin(), g.end(), [](double x) { return x >= 0.0; });
            });
            decided = true;
            if (!holds) {
                ev_problem_.u = ev_->motion(y);  // the anchors of the look-ahead's problem, at y
                decide_by_solving("at the state");
                decided = false;
                ++stats_.settled_transitions;
            }
        }
    }

    // Log the transitions, enter the new modes, refactorise (unless the candidate was).
    double w = 0.0, wd = 0.0;
    ev_->body_motion(y, p_cur, w, wd);
    for (int kk = 0; kk < np_; ++kk) {
        const auto& cp = pairs()[kk];
        if (cp.kind == PairKind::bonded) continue;
        if (nm[kk] == modes_.nmode[kk] && tm[kk] == modes_.tmode[kk] && cause != "start") continue;
        ContactEvent e;
        e.t_s = t_;
        e.pair = kk;
        const PairSpec& spec = sys_.pair_spec(kk);
        e.interface_index = spec.interface_index;
        e.x_m = spec.x_m;
        e.from = cause == "start" ? "none" : mode_label(cp, modes_.nmode[kk], modes_.tmode[kk]);
        e.to = mode_label(cp, nm[kk], tm[kk]);
        e.cause = cause;
        e.w_m = w;
        e.w_dot_m_per_s = wd;
        events_.push_back(std::move(e));
        if (cause != "start" && pair_chatter_limit_) note_pair_switch(kk, te);
    }
    enter(rel, nm, tm);
    if (ev_->settle_at_state() && stick_at_cones(p_cur, tm)) decided = false;  // p0 holds the anchors
    if (!decided) rebuild();
    ev_->after_event(cause, p_cur, ev_->forces(y));
    reset_check_anchors(y);
    stats_.event_time_s += seconds_since(t_start) - (stats_.contact_time_s - contact_before);
}

bool EventDriver::engage_clamps_by_slider_rate(const Vec& y, const Vec& rel, std::vector<signed char>& nm,
                                               std::vector<signed char>& tm) {
    // A clamp engages (released -> engaged) where its normal force falls through its preload
    // F_c: p_n is continuous there, so its friction limit mu (F_c - p_n) starts from 0 and cannot
    // stop a slide at once. It enters slip against its slider rate ds_t/dt (SLIP_POS: the rate
    // negative, the friction force positive) and sticks only where that rate is within the
    // motion margin (kMotionMargin V_ref): later, at the rate witness's root. Entered stuck, the
    // clamp's shear loads it past its preload at once (its release witness negative after the
    // next step) while released it falls back below: a loop at one instant (soak seed 29 under
    // cvode-modal, docs/decisions/071-soak-clamps-mesh-layer.md).
    std::vector<int> engaging;
    for (int kk = 0; kk < np_; ++kk) {
        const auto& cp = pairs()[kk];
        if (cp.kind != PairKind::clamp || cp.row_t < 0 || modes_.tmode[kk] != FREE || tm[kk] != STICK) continue;
        engaging.push_back(kk);
        tm[kk] = SLIP_POS;
    }
    if (engaging.empty()) return false;
    // The rate of each engaging clamp in the candidate modes at y: its SLIP_POS witness is
    // -rate / V_ref + kMotionMargin (witnesses_from).
    std::vector<double> g(slots_.size());
    in_candidate_modes(rel, nm, tm, true, [&] { ev_->witnesses(y, g.data()); });
    for (std::size_t i = 0; i < slots_.size(); ++i) {
        const int kk = slots_[i].pair;
        if (slots_[i].normal || std::find(engaging.begin(), engaging.end(), kk) == engaging.end()) continue;
        const double rate = kMotionMargin - g[i];  // ds_t/dt / V_ref
        tm[kk] = rate < -kMotionMargin ? SLIP_POS : rate > kMotionMargin ? SLIP_NEG : STICK;
    }
    return true;
}

void EventDriver::reset_check_anchors(const State& y) {
    d_chk_ = d_;
    if (n_ == 0 || !ev_) return;
    const Vec rel = ev_->relative(y);
    for (int kk = 0; kk < np_; ++kk) {
        const auto& cp = pairs()[kk];
        if (cp.row_t >= 0 && cp.kind != PairKind::bonded && modes_.tmode[kk] != STICK) d_chk_[cp.row_t] = rel[cp.row_t];
    }
}

/// True when the modes hold at y: every witness positive and the paper's incremental
/// problem (anchors d_chk) satisfied by the mode solution to the contact tolerance.
/// `residual` gets ||v|| (eq. 9).
bool EventDriver::modes_hold(const State& y, double& residual, bool* witnesses_ok) {
    std::vector<double> g(slots_.size());
    if (!slots_.empty()) ev_->witnesses(y, g.data());
    residual = 0.0;
    if (n_ > 0) {
        const Vec p = ev_->forces(y);
        chk_problem_.u = ev_->motion(y);
        chk_problem_.d = d_chk_;
        // s = (s + d) - d_chk, affine in the state: no product with the compliance
        residual = error_vector(chk_problem_, p, Vec(ev_->relative(y) - d_chk_)).norm();
    }
    const bool positive = std::all_of(g.begin(), g.end(), [](double v) { return v >= 0.0; });
    if (witnesses_ok) *witnesses_ok = positive;
    return positive && residual < opt_.solver.tolerance_m;
}

void EventDriver::restart(double te, const Vec& y) {
    const auto t0 = Clock::now();
    cvode_->y() = y;
    cvode_->reinit(te);
    ++stats_.restarts;
    stats_.event_time_s += seconds_since(t0);
}

bool EventDriver::cross_break_at(double te, const Vec& y) {
    if (next_break_ >= breaks_.size() || te < breaks_[next_break_]) return false;
    // the records up to te are out (the loading's left limit); past te the next piece
    Vec yb = y;
    cross_loading_break(te, yb);
    while (next_break_ < breaks_.size() && breaks_[next_break_] <= te) ++next_break_;
    if (ev_) {
        double residual = 0.0;
        if (!modes_hold(yb, residual)) {
            note_event_time(te);
            decide_modes(te, yb, ev_->forces(yb), "loading");
        }
        reset_check_anchors(yb);
    }
    cvode_->set_stop_time(stop_time());
    restart(te, yb);
    return true;
}

/// Queues the records of the output times in (t, upto] (the current modes hold there).
void EventDriver::emit_until(double upto) {
    long next = out_index_ + static_cast<long>(pending_.size()) + 1;
    while (next <= n_out_ && output_time(next) <= upto) {
        const double tau = output_time(next);
        cvode_->dense_output(tau);
        Output o;
        o.rec = record_at(tau, cvode_->ydky(), o.p, o.rel);
        o.y = cvode_->ydky();
        pending_.push_back(std::move(o));
        ++next;
    }
}

/// The per-step check of an accepted step at state y; true when the modes hold there.
bool EventDriver::step_keeps_modes(const Vec& y) {
    // The contact iteration at the accepted step (the configured solver; the paper's
    // projected iteration by default) on the paper's incremental problem, warm-started
    // at the mode solution. Its first act is its stop test, ||v|| < tolerance at the
    // warm start (modes_hold computes exactly that v): when it passes, the iteration
    // ends there with the mode solution as its answer. Otherwise it runs, and the
    // modes hold only if its answer leaves every pair in the mode CVODE integrated.
    const auto t_check = Clock::now();
    double residual = 0.0;
    bool witnesses_ok = false;
    bool ok = modes_hold(y, residual, &witnesses_ok);
    stats_.max_check_residual_m = std::max(stats_.max_check_residual_m, residual);
    last_check_residual_ = residual;
    if (!ok && witnesses_ok && n_ > 0) {
        const Vec pm = ev_->forces(y);
        Vec p = pm;
        const SolveResult res = chk_solver_->solve(chk_problem_, p);  // u, d set by modes_hold
        stats_.contact_iterations += res.iterations;
        iters_since_ += res.iterations;
        last_check_residual_ = res.residual_m;
        ok = res.converged;
        for (int kk = 0; kk < np_ && ok; ++kk)
            if (pair_state(chk_problem_, kk, p) != pair_state(chk_problem_, kk, pm)) ok = false;
        if (ok) stats_.max_check_force_difference_n = std::max(stats_.max_check_force_difference_n, (p - pm).lpNorm<Eigen::Infinity>());
    }
    stats_.contact_time_s += seconds_since(t_check);
    return ok;
}

/// One CVODE step and what follows it; returns false at the end of the run.
bool EventDriver::step_once() {
    if (t_ >= t_final_) return false;
    double tret = t_;
    const auto t_cv = Clock::now();
    // CVODE's tout matters only to its estimate of a first step (at most a tenth of the distance
    // to tout): with events, the run's end, so that a restart at an event just before an output
    // is not held to a tiny first step; without events (one start, no restart) the first output,
    // the horizon an output-to-output loop gives it (the held stepper's figures were made so).
    const double tout = ev_ ? t_final_ : output_time(out_index_ + 1);
    int flag = 0;
    try {
        flag = cvode_->advance(tout, CV_ONE_STEP, opt_.cvode.max_steps, tret);
    } catch (const SolverError& e) {
        if (cvode_->counters().steps <= opt_.cvode.max_steps) throw;
        throw SolverError(e.what() + step_limit_diagnostics(), e.step(), e.time_s(), e.residual());
    }
    stats_.cvode_time_s += seconds_since(t_cv);
    const CvodeCounters& cc = cvode_->counters();
    stats_.steps = cc.steps;
    stats_.rhs_evaluations = cc.rhs_evaluations;
    stats_.root_evaluations = cc.root_evaluations;
    const Vec y = cvode_->y();

    if (flag == CV_ROOT_RETURN) {
        emit_until(tret);  // the old modes hold up to the root
        t_ = tret;
        note_event_time(tret);
        std::vector<int> found(slots_.size(), 0);
        cvode_->root_info(found);
        decide_modes(tret, y, ev_->forces(y), "root", &found);
        if (!cross_break_at(tret, y)) restart(tret, y);
        return true;
    }

    // Without events (EventStart::events null) every accepted step keeps the modes.
    if (!ev_ || step_keeps_modes(y)) {
        emit_until(tret);
        t_ = tret;
        reset_check_anchors(y);
        cross_break_at(tret, y);
        return tret < t_final_;
    }

    // A missed event: locate its time by bisection on the dense output of the last step.
    const double hlast = cvode_->last_step();
    double lo = tret - hlast, hi = tret;
    const double tol_t = 1e-13 * std::max(1.0, std::abs(tret)) + 1e-9 * hlast;
    while (hi - lo > tol_t) {
        const double mid = 0.5 * (lo + hi);
        cvode_->dense_output(mid);
        double res_m = 0.0;
        if (modes_hold(cvode_->ydky(), res_m)) lo = mid;
        else hi = mid;
    }
    cvode_->dense_output(hi);
    const Vec ye = cvode_->ydky();
    emit_until(hi);
    t_ = hi;
    ++stats_.missed_events;
    note_event_time(hi);
    decide_modes(hi, ye, ev_->forces(ye), "check");
    if (!cross_break_at(hi, ye)) restart(hi, ye);
    return true;
}

/// The caller's stop check (SimulationOptions::stop_requested), polled every
/// kStopCheckSteps CVODE steps: RunStopped at the last accepted time.
void EventDriver::check_stop() {
    if (!opt_.stop_requested || stats_.steps - steps_at_stop_check_ < kStopCheckSteps) return;
    steps_at_stop_check_ = stats_.steps;
    if (opt_.stop_requested())
        throw RunStopped(who_ + ": stopped on request at t = " + format_value(t_) + " s after " +
                             std::to_string(stats_.steps) + " steps (the last output is at t = " +
                             format_value(record_.t_s) + " s)",
                         stats_.steps, t_);
}

const StepRecord& EventDriver::advance() {
    if (out_index_ >= n_out_) throw InputError("advance", "the run has reached t_end = " + format_value(t_final_) + " s");
    while (pending_.empty()) {
        check_stop();
        if (!step_once() && pending_.empty())
            throw SolverError(who_ + ": reached t = " + format_value(t_) + " s without the output at " +
                                  format_value(output_time(out_index_ + 1)) + " s",
                              stats_.steps, t_, 0.0);
    }
    record_ = std::move(pending_.front().rec);
    p_out_ = std::move(pending_.front().p);
    rel_out_ = std::move(pending_.front().rel);
    y_out_ = std::move(pending_.front().y);
    pending_.pop_front();
    ++out_index_;
    const CvodeCounters& cc = cvode_->counters();  // Newton's (0 with fixed point)
    stats_.jacobian_evaluations = cc.jacobian_evaluations;
    stats_.linear_setups = cc.linear_setups;
    return record_;
}

RunReport EventDriver::report() const { return event_report(stats_, events_); }

EventStepper::EventStepper(std::unique_ptr<EventDriver> driver) : driver_(std::move(driver)) {}
EventStepper::~EventStepper() = default;

const StepRecord& EventStepper::advance() { return driver_->advance(); }
const StepRecord& EventStepper::current() const noexcept { return driver_->current(); }
long EventStepper::record_index() const noexcept { return driver_->record_index(); }
std::vector<PairRecord> EventStepper::pairs() const { return driver_->pair_records(); }
std::vector<LeafNodes> EventStepper::nodes() const { return driver_->nodes_at_output(); }
Stresses EventStepper::stresses() const {
    return compute_stresses(driver_->system(), driver_->displacements_at_output(), pairs(), driver_->leaf_motion_at_output());
}
LeafMotion EventDriver::leaf_motion(double, const State&, const Vec&) const { return {}; }
RunReport EventStepper::report() const { return driver_->report(); }
const CvodeStats& EventStepper::stats() const noexcept { return driver_->stats(); }
const std::vector<ContactEvent>& EventStepper::events() const noexcept { return driver_->events(); }
const Eigen::VectorXd& EventStepper::contact_forces() const noexcept { return driver_->contact_forces(); }
const Eigen::VectorXd& EventStepper::relative_positions() const noexcept { return driver_->relative_positions(); }

}  // namespace stackbeam::detail
