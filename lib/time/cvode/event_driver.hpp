#pragma once
// Internal: the one driver of every cvode stepper (cvode_stepper.hpp for the method;
// docs/decisions/029-event-driver-hooks.md, 033-held-stepper-in-the-driver.md): CVODE
// between contact events with root-finding on the witnesses (decreasing crossings), the
// contact iteration deciding the modes at an event on the look-ahead problem, the per-step
// check of every accepted step, bisection of a missed event on CVODE's dense output, restarts
// (CVodeReInit), the event log, the records on the dt grid and the caller's stop check
// (SimulationOptions::stop_requested).
//
// As Drake's IntegratorBase and its DoStep: the driver owns every piece of run state privately
// (CVODE's memory, the modes and anchors, the contact problems and solvers, the pending
// records, the clocks and counters). A stepper derives from it, builds its operators in its
// constructor, hands the driver one EventStart value (start()) and implements the fixed hooks
// below (the ODE's; those of the contact events in ContactEventHooks, which a stepper whose
// pairs never change mode leaves out), which read the driver's state through const accessors
// and never write it:
//  - the massless stepper (cvode_stepper.cpp): y = [w, w', D (, W_e)], the contact
//    problem driven by R's displacement, s = C'p + c w - d;
//  - the modal one with leaf inertia (cvode_modal.cpp): y = [q, q', D (, X, t)], driven by
//    the retained modes, s = W p + G Phi q (+ Hq u(t)) - d;
//  - the massive stack (cvode_massive.cpp): y = [z, z', D, D_c, W], s = G z + C_L p - d;
//  - the held stack (cvode_held.cpp): y = the held stack's modes in energy-norm coordinates,
//    every pair held for good: no event hooks, SUNDIALS' band solver (NewtonSolver::band).
#include <Eigen/Dense>
#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "stackbeam/contact/modes.hpp"
#include "stackbeam/contact/contact.hpp"
#include "stackbeam/errors.hpp"
#include "stackbeam/fe/system.hpp"
#include "stackbeam/time/run_report.hpp"
#include "stackbeam/time/stepper.hpp"
#include "time/cvode/cvode_modes.hpp"
#include "time/cvode/sundials.hpp"
#include "time/initial_state.hpp"

