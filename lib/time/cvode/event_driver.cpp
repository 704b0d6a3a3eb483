// The event driver of the event-driven cvode steppers (event_driver.hpp; the method in
// cvode_stepper.hpp).
#include "time/cvode/event_driver.hpp"
#include "fe/tied_shape.hpp"
#include "stackbeam/model/loading.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "model/mesh_note.hpp"
#include "stackbeam/errors.hpp"
#include "time/contact_state.hpp"
#include "time/cvode/cvode_testing.hpp"
#include "time/record.hpp"

namespace stackbeam::detail {

EventDriver::EventDriver(const System& system, const SimulationOptions& options, std::string who_)
    : sys(system),
      opt(options),
      who(std::move(who_)),
      n(system.num_components()),
      np(static_cast<int>(system.pairs().size())),
      ndof(system.num_reduced_dofs()),
      w_dof(system.num_reduced_dofs() - 1),
      f(system.model().whole_spring_factor()),
      m_body(system.model().spec().rigid_body.mass_kg),
      d(system.initial_offsets_m()),
      root_finding(cvode_testing().root_finding) {}

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
    rec.energy_balance_error_j = e0 + rec.external_work_j -
                                 (kinetic_j + rec.strain_energy_j + rec.dissipated_energy_j + rec.damping_energy_j);
}

void EventDriver::init_grid() {
    dt = opt.dt_s;
    n_out = static_cast<long>(std::ceil(opt.t_end_s / dt - 1e-9));
    t_final = static_cast<double>(n_out) * dt;
}

void EventDriver::init_slots() {
    for (int kk = 0; kk < np; ++kk) {
        const auto& cp = sys.pairs()[kk];
        if (cp.kind == PairKind::bonded) continue;
        const bool friction = cp.row_t >= 0 && cp.friction_coefficient > 0.0;
        if (cp.kind == PairKind::coulomb && cp.row_n >= 0) slots.push_back({kk, true});
        if (cp.kind == PairKind::clamp && friction && cp.row_n >= 0) slots.push_back({kk, true});
        if (friction && (cp.kind == PairKind::clamp || cp.row_n >= 0)) slots.push_back({kk, false});
    }
}

void EventDriver::init_problems(const Eigen::MatrixXd& W, double event_tolerance_m) {
    chk_problem.W = W;
    chk_problem.pairs = sys.pairs();
    chk_problem.tau_rule = TauRule::current;
    chk_problem.tau_previous_n = Vec::Zero(np);
    chk_problem.q = Vec::Zero(n);  // sized: ModeSet::linearize takes n from it
    ev_problem = chk_problem;
    chk_solver = make_solver(opt.solver);
    ev_tolerance = event_tolerance_m;
    ev_solver = make_solver(event_solver_options(opt.solver, ev_tolerance));
}

void EventDriver::start_cvode(CVRhsFn rhs, const StiffIntegrator* stiff) {
    cvode->create(stiff ? CV_BDF : CV_ADAMS, rhs, this, opt.cvode.rtol);
    if (stiff) {
        cvode->use_embedded_newton(stiff->psetup, stiff->psolve, this);
        cvode->set_max_order(stiff->max_order);
    } else {
        cvode->use_fixed_point();
    }
    cvode->set_limits(opt.cvode.max_step_s);
    cvode->set_stop_time(t_final);
    if (root_finding && !slots.empty()) cvode->set_roots(static_cast<int>(slots.size()), &EventDriver::roots);
}

int EventDriver::roots(sunrealtype, N_Vector y, sunrealtype* g, void* user) {
    const auto* self = static_cast<const EventDriver*>(user);
    self->witnesses(Eigen::Map<const Vec>(N_VGetArrayPointer(y), self->nstate), g);
    return 0;
}

StepRecord EventDriver::record_at(double tau, const State& y, Vec& p, Vec& rel) {
    StepRecord rec = make_record(tau, y, p, rel);
    rec.t_s = tau;
    rec.contact_iterations = static_cast<int>(iters_since);
    rec.factorizations = static_cast<int>(facts_since);
    rec.contact_residual_m = last_check_residual;
    iters_since = facts_since = 0;
    return rec;
}

void EventDriver::solve_initial_forces(const Vec& motion0, Vec& p) {
    ev_problem.q = motion0 - d;
    const SolveResult r0 = ev_solver->solve(ev_problem, p);
    if (!r0.converged) throw SolverError("initial contact state: " + r0.message, 0, 0.0, r0.residual_m);
}

