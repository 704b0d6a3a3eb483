#pragma once
// Internal: the one event driver of the event-driven cvode steppers (cvode_stepper.hpp for
// the method): CVODE between contact events with root-finding on the witnesses (decreasing
// crossings), the contact iteration deciding the modes at an event on the look-ahead
// problem, the per-step check of every accepted step, bisection of a missed event on
// CVODE's dense output, restarts (CVodeReInit), the event log and the records on the dt
// grid. Written once; what differs between the steppers is the state and its mode algebra:
//  - the massless stepper (cvode_stepper.cpp): y = [w, w', D (, W_e)], the contact
//    problem driven by R's displacement, s = C'p + c w - d;
//  - the modal one with leaf inertia (cvode_modal.cpp): y = [q, q', D], driven by the
//    retained modes, s = W p + G Phi q - d.
// A stepper derives from EventDriver and implements the hooks below; its Stepper face is an
// EventStepper (below) that owns the driver.
#include <Eigen/Dense>
#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "stackbeam/contact/modes.hpp"
#include "stackbeam/contact/contact.hpp"
#include "stackbeam/fe/system.hpp"
#include "stackbeam/time/run_report.hpp"
#include "stackbeam/time/stepper.hpp"
#include "time/cvode/cvode_modes.hpp"
#include "time/cvode/sundials.hpp"

namespace stackbeam::detail {

class EventDriver {
public:
    using Vec = Eigen::VectorXd;
    using State = Eigen::Ref<const Eigen::VectorXd>;

    /// `who` prefixes the messages ("cvode mode", "cvode mode (leaf inertia)").
    EventDriver(const System& system, const SimulationOptions& options, std::string who);
    virtual ~EventDriver();
    EventDriver(const EventDriver&) = delete;
    EventDriver& operator=(const EventDriver&) = delete;

    /// The record of the next output time (Stepper::advance()).
    const StepRecord& advance();
    const StepRecord& current() const noexcept { return record; }
    long record_index() const noexcept { return out_index; }
    /// The pairs at the current output from its forces and relative positions (rel:
    /// s + d, all rows).
    std::vector<PairRecord> pair_records_at(const Vec& rel) const;
    /// Every leaf's nodes at the current output (Stepper::nodes()): displacements() at its state.
    std::vector<LeafNodes> nodes_at_output() const { return sys.leaf_nodes(displacements(y_out, p_out)); }
    RunReport report() const { return event_report(stats, events); }

    // ---- what the steppers share, set up by their constructors ---------------------------
    const System& sys;
    SimulationOptions opt;
    std::string who;
    // from the system (constructor)
    int n = 0;                  ///< contact rows
    int np = 0;                 ///< pairs
    int ndof = 0, w_dof = 0;    ///< reduced DOFs (System::num_reduced_dofs), R's DOF (the last)
    double f = 1.0;             ///< whole-spring factor (System's model)
    double m_body = 0.0;        ///< R's mass, whole spring [kg]
    int nstate = 0;             ///< CVODE's state size
    double F_ref = 1.0, L_ref = 1.0, V_ref = 1.0;  ///< force [N], length [m], velocity [m/s] scales
    double gap_margin = kMotionMargin;             ///< margin of the gap witnesses (relative to L_ref)
    ModeSet modes;                                 ///< the current modes
    std::vector<signed char>& nmode = modes.nmode;  ///< per pair: CLOSED, OPEN (NONE: no normal row)
    std::vector<signed char>& tmode = modes.tmode;  ///< per pair: STICK, SLIP_POS, SLIP_NEG, FREE (NONE)
    Vec d;                      ///< gaps (normal rows) and anchors (tangential rows) [m]; the system's offsets at first
    Vec d_chk;                  ///< anchors of the per-step check
    struct Slot { int pair; bool normal; };
    std::vector<Slot> slots;    ///< one witness per possible transition
    ContactProblem chk_problem, ev_problem;  ///< the per-step check's and the event decisions' problems
    std::unique_ptr<ContactSolver> chk_solver, ev_solver;
    double ev_tolerance = 0.0;  ///< [m] the event decisions' tolerance on ||v||
    std::unique_ptr<CvodeSession> cvode;
    double t = 0.0;             ///< time of the last accepted point [s]
    double t_final = 0.0, dt = 0.0;
    long n_out = 0, out_index = 0;
    StepRecord record;          ///< of the current output
    Vec p_out, rel_out;         ///< its forces [N] and (modal) relative positions [m]
    Vec y_out;                  ///< its state (CVODE's y at the output time)
    double e0 = 0.0;            ///< initial energy [J]
    bool root_finding = true;   ///< CVODE's root-finding on the witnesses (off only in tests: cvode_testing.hpp)
    long iters_since = 0, facts_since = 0;  ///< contact iterations and factorisations since the last record
    double last_check_residual = 0.0;
    std::vector<ContactEvent> events;
    CvodeStats stats;