namespace stackbeam::detail {

/// The scales that make every witness of order one (cvode_stepper.hpp: g = -p_n / F_ref,
/// -s_n / L_ref, -sigma ds_t/dt / V_ref, ...), one formula for every event stepper (event_scales).
struct EventScales {
    double L_ref_m = 1e-3;         ///< displacement scale [m]
    double V_ref_m_per_s = 1.0;    ///< velocity scale omega L_ref [m/s]
    double F_ref_n = 1.0;          ///< contact force scale [N, meshed part]
    double omega_rad_per_s = 1.0;  ///< the frequency of V_ref [rad/s]
};

/// What the one witness-scale formula (event_scales) takes from a stepper.
struct ScaleInputs {
    double stiffness_n_per_m = 1.0;           ///< k of F_ref [N/m, meshed part]
    double omega_rad_per_s = 1.0;             ///< omega of V_ref [rad/s]
    double omega_amplitude_rad_per_s = 1.0;   ///< omega turning R's initial velocity into an amplitude [rad/s]
    double w0_m = 0.0, wd0_m_per_s = 0.0;     ///< R's initial displacement [m] and velocity [m/s]
    double deflection_m = 0.0;                ///< the loading's static deflection F_max / k [m]
    double motion_max_m = 0.0;                ///< the base's or the rig's largest displacement [m]
};

/// The witness scales, one formula for every event stepper:
///   L_ref = |w(0)| + |w'(0)| / omega_amplitude + F_max / k + y_max      [m]   (1e-3 m when 0: nothing moves)
///   V_ref = omega L_ref                                                 [m/s]
///   F_ref = max(largest clamp preload [N], k L_ref)                     [N, meshed part]
/// The massless stepper (cvode_stepper.cpp) takes k = max(k_tied, k_free), omega = sqrt(k / m),
/// omega_amplitude = sqrt(k_free / m), F_max the largest external force on R over the run;
/// the steppers with leaf mass take leaf_mass_scale_inputs.
EventScales event_scales(const System& system, const ScaleInputs& in);
/// The inputs of the steppers with leaf mass (modal, massive): k and omega of the tied stack
/// (k = System::tied_stiffness_n_per_m / f, omega = sqrt(k_tied / m_R)), the body's w(0), w'(0),
/// F_max = the applied force's largest value + the weight of every mass (System::vertical_inertia_kg),
/// y_max = the base's or the rig's largest displacement.
ScaleInputs leaf_mass_scale_inputs(const System& system, const Loading& loading);
/// The largest |F(t)| of a time function (mean + amplitude, table values) [its unit].
double largest_value(const TimeFunction& F);

/// The driver's and the hooks' vector types (one declaration, so a stepper deriving from both
/// names them unambiguously).
struct EventTypes {
    using Vec = Eigen::VectorXd;
    using State = Eigen::Ref<const Eigen::VectorXd>;
};

/// The hooks of a stepper whose contact modes change at events (EventStart::events): the
/// contact side of the modes, the witnesses and the decisions at an event. A stepper whose
/// pairs keep their modes for the whole run (every pair held in its operators) has none: it
/// leaves EventStart::events null and the driver integrates its ODE without witnesses, per-step
/// contact check or mode decisions. The hooks read the driver's state through its const
/// accessors (the stepper derives from both) and never write it.
class ContactEventHooks : public EventTypes {
public:
    virtual ~ContactEventHooks() = default;