void EventDriver::start_record(const Vec& y0) {
    record = record_at(0.0, y0, p_out, rel_out);
    y_out = y0;
    e0 = record.kinetic_energy_j + record.strain_energy_j;
    record.energy_balance_error_j = 0.0;
}

std::vector<PairRecord> EventDriver::pair_records_at(const Vec& rel) const {
    return pair_records(sys, chk_problem, p_out, rel);
}

void EventDriver::enter(const Vec& rel, const std::vector<signed char>& nm, const std::vector<signed char>& tm) {
    for (int kk = 0; kk < np; ++kk) {
        const auto& cp = pairs()[kk];
        if (cp.row_t >= 0 && cp.kind != PairKind::bonded && tm[kk] == STICK && tmode[kk] != STICK)
            d[cp.row_t] = rel[cp.row_t];
    }
    nmode = nm;
    tmode = tm;
}

void EventDriver::correct_decision(const State&, const Vec&, std::vector<signed char>&, std::vector<signed char>&) {}

bool EventDriver::settle_at_state() const { return false; }
bool EventDriver::settle_after_missed_event() const { return false; }

void EventDriver::in_candidate_modes(const Vec& rel, const std::vector<signed char>& nm,
                                     const std::vector<signed char>& tm, bool build, const std::function<void()>& body) {
    const Vec d_saved = d;
    const std::vector<signed char> nm_saved = nmode, tm_saved = tmode;
    enter(rel, nm, tm);
    if (build) build_mode();
    body();
    d = d_saved;
    nmode = nm_saved;
    tmode = tm_saved;
}

bool EventDriver::apply_slot_transitions(const std::function<bool(std::size_t)>& take, const Vec& p,
                                         std::vector<signed char>& nm, std::vector<signed char>& tm) const {
    bool any = false;
    for (std::size_t i = 0; i < slots.size(); ++i) {
        if (!take(i)) continue;
        const int kk = slots[i].pair;
        const auto& cp = pairs()[kk];
        apply_transition(cp, slots[i].normal, cp.row_t >= 0 ? p[cp.row_t] : 0.0, nm[kk], tm[kk]);
        any = true;
    }
    return any;
}

void EventDriver::signs_follow_slip_rates(const Vec& rel, std::vector<signed char>& nm, std::vector<signed char>& tm,
                                          const std::function<Vec()>& rate) {
    for (int pass = 0; pass < 3; ++pass) {
        bool changed = false;
        in_candidate_modes(rel, nm, tm, true, [&] {
            const Vec r = rate();
            for (int kk = 0; kk < np; ++kk) {
                const int rt = pairs()[kk].row_t;
                if (rt < 0) continue;
                if (tm[kk] == SLIP_POS && r[rt] > kMotionMargin * V_ref) { tm[kk] = SLIP_NEG; changed = true; }
                else if (tm[kk] == SLIP_NEG && r[rt] < -kMotionMargin * V_ref) { tm[kk] = SLIP_POS; changed = true; }
            }
        });
        if (!changed) break;
    }
}

void EventDriver::witnesses_from(const Vec& p, const std::function<double(int)>& s_of,
                                 const std::function<double(int)>& rate_of, double* g) const {
    for (std::size_t i = 0; i < slots.size(); ++i) {
        const int kk = slots[i].pair;
        const auto& cp = pairs()[kk];
        double val = 1.0, margin = kForceMargin;
        if (slots[i].normal) {
            const double pn = p[cp.row_n];
            if (cp.kind == PairKind::coulomb) {
                if (nmode[kk] == CLOSED) {
                    val = -pn / F_ref;
                } else {
                    val = -s_of(cp.row_n) / L_ref;
                    margin = gap_margin;
                }
            } else {
                val = tmode[kk] == FREE ? (pn - cp.preload_n) / F_ref : (cp.preload_n - pn) / F_ref;
            }
        } else {
            const int rt = cp.row_t;
            switch (tmode[kk]) {
                case STICK:
                    val = (cp.friction_coefficient * friction_normal_force(chk_problem, kk, p) - std::abs(p[rt])) / F_ref;
                    break;
                case SLIP_POS: val = -rate_of(rt) / V_ref; margin = kMotionMargin; break;
                case SLIP_NEG: val = rate_of(rt) / V_ref; margin = kMotionMargin; break;
                default: val = 1.0; break;
            }
        }
        g[i] = val + margin;
    }
}

void EventDriver::book_force_jump(const std::string& cause, double loss, const Vec& p_cur, const Vec& p_new) {
    if (cause == "start") return;
    jump_dissipation += loss;
    stats.min_jump_dissipation_j = std::min(stats.min_jump_dissipation_j, loss);
    stats.max_force_jump_n = std::max(stats.max_force_jump_n, (p_new - p_cur).lpNorm<Eigen::Infinity>());
}