    const std::vector<ContactPair>& pairs() const { return chk_problem.pairs; }

    /// Completes a record of a stepper with leaf inertia: the kinetic energy [J] of the leaves
    /// and R (the leaves' share apart), m w'' [N], the damping energy [J] and the balance
    /// with the record's external work, strain energy and dissipation.
    void finish_inertia_record(StepRecord& rec, double kinetic_j, double force_on_mass_n,
                               double damping_energy_j = 0.0) const;
    /// The output grid t_i = i dt_s up to t_final = n_out dt_s (as the closed-form mode).
    void init_grid();
    /// The witness slots: every non-bonded pair's normal (unilateral, or a clamp with
    /// friction) and tangential (friction) transitions.
    void init_slots();
    /// The check and event problems on the compliance W [m/N], their solvers (the event
    /// solver to `event_tolerance_m`).
    void init_problems(const Eigen::MatrixXd& W, double event_tolerance_m);
    /// A stiff stepper's integrator: BDF up to `max_order`, Newton on the stepper's exact
    /// factorisation (psetup) and solve (psolve) of the Newton matrix, as a matrix-embedded
    /// linear solver (CvodeSession::use_embedded_newton).
    struct StiffIntegrator {
        int max_order = 2;
        CVLsPrecSetupFn psetup = nullptr;
        CVLsPrecSolveFn psolve = nullptr;
    };
    /// CVODE on the state y() and atol() set by the stepper: Adams with fixed point (or
    /// `stiff`), the user's limits, stop time t_final, the witnesses as roots (if
    /// root-finding is on).
    void start_cvode(CVRhsFn rhs, const StiffIntegrator* stiff = nullptr);
    /// The contact forces at t = 0 (the initial contact state of every event stepper): the event
    /// problem at s = motion0 - d [m] (motion0: the motion's part of s at t = 0) solved by the
    /// event solver from the warm start p, the forces [N] left in p; throws SolverError
    /// ("initial contact state") when the solve fails. The modes follow from p (the stepper then
    /// decides them a look-ahead on: decide_modes).
    void solve_initial_forces(const Vec& motion0, Vec& p);
    /// The initial record: `make_record` at t = 0, its balance error 0, e0 from it.
    void start_record(const Vec& y0);