    /// Builds the current modes' operators from their linearisation (ModeSet::linearize of the
    /// laws: held rows S, p = T p_S + e). The driver counts the factorisation.
    virtual void build_mode(const ModeLinearization& lin) = 0;
    /// Contact forces p [N] of the current modes at state y.
    virtual Vec forces(const State& y) const = 0;
    /// s + d [m] of the current modes at y (affine in the state).
    virtual Vec relative(const State& y) const = 0;
    /// s + d [m] at an event from the forces p_cur (before the modes are decided).
    virtual Vec relative_at_event(const State& y, const Vec& p_cur) const = 0;
    /// The motion's part of s + d: c w, G Phi q, G z [m].
    virtual Vec motion(const State& y) const = 0;
    /// Witness functions at y, positive while the modes hold.
    virtual void witnesses(const State& y, double* g) const = 0;
    /// The state a short look-ahead after (te, y): the contact points move by ~kLookahead L_ref.
    virtual Vec look_ahead(double te, const State& y, const Vec& p_cur) const = 0;
    /// R's displacement and velocity at y (for the event log).
    virtual void body_motion(const State& y, const Vec& p_cur, double& w, double& wd) const = 0;
    /// After the exact solver's decision (nm, tm) at y (rel: s + d there): corrections of
    /// the stepper (default none).
    virtual void correct_decision(const State& y, const Vec& rel, std::vector<signed char>& nm,
                                  std::vector<signed char>& tm);
    /// True when the state y alone decides every pair's modes (no instantaneous coupling but
    /// the diagonal layer): decide_modes then makes every witness hold at y (default false).
    virtual bool settle_at_state() const;
    /// The compliance c_i [m/N] of contact row i's own layer where the stepper's forces of held rows
    /// are p_i = (d_i - G_i z) / c_i (a diagonal layer: settle_at_state), else 0 (default): a pair
    /// that sticks at an event with its force past its cone then sticks at the cone (decide_modes).
    virtual double own_layer_compliance_m_per_n(int row) const;
    /// The new modes entered with forces p_new (p_cur before): the stepper's bookkeeping of the jump.
    virtual void after_event(const std::string& cause, const Vec& p_cur, const Vec& p_new) = 0;
};

/// How CVODE's Newton iteration solves its linear systems (EventStart::newton).
enum class NewtonSolver {
    stepper,  ///< the stepper's newton_setup / newton_solve (a matrix-embedded linear solver)
    band,     ///< SUNDIALS' band direct solver on the stepper's band_jacobian
};

/// What a stepper hands the driver once its operators are built (EventDriver::start).
struct EventStart {
    int nstate = 0;                      ///< CVODE's state size
    Eigen::VectorXd y0;                  ///< the state at t = 0 (nstate entries)
    EventScales scales;
    Eigen::MatrixXd compliance;          ///< the instantaneous compliance W of the contact problem [m/N]
    double event_tolerance_m = 0.0;      ///< the event decisions' tolerance on ||v|| [m]
    double gap_margin = kMotionMargin;   ///< margin of the gap witnesses (relative to L_ref)
    /// true: the forces at t = 0 are re-solved from the stage's (event solver, at the motion of
    /// y0) and the modes built before they are decided; false: the stage's forces are those at y0.
    bool resolve_initial_forces = true;
    /// The stepper's event hooks (a stepper deriving from ContactEventHooks: `this`); null: every
    /// pair keeps the set-up stage's mode for the whole run, held in the stepper's operators, so
    /// there are zero witness functions, no per-step contact check, no mode decisions and no
    /// events; the records' contact residual is then the stepper's own (make_record).
    ContactEventHooks* events = nullptr;
    int stiff_max_order = 0;             ///< 0: Adams with fixed point; else BDF to this order with Newton
    NewtonSolver newton = NewtonSolver::stepper;  ///< BDF's linear solver
    int band_upper = 0, band_lower = 0;  ///< the band solver's half-bandwidths (NewtonSolver::band)
    /// The loading's breaks in (0, t_end) [s], sorted: times where the right-hand side is not smooth
    /// (a table's points). CVODE stops at each (its stop time) and restarts past it after
    /// cross_loading_break; the contact modes are decided again there when they do not hold.
    std::vector<double> loading_breaks_s;
    /// The per-pair chatter limit (kMaxPairSwitches): the massive stack, whose contact points carry
    /// mass and vibrate on the elastic layer. Not the massless-layer steppers: near rest a pair
    /// of theirs switches at every small turning point (paper_friction at 20x: 100 switches of
    /// pair 22 within 8.5e-5 s at t = 22.3 s, a healthy run).
    bool pair_chatter_limit = false;
    int retained_modes = 0;              ///< CvodeStats (modal stepper)
    double modal_cutoff_rad_per_s = 0.0; ///< CvodeStats (modal stepper)
};

class EventDriver : public EventTypes {
public:
    virtual ~EventDriver();
    EventDriver(const EventDriver&) = delete;
    EventDriver& operator=(const EventDriver&) = delete;