void EventDriver::decide_modes(double te, const Vec& y, const Vec& p_cur, const std::string& cause,
                               const std::vector<int>* triggered) {
    const auto t_start = Clock::now();
    const double contact_before = stats.contact_time_s;
    const Vec rel = relative_at_event(y, p_cur);  // s + d
    // Incremental problem a look-ahead away: stuck pairs keep their anchors, every
    // other pair is anchored where it is (paper, section 5).
    const Vec y_la = look_ahead(te, y, p_cur);
    Vec d_la = d;
    for (int kk = 0; kk < np; ++kk) {
        const auto& cp = pairs()[kk];
        if (cp.row_t >= 0 && cp.kind != PairKind::bonded && tmode[kk] != STICK) d_la[cp.row_t] = rel[cp.row_t];
    }
    ev_problem.q = motion(y_la) - d_la;

    std::vector<signed char> nm, tm;
    bool decided = false;
    if (triggered != nullptr && n > 0) {
        nm = nmode;
        tm = tmode;
        apply_slot_transitions([&](std::size_t i) { return (*triggered)[i] != 0; }, p_cur, nm, tm);
        // restored either way: the log below compares with the old modes
        in_candidate_modes(rel, nm, tm, true, [&] {
            // the stop test of the contact iteration at the look-ahead, and every witness
            const Vec pl = forces(y_la);
            const double v = error_vector(ev_problem, pl, Vec(relative(y_la) - d_la)).norm();
            std::vector<double> g(slots.size());
            if (!slots.empty()) witnesses(y_la, g.data());
            decided = v < ev_tolerance && std::all_of(g.begin(), g.end(), [](double x) { return x >= 0.0; });
        });
        ++stats.contact_iterations;
        ++iters_since;
    }
    // The modes of the exact solution of ev_problem (its q set), slip signs corrected.
    const auto decide_by_solving = [&](const std::string& where) {
        Vec p_sol = p_cur;
        const auto t_solve = Clock::now();
        const SolveResult res = ev_solver->solve(ev_problem, p_sol);
        stats.contact_time_s += seconds_since(t_solve);
        stats.contact_iterations += res.iterations;
        iters_since += res.iterations;
        if (!res.converged)
            throw SolverError(who + ": the contact iteration " + where + " at t = " + format_value(t) + " s (" + cause +
                                  ") did not converge: " + res.message + mesh_note(sys.model()),
                              stats.steps, t, res.residual_m);
        modes_from_solution(chk_problem, p_sol, 1e-12 * F_ref, nm, tm);
        correct_decision(y, rel, nm, tm);
    };
    if (!decided) decide_by_solving("deciding the modes");

    // A stepper whose state decides every pair by itself (settle_at_state: the massive stack,
    // where only the layer is instantaneous) restarts only in modes that hold at y itself: a
    // witness the decided modes leave negative at y (a pair the look-ahead keeps closed that is
    // still in tension at y, its gap closing within the look-ahead) takes its transition, so
    // that root-finding, not the per-step check, finds the next one. Each such transition makes
    // its witness positive at y (closed in tension -> open with the gap c p; penetrating ->
    // closed in compression; over the cone -> slipping; a reversing slip -> sticking at its force).
    // The modal stepper does this only at a missed event (settle_after_missed_event): there the
    // look-ahead's decision can leave a witness negative at y (a force grazing its cone, back
    // inside a look-ahead later), and root-finding, seeing no sign change, would never leave it.
    if ((settle_at_state() || (settle_after_missed_event() && cause == "check")) && !slots.empty()) {
        std::vector<double> g(slots.size());
        for (int pass = 0; pass < kSettlePasses; ++pass) {
            bool changed = false;
            in_candidate_modes(rel, nm, tm, pass > 0 || !decided, [&] {
                witnesses(y, g.data());
                changed = apply_slot_transitions([&](std::size_t i) { return g[i] < 0.0; }, forces(y), nm, tm);
            });
            decided = true;  // the factorisation is of (nm, tm)
            if (!changed) break;
            decided = false;  // (nm, tm) changed after the last factorisation
            ++stats.settled_transitions;
        }
        // Not settled in kSettlePasses (a coupled contact layer, the modal stepper's W = G R G^T:
        // one pair's transition moves the others' forces): the modes of the contact problem at y
        // itself (stuck pairs at their anchors, the others anchored where they are), which hold
        // at y by construction, slip signs from the rates as after the look-ahead's decision.
        if (!decided) {
            bool holds = false;
            in_candidate_modes(rel, nm, tm, true, [&] {
                witnesses(y, g.data());
                holds = std::all_of(g.begin(), g.end(), [](double x) { return x >= 0.0; });
            });
            decided = true;
            if (!holds) {
                ev_problem.q = motion(y) - d_la;  // the anchors of the look-ahead's problem, at y
                decide_by_solving("at the state");
                decided = false;
                ++stats.settled_transitions;
            }
        }
    }

    // Log the transitions, enter the new modes, refactorise (unless the candidate was).
    double w = 0.0, wd = 0.0;
    body_motion(y, p_cur, w, wd);
    for (int kk = 0; kk < np; ++kk) {
        const auto& cp = pairs()[kk];
        if (cp.kind == PairKind::bonded) continue;
        if (nm[kk] == nmode[kk] && tm[kk] == tmode[kk] && cause != "start") continue;
        ContactEvent e;
        e.t_s = t;
        e.pair = kk;
        const PairSpec& spec = sys.pair_spec(kk);
        e.interface_index = spec.interface_index;
        e.x_m = spec.x_m;
        e.from = cause == "start" ? "none" : mode_label(cp, nmode[kk], tmode[kk]);
        e.to = mode_label(cp, nm[kk], tm[kk]);
        e.cause = cause;
        e.w_m = w;
        e.w_dot_m_per_s = wd;
        events.push_back(std::move(e));
    }
    enter(rel, nm, tm);
    if (!decided) build_mode();
    after_event(cause, p_cur, forces(y));
    reset_check_anchors(y);
    stats.event_time_s += seconds_since(t_start) - (stats.contact_time_s - contact_before);
}