    /// The contact iteration decides the modes at (te, y) with the forces p_cur there in
    /// the old modes: CVODE's transitions (`triggered`: the witness slots it found) applied
    /// to the old modes first, kept if the contact iteration's stop test and every witness
    /// accept them a look-ahead away; otherwise the exact solver on that look-ahead
    /// problem decides. Logs the transitions, enters the new modes.
    void decide_modes(double te, const Vec& y, const Vec& p_cur, const std::string& cause,
                      const std::vector<int>* triggered = nullptr);
    /// Enters the modes (nm, tm): pairs that start to stick are anchored at rel [m].
    void enter(const Vec& rel, const std::vector<signed char>& nm, const std::vector<signed char>& tm);
    /// Milliseconds-free wall clock for the stats' time split.
    using Clock = std::chrono::steady_clock;
    static double seconds_since(Clock::time_point t0);

protected:
    // ---- the hooks: what differs between the steppers --------------------------------
    /// Factorises the current modes' linear conditions (counts the factorisation).
    virtual void build_mode() = 0;
    /// Contact forces p [N] of the current modes at state y.
    virtual Vec forces(const State& y) const = 0;
    /// s + d [m] of the current modes at y (affine in the state).
    virtual Vec relative(const State& y) const = 0;
    /// s + d [m] at an event from the forces p_cur (before the modes are decided).
    virtual Vec relative_at_event(const State& y, const Vec& p_cur) const = 0;
    /// The motion's part of s + d: c w, or G Phi q [m].
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
    /// As settle_at_state, only at the events the per-step check found (cause "check"): a
    /// decision at the look-ahead that leaves a witness negative at the state would restart
    /// into the same missed event (default false).
    virtual bool settle_after_missed_event() const;
    /// Runs `body` in the candidate modes (nm, tm): entered (pairs that start to stick anchored
    /// at rel), factorised if `build`, then the current modes and anchors restored.
    void in_candidate_modes(const Vec& rel, const std::vector<signed char>& nm, const std::vector<signed char>& tm,
                            bool build, const std::function<void()>& body);
    /// Applies to (nm, tm) the transition of every witness slot i with take(i) (a slip's
    /// direction from p [N]); true when there was one.
    bool apply_slot_transitions(const std::function<bool(std::size_t)>& take, const Vec& p,
                                std::vector<signed char>& nm, std::vector<signed char>& tm) const;
    /// For correct_decision of the steppers with slipping pairs of their own rate: a slipping
    /// pair slips against its slider rate; where the new modes' rate (`rate`, evaluated on the
    /// candidate modes after build_mode) contradicts the decided sign beyond the margin (a
    /// rate the look-ahead's motion is too short to resolve), the sign follows the rate.
    /// At most three passes; the current modes and anchors are left as they were.
    void signs_follow_slip_rates(const Vec& rel, std::vector<signed char>& nm, std::vector<signed char>& tm,
                                 const std::function<Vec()>& rate);
    /// Books a force jump at an event (a slip that reverses where sticking is not admissible)
    /// that released `loss` [J, whole spring] of the contact layer's energy: friction work.
    void book_force_jump(const std::string& cause, double loss, const Vec& p_cur, const Vec& p_new);
    double jump_dissipation = 0.0;  ///< friction work in force jumps at events [J, whole spring]
    /// The witnesses of the steppers whose modes give the forces `p` [N], the relative position
    /// s [m] of a normal row (`s_of(row)`, > 0 interpenetration) and the slider rate ds/dt [m/s]
    /// of a tangential row (`rate_of(row)`): a closed pair's compression, an open pair's gap, a
    /// clamp's release or engagement, a sticking pair's margin to the cone, a slipping pair's
    /// rate against its force; each positive while its modes hold, with its margin.
    void witnesses_from(const Vec& p, const std::function<double(int)>& s_of, const std::function<double(int)>& rate_of,
                        double* g) const;
    /// The new modes entered with forces p_new (p_cur before): the stepper's bookkeeping of the jump.
    virtual void after_event(const std::string& cause, const Vec& p_cur, const Vec& p_new) = 0;
    /// The record at time tau of state y, with the forces p and (optional) relative positions rel;
    /// the driver sets t, the counters and the residual.
    virtual StepRecord make_record(double tau, const State& y, Vec& p, Vec& rel) const = 0;
    /// The reduced displacements z = [z_r; w] [m, rad] at state y with the forces p [N] of its
    /// record (System::leaf_nodes makes the nodes of them).
    virtual Vec displacements(const State& y, const Vec& p) const = 0;

private:
    struct Output { StepRecord rec; Vec p, rel, y; };
    std::deque<Output> pending;
    double last_event_t = -1.0;
    int events_at_this_time = 0;

    static int roots(sunrealtype, N_Vector y, sunrealtype* g, void* user);
    StepRecord record_at(double tau, const State& y, Vec& p, Vec& rel);
    double output_time(long i) const { return i == n_out ? t_final : static_cast<double>(i) * dt; }
    void emit_until(double upto);
    void note_event_time(double te);
    void reset_check_anchors(const State& y);
    bool modes_hold(const State& y, double& residual, bool* witnesses_ok = nullptr);
    void restart(double te, const Vec& y);
    bool step_once();
};

/// The Stepper face of the event-driven steppers with leaf inertia (modal and massive): every
/// call forwards to their EventDriver.
class EventStepper : public Stepper {
public:
    ~EventStepper() override;
    /// Integrates to the next output time (t = i dt_s) and returns its record.
    const StepRecord& advance() override;
    const StepRecord& current() const noexcept override;
    long record_index() const noexcept override;
    /// The pairs at the last output (contact_forces(), relative_positions()).
    std::vector<PairRecord> pairs() const override;
    /// The leaves' nodes at the last output (EventDriver::displacements at its state).
    std::vector<LeafNodes> nodes() const override;
    /// CVODE's steps, the contact iterations and mode factorisations, the stats and the events.
    RunReport report() const override;
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