    /// The record of the next output time (Stepper::advance()). Throws SolverError on a
    /// failure, RunStopped when the options' stop check asks for it.
    const StepRecord& advance();
    const StepRecord& current() const noexcept { return record_; }
    long record_index() const noexcept { return out_index_; }
    long num_outputs() const noexcept { return n_out_; }
    /// The pairs at the current output from its forces and relative positions (rel: s + d, all rows).
    std::vector<PairRecord> pair_records_at(const Vec& rel) const;
    /// The pairs at the current output with the relative positions of its record.
    std::vector<PairRecord> pair_records() const { return pair_records_at(rel_out_); }
    /// Every leaf's nodes at the current output (Stepper::nodes()): displacements() at its state.
    std::vector<LeafNodes> nodes_at_output() const { return sys_.leaf_nodes(displacements_at_output()); }
    /// z at the current output (displacements() at its state): Stepper::nodes() and stresses().
    Vec displacements_at_output() const { return displacements(y_out_, p_out_); }
    /// The leaves' motion at the current output for their distributed loads (Stepper::stresses()).
    LeafMotion leaf_motion_at_output() const { return leaf_motion(record_.t_s, y_out_, p_out_); }
    RunReport report() const;
    const CvodeStats& stats() const noexcept { return stats_; }
    const std::vector<ContactEvent>& events() const noexcept { return events_; }
    /// Contact forces p [N] (all rows) and relative positions s + d [m] at the current output.
    const Vec& contact_forces() const noexcept { return p_out_; }
    const Vec& relative_positions() const noexcept { return rel_out_; }
    const System& system() const noexcept { return sys_; }

protected:
    /// `who` prefixes the messages ("cvode mode", "cvode mode (leaf inertia)").
    EventDriver(const System& system, const SimulationOptions& options, std::string who);
    /// Starts the run (once, at the end of the stepper's constructor): the grid, the contact
    /// problems on `s.compliance`, the anchors of the set-up stage, CVODE on s.y0; with event
    /// hooks (s.events) the witness slots, the contact solvers and the initial modes decided a
    /// look-ahead on (cause "start"); then started() and tolerances(), the record at t = 0.
    void start(const InitialState& stage, const EventStart& s);

    // ---- what the hooks read ------------------------------------------------------------
    const SimulationOptions& options() const noexcept { return opt_; }
    const std::string& who() const noexcept { return who_; }
    int rows() const noexcept { return n_; }          ///< contact rows
    int num_pairs() const noexcept { return np_; }
    int ndof() const noexcept { return ndof_; }       ///< reduced DOFs (System::num_reduced_dofs)
    int w_dof() const noexcept { return ndof_ - 1; }  ///< R's DOF (the last)
    double spring_factor() const noexcept { return f_; }  ///< whole-spring factor (System's model)
    double body_mass_kg() const noexcept { return m_body_; }  ///< R's mass, whole spring [kg]
    int nstate() const noexcept { return nstate_; }
    const EventScales& scales() const noexcept { return scales_; }
    const ModeSet& modes() const noexcept { return modes_; }
    /// Gaps (normal rows) and anchors (tangential rows) [m] of the current modes.
    const Vec& anchors() const noexcept { return d_; }
    /// The pairs and their laws (tau rule current), the check problem's W.
    const ContactLaws& laws() const noexcept { return chk_problem_; }
    const std::vector<ContactPair>& pairs() const { return chk_problem_.pairs; }
    double time() const noexcept { return t_; }        ///< the last accepted time [s]
    long steps() const noexcept { return stats_.steps; }
    double initial_energy_j() const noexcept { return e0_; }
    double jump_dissipation_j() const noexcept { return jump_dissipation_; }  ///< [J, whole spring]
    /// A SolverError "<who>: <what> at t = .. s" at the current time and step.
    SolverError failure(const std::string& what) const;