void EventDriver::reset_check_anchors(const State& y) {
    d_chk = d;
    if (n == 0) return;
    const Vec rel = relative(y);
    for (int kk = 0; kk < np; ++kk) {
        const auto& cp = pairs()[kk];
        if (cp.row_t >= 0 && cp.kind != PairKind::bonded && tmode[kk] != STICK) d_chk[cp.row_t] = rel[cp.row_t];
    }
}

/// True when the modes hold at y: every witness positive and the paper's incremental
/// problem (anchors d_chk) satisfied by the mode solution to the contact tolerance.
/// `residual` gets ||v|| (eq. 9).
bool EventDriver::modes_hold(const State& y, double& residual, bool* witnesses_ok) {
    std::vector<double> g(slots.size());
    if (!slots.empty()) witnesses(y, g.data());
    residual = 0.0;
    if (n > 0) {
        const Vec p = forces(y);
        chk_problem.q = motion(y) - d_chk;
        // s = (s + d) - d_chk, affine in the state: no product with the compliance
        residual = error_vector(chk_problem, p, Vec(relative(y) - d_chk)).norm();
    }
    const bool positive = std::all_of(g.begin(), g.end(), [](double v) { return v >= 0.0; });
    if (witnesses_ok) *witnesses_ok = positive;
    return positive && residual < opt.solver.tolerance_m;
}

void EventDriver::restart(double te, const Vec& y) {
    const auto t0 = Clock::now();
    cvode->y() = y;
    cvode->reinit(te);
    ++stats.restarts;
    stats.event_time_s += seconds_since(t0);
}

/// Queues the records of the output times in (t, upto] (the current modes hold there).
void EventDriver::emit_until(double upto) {
    long next = out_index + static_cast<long>(pending.size()) + 1;
    while (next <= n_out && output_time(next) <= upto) {
        const double tau = output_time(next);
        cvode->dense_output(tau);
        Output o;
        o.rec = record_at(tau, cvode->ydky(), o.p, o.rel);
        o.y = cvode->ydky();
        pending.push_back(std::move(o));
        ++next;
    }
}

void EventDriver::note_event_time(double te) {
    if (te == last_event_t) {
        if (++events_at_this_time > kMaxEventsAtOneTime)
            throw SolverError(who + ": more than " + std::to_string(kMaxEventsAtOneTime) + " events at t = " +
                                  format_value(te) + " s: the contact modes chatter (no consistent mode set found)",
                              stats.steps, te, 0.0);
    } else {
        last_event_t = te;
        events_at_this_time = 0;
    }
    ++stats.events;
}

/// One CVODE step and what follows it; returns false at the end of the run.
bool EventDriver::step_once() {
    if (t >= t_final) return false;
    double tret = t;
    const auto t_cv = Clock::now();
    const int flag = cvode->advance(t_final, CV_ONE_STEP, opt.cvode.max_steps, tret);
    stats.cvode_time_s += seconds_since(t_cv);
    const CvodeCounters& cc = cvode->counters();
    stats.steps = cc.steps;
    stats.rhs_evaluations = cc.rhs_evaluations;
    stats.root_evaluations = cc.root_evaluations;
    const Vec y = cvode->y();

    if (flag == CV_ROOT_RETURN) {
        emit_until(tret);  // the old modes hold up to the root
        t = tret;
        note_event_time(tret);
        std::vector<int> found(slots.size(), 0);
        cvode->root_info(found);
        decide_modes(tret, y, forces(y), "root", &found);
        restart(tret, y);
        return true;
    }

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
    stats.max_check_residual_m = std::max(stats.max_check_residual_m, residual);
    last_check_residual = residual;
    if (!ok && witnesses_ok && n > 0) {
        const Vec pm = forces(y);
        Vec p = pm;
        const SolveResult res = chk_solver->solve(chk_problem, p);  // q was set by modes_hold
        stats.contact_iterations += res.iterations;
        iters_since += res.iterations;
        last_check_residual = res.residual_m;
        ok = res.converged;
        for (int kk = 0; kk < np && ok; ++kk)
            if (pair_state(chk_problem, kk, p) != pair_state(chk_problem, kk, pm)) ok = false;
        if (ok) stats.max_check_force_difference_n = std::max(stats.max_check_force_difference_n, (p - pm).lpNorm<Eigen::Infinity>());
    }
    stats.contact_time_s += seconds_since(t_check);
    if (ok) {
        emit_until(tret);
        t = tret;
        reset_check_anchors(y);
        return tret < t_final;
    }

    // A missed event: locate its time by bisection on the dense output of the last step.
    const double hlast = cvode->last_step();
    double lo = tret - hlast, hi = tret;
    const double tol_t = 1e-13 * std::max(1.0, std::abs(tret)) + 1e-9 * hlast;
    while (hi - lo > tol_t) {
        const double mid = 0.5 * (lo + hi);
        cvode->dense_output(mid);
        double res_m = 0.0;
        if (modes_hold(cvode->ydky(), res_m)) lo = mid;
        else hi = mid;
    }
    cvode->dense_output(hi);
    const Vec ye = cvode->ydky();
    emit_until(hi);
    t = hi;
    ++stats.missed_events;
    note_event_time(hi);
    decide_modes(hi, ye, forces(ye), "check");
    restart(hi, ye);
    return true;
}

const StepRecord& EventDriver::advance() {
    if (out_index >= n_out) throw InputError("advance", "the run has reached t_end = " + format_value(t_final) + " s");
    while (pending.empty()) {
        if (!step_once() && pending.empty())
            throw SolverError(who + ": reached t = " + format_value(t) + " s without the output at " +
                                  format_value(output_time(out_index + 1)) + " s",
                              stats.steps, t, 0.0);
    }
    record = std::move(pending.front().rec);
    p_out = std::move(pending.front().p);
    rel_out = std::move(pending.front().rel);
    y_out = std::move(pending.front().y);
    pending.pop_front();
    ++out_index;
    return record;
}

EventStepper::EventStepper(std::unique_ptr<EventDriver> driver) : driver_(std::move(driver)) {}
EventStepper::~EventStepper() = default;

const StepRecord& EventStepper::advance() {
    const StepRecord& r = driver_->advance();
    const CvodeCounters& cc = driver_->cvode->counters();  // Newton's (0 with fixed point)
    driver_->stats.jacobian_evaluations = cc.jacobian_evaluations;
    driver_->stats.linear_setups = cc.linear_setups;
    return r;
}
const StepRecord& EventStepper::current() const noexcept { return driver_->current(); }
long EventStepper::record_index() const noexcept { return driver_->record_index(); }
std::vector<PairRecord> EventStepper::pairs() const { return driver_->pair_records_at(driver_->rel_out); }
std::vector<LeafNodes> EventStepper::nodes() const { return driver_->nodes_at_output(); }
RunReport EventStepper::report() const { return driver_->report(); }
const CvodeStats& EventStepper::stats() const noexcept { return driver_->stats; }
const std::vector<ContactEvent>& EventStepper::events() const noexcept { return driver_->events; }
const Eigen::VectorXd& EventStepper::contact_forces() const noexcept { return driver_->p_out; }
const Eigen::VectorXd& EventStepper::relative_positions() const noexcept { return driver_->rel_out; }

}  // namespace stackbeam::detail