    // ---- helpers the hooks may call -----------------------------------------------------
    /// Completes a record of a stepper with leaf inertia: the kinetic energy [J] of the leaves
    /// and R (the leaves' share apart), m w'' [N], the damping energy [J] and the balance
    /// with the record's external work, strain energy and dissipation.
    void finish_inertia_record(StepRecord& rec, double kinetic_j, double force_on_mass_n,
                               double damping_energy_j = 0.0) const;
    /// The witnesses of the steppers whose modes give the forces `p` [N], the relative position
    /// s [m] of a normal row (`s_of(row)`, > 0 interpenetration) and the slider rate ds/dt [m/s]
    /// of a tangential row (`rate_of(row)`): a closed pair's compression, an open pair's gap, a
    /// clamp's release or engagement, a sticking pair's margin to the cone, a slipping pair's
    /// rate against its force; each positive while its modes hold, with its margin.
    /// `force_round_off` (optional, per row [N]): the round-off of each row's force; a sticking
    /// pair's margin is then at least that of its force and of mu times its normal force's
    /// (the massive stack on a stiff layer, decision 074).
    void witnesses_from(const Vec& p, const std::function<double(int)>& s_of, const std::function<double(int)>& rate_of,
                        double* g, const Vec* force_round_off = nullptr) const;
    /// The round-off [N] of pair kk's stick margin mu tau - |p_t| from each row's force round-off
    /// `force_round_off` [N]: its tangential row's, plus mu times its normal row's.
    double stick_round_off_n(int kk, const Vec& force_round_off) const;
    /// For correct_decision of the steppers with slipping pairs of their own rate: a slipping
    /// pair slips against its slider rate; where the new modes' rate (`rate`, evaluated on the
    /// candidate modes after build_mode) contradicts the decided sign beyond the margin (a
    /// rate the look-ahead's motion is too short to resolve), the sign follows the rate.
    /// `cone_side` (optional, per pair: +1 / -1 where the pair's force at the event's state is
    /// at the positive / negative edge of its cone, 0 inside): a pair whose contradicted slip
    /// has the sign of the edge it is at sticks instead (its slip would stop at once, and its
    /// stick force moves into the cone: the massive stack, decision 074).
    /// At most three passes; the current modes and anchors are left as they were.
    void signs_follow_slip_rates(const Vec& rel, std::vector<signed char>& nm, std::vector<signed char>& tm,
                                 const std::function<Vec()>& rate, const std::vector<signed char>* cone_side = nullptr);
    /// Books a force jump at an event (a slip that reverses where sticking is not admissible)
    /// that released `loss` [J, whole spring] of the contact layer's energy: friction work.
    void book_force_jump(const std::string& cause, double loss, const Vec& p_cur, const Vec& p_new);
    /// Notes the largest force jump at an event [N] without booking energy (the massless layer).
    void note_force_jump(const Vec& p_cur, const Vec& p_new);

    // ---- the hooks of every stepper: the ODE between events and its records ------------
    /// CVODE's right-hand side y' = f(t, y) of the current modes (nstate entries each).
    virtual void derivatives(double t_s, const double* y, double* ydot) const = 0;
    /// Stiff steppers (EventStart::stiff_max_order > 0) that solve CVODE's Newton systems
    /// themselves (EventStart::newton == NewtonSolver::stepper): factorise the Newton matrix at
    /// gamma (0 ok, > 0 recoverable) and solve it for r into x (CvodeSession::use_embedded_newton).
    virtual int newton_setup(double gamma);
    virtual int newton_solve(double t_s, const double* y, const double* r, double* x, double gamma) const;
    /// Stiff steppers with SUNDIALS' band direct solver (EventStart::newton == NewtonSolver::band):
    /// the Jacobian df/dy at (t, y) into J, zero on entry, within the half-bandwidths of
    /// EventStart (0 ok, > 0 recoverable).
    virtual int band_jacobian(double t_s, const State& y, BandMatrixView J) const;
    /// Once the initial modes are decided, before the first record (default nothing).
    virtual void started(const State& y0);
    /// CVODE stopped at the loading's break t_s (EventStart::loading_breaks_s) in state y, the
    /// loading's left limit: the stepper enters the next piece of its loading and books in y what
    /// jumps there (default nothing).
    virtual void cross_loading_break(double t_s, Vec& y);
    /// CVODE's absolute tolerances at the initial state y0 into atol (nstate entries).
    virtual void tolerances(const State& y0, Eigen::Ref<Vec> atol) const = 0;
    /// The record at time tau of state y, with the forces p and (optional) relative positions rel;
    /// the driver sets t, the counters and the residual.
    virtual StepRecord make_record(double tau, const State& y, Vec& p, Vec& rel) const = 0;
    /// The reduced displacements z = [z_r; w] [m, rad] at state y with the forces p [N] of its
    /// record (System::leaf_nodes makes the nodes of them).
    virtual Vec displacements(const State& y, const Vec& p) const = 0;
    /// The leaves' accelerations z'' (relative to the supports), velocities (damped) and the frame's
    /// acceleration g + y_b'' at time t_s, state y with the forces p of its record, such that
    /// M z'' + C z' + K z = G^T p + e_w F - (g + y_b'') l holds on the leaves' DOFs (compute_stresses
    /// takes the elements' distributed loads off with them; decision 061). Default: none.
    virtual LeafMotion leaf_motion(double t_s, const State& y, const Vec& p) const;

private:
    using Clock = std::chrono::steady_clock;
    static double seconds_since(Clock::time_point t0);
    struct Slot { int pair; bool normal; };
    struct Output { StepRecord rec; Vec p, rel, y; };

    const System& sys_;
    SimulationOptions opt_;
    std::string who_;
    int n_ = 0, np_ = 0, ndof_ = 0;  // contact rows, pairs, reduced DOFs
    double f_ = 1.0, m_body_ = 0.0;
    int nstate_ = 0;
    EventScales scales_;
    ContactEventHooks* ev_ = nullptr;  // EventStart::events (null: no events)
    double gap_margin_ = kMotionMargin;
    ModeSet modes_;
    Vec d_, d_chk_;                // anchors of the modes and of the per-step check [m]
    std::vector<Slot> slots_;      // one witness per possible transition
    // the check's and the events' problems on one dense operator (W; u = the motion, q = u - d)
    StepProblem chk_problem_, ev_problem_;
    std::unique_ptr<StepContactSolver> chk_solver_, ev_solver_;
    double ev_tolerance_ = 0.0;    // [m]
    std::unique_ptr<CvodeSession> cvode_;
    double t_ = 0.0, t_final_ = 0.0, dt_ = 0.0;
    long n_out_ = 0, out_index_ = 0;
    StepRecord record_;
    Vec p_out_, rel_out_, y_out_;
    double e0_ = 0.0;
    double jump_dissipation_ = 0.0;
    bool root_finding_ = true;     // off only in tests (InitialState::root_finding)
    long iters_since_ = 0, facts_since_ = 0;
    long steps_at_stop_check_ = 0; // CVODE's steps at the last stop check
    double last_check_residual_ = 0.0;
    std::vector<ContactEvent> events_;
    CvodeStats stats_;
    std::deque<Output> pending_;
    double last_event_t_ = -1.0;
    int events_at_this_time_ = 0;
    bool pair_chatter_limit_ = false;  // EventStart::pair_chatter_limit
    std::vector<std::deque<double>> switch_times_;  // per pair, its last kMaxPairSwitches mode changes [s]
    std::vector<double> breaks_;   // EventStart::loading_breaks_s
    std::size_t next_break_ = 0;   // the first break not crossed yet

    void init_grid();
    void init_slots();
    void init_problems(const Eigen::MatrixXd& W, double event_tolerance_m);
    /// The round-off of the event problem's numbers [m]: its relative positions `motion` = G z
    /// and anchors `d` [m]. An event solve that stops above its tolerance but within this has
    /// reached what the problem's own numbers resolve, and its answer is taken.
    double round_off_m(const Vec& motion, const Vec& d) const;
    /// Appended to the step limit's SolverError: the mean and last step against the stack's
    /// period, the events, and the pairs that changed modes most lately.
    std::string step_limit_diagnostics() const;
    void start_cvode(const EventStart& s);
    void decide_initial_modes(const InitialState& stage, const EventStart& s);
    void rebuild();
    /// Moves the anchors of the stuck pairs whose force p_cur lies past their cone so that it sits
    /// on it (a diagonal layer only); true when one moved.
    bool stick_at_cones(const Vec& p_cur, const std::vector<signed char>& tm);
    void enter(const Vec& rel, const std::vector<signed char>& nm, const std::vector<signed char>& tm);
    void in_candidate_modes(const Vec& rel, const std::vector<signed char>& nm, const std::vector<signed char>& tm,
                            bool build, const std::function<void()>& body);
    bool apply_slot_transitions(const std::function<bool(std::size_t)>& take, const Vec& p,
                                std::vector<signed char>& nm, std::vector<signed char>& tm) const;
    /// At an event after the start: every clamp that (nm, tm) engages (released -> stuck) enters slip against its
    /// slider rate at y instead, stuck only where that rate is within the motion margin. True
    /// when it changed (nm, tm) (the candidate modes must then be built again).
    bool engage_clamps_by_slider_rate(const Vec& y, const Vec& rel, std::vector<signed char>& nm,
                                      std::vector<signed char>& tm);
    void decide_modes(double te, const Vec& y, const Vec& p_cur, const std::string& cause,
                      const std::vector<int>* triggered = nullptr);
    static int rhs_of(sunrealtype t, N_Vector y, N_Vector ydot, void* user);
    static int roots_of(sunrealtype, N_Vector y, sunrealtype* g, void* user);
    static int band_jacobian_of(sunrealtype t, N_Vector y, N_Vector, SUNMatrix J, void* user, N_Vector, N_Vector,
                                N_Vector);
    static int psetup_of(sunrealtype, N_Vector, N_Vector, sunbooleantype, sunbooleantype* jcur, sunrealtype gamma,
                         void* user);
    static int psolve_of(sunrealtype t, N_Vector y, N_Vector, N_Vector r, N_Vector x, sunrealtype gamma, sunrealtype,
                         int, void* user);
    StepRecord record_at(double tau, const State& y, Vec& p, Vec& rel);
    double output_time(long i) const { return i == n_out_ ? t_final_ : static_cast<double>(i) * dt_; }
    void emit_until(double upto);
    void note_event_time(double te);
    /// Pair kk changed modes at te: a SolverError naming it when it chatters (kMaxPairSwitches).
    void note_pair_switch(int kk, double te);
    void reset_check_anchors(const State& y);
    bool modes_hold(const State& y, double& residual, bool* witnesses_ok = nullptr);
    void restart(double te, const Vec& y);
    /// CVODE's stop time: the next break of the loading or the run's end [s].
    double stop_time() const { return next_break_ < breaks_.size() ? breaks_[next_break_] : t_final_; }
    /// At a break (te at or past the next one): cross it (cross_loading_break), decide the modes
    /// if they no longer hold, move the stop time on and restart CVODE there. True when it did.
    bool cross_break_at(double te, const Vec& y);
    bool step_keeps_modes(const Vec& y);
    bool step_once();
    void check_stop();
};

/// The Stepper face of every cvode stepper with leaf inertia (held, modal, massive): every
/// call forwards to its EventDriver. Its outputs: advance() integrates to the next output time
/// (t = i dt_s); pairs() are contact_forces() and relative_positions() at the last output, nodes()
/// EventDriver::displacements at its state, stresses() of those and pairs(); report() CVODE's
/// steps, the contact iterations and mode factorisations, the stats and the events.
class EventStepper : public Stepper {
public:
    ~EventStepper() override;
    STACKBEAM_STEPPER_OVERRIDES
    const CvodeStats& stats() const noexcept;
    /// Every mode transition, in time order (cause "start", "root" or "check").
    const std::vector<ContactEvent>& events() const noexcept;
    /// Contact forces p [N] (all rows, conventions.hpp) at the last output.
    const Eigen::VectorXd& contact_forces() const noexcept;
    /// Relative positions s + d [m] (all rows) at the last output.
    const Eigen::VectorXd& relative_positions() const noexcept;

protected:
    explicit EventStepper(std::unique_ptr<EventDriver> driver);
    std::unique_ptr<EventDriver> driver_;
};

}  // namespace stackbeam::detail
