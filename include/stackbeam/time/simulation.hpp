#pragma once
/// @file simulation.hpp
/// The simulation's options, its per-record results (StepRecord, PairRecord) and
/// simulate(), which runs a model in one of the modes (Mode) from t = 0 to t_end.
/// The steppers of the modes: closed_form_stepper.hpp, cvode_stepper.hpp,
/// newmark_stepper.hpp.
#include <functional>
#include <string>
#include <vector>

#include "stackbeam/contact/contact.hpp"
#include "stackbeam/contact/step.hpp"
#include "stackbeam/model/loading.hpp"
#include "stackbeam/fe/system.hpp"

namespace stackbeam {

/// Whole-spring values at the end of a step (also on the half model). SI units.
struct StepRecord {
    double t_s = 0.0;                   ///< time [s]
    double w_m = 0.0;                   ///< displacement of R [m] (+y; the initial velocity's direction in the example)
    double w_dot_m_per_s = 0.0;         ///< velocity of R [m/s]
    double force_on_mass_n = 0.0;       ///< m * d2w/dt2 = -(force of R on the stack) [N]
    double probe_friction_force_n = 0.0;///< tangential contact force p_t at the probe pair [N] (0 if it has none; NaN: no probe)
    int contact_iterations = 0;         ///< solver iterations of this step
    int n_stick = 0, n_slip = 0, n_open = 0;  ///< pairs by state (meshed part)
    double kinetic_energy_j = 0.0;      ///< kinetic energy [J]: m w_dot^2 / 2, plus the leaves' v^T M v / 2 in mode newmark
                                        ///< (the windup rig leaves R's inertia out of its loop: then the leaves' alone)
    double strain_energy_j = 0.0;       ///< elastic energy of the leaves and of any elastic interface layer [J]
    double dissipated_energy_j = 0.0;   ///< cumulative friction work, sum of |p_t . slip increment| [J]
    double energy_balance_error_j = 0.0;///< initial energy - (kinetic + strain + dissipated + impact loss
                                        ///< + damping energy) [J]
    double contact_residual_m = 0.0;    ///< ||v||_2 (eq. 9) at the converged forces [m]
    int factorizations = 0;             ///< dense factorisations of the step (exact solver)
    // Loadings (loading.hpp); all zero under the paper's initial conditions.
    double spring_force_n = 0.0;        ///< force of R on the stack, +y: k w - c^T p, whole spring [N]
                                        ///< (the force the rig's load cell reads; the loop is spring_force vs w)
    double external_force_n = 0.0;      ///< load on R besides the stack: applied force - weight - m y_b'' [N];
                                        ///< prescribed displacement: the rig's force on the spring (= spring_force_n)
    double base_displacement_m = 0.0;   ///< y_b of the supports [m] (base excitation): R's absolute displacement is w + y_b
    double external_work_j = 0.0;       ///< work of the external loads since t = 0 [J]; the balance is
                                        ///< E(0) + external work - (kinetic + strain + dissipated)
    double leaf_kinetic_energy_j = 0.0; ///< the leaves' share of kinetic_energy_j [J] (0 with massless leaves)
    double impact_loss_j = 0.0;         ///< cumulative energy lost at contact closures net of openings [J]
                                        ///< (mode newmark: the normal contact work, newmark_stepper.hpp; with
                                        ///< massive leaves on an elastic layer also the implicit contact
                                        ///< impulse's loss on the layer, (p1 - p0)^T C_L (p1 - p0) / 2 per step)
    double damping_energy_j = 0.0;      ///< cumulative energy taken by structural damping, int v^T C v dt [J]
                                        ///< (SimulationOptions::damping; 0 without); in the balance as dissipated
    // The seat (conventions.hpp, "Seat"; loading.hpp, seat loads and the windup rig): modes closed-form,
    // newmark and cvode's massive and modal steppers; 0 on the half model and in cvode's massless and held ones.
    double seat_rotation_rad = 0.0;     ///< theta_R, the seat's rotation [rad], counter-clockwise
    double seat_moment_n_m = 0.0;       ///< the moment on the spring at the seat [N m], counter-clockwise: the
                                        ///< applied M - H h, or the windup rig's reaction moment
    double seat_axial_m = 0.0;          ///< u_R, the seat's axial displacement [m], +x (0 where it locates the stack)
};

/// Column names of StepRecord in CSV order.
std::vector<std::string> step_record_columns();
/// Values of a record in the order of step_record_columns().
std::vector<double> step_record_values(const StepRecord& r);

/// The integrators.
enum class Mode {
    closed_form,  ///< the paper's closed-form step (eq. 16), fixed dt: the reference (massless leaves)
    cvode,        ///< SUNDIALS CVODE between events, root-finding on every contact transition (massless leaves)
    newmark,      ///< leaves with mass: average-acceleration Newmark, fixed dt (newmark_stepper.hpp)
};
template <>
const std::vector<EnumWord<Mode>>& enum_words<Mode>();
const char* to_string(Mode m);
Mode parse_mode(const std::string& text, const std::string& field);

// ContactPath, parse_contact_path and kSparsePathMinComponents: stackbeam/contact/step.hpp

/// Mode cvode with leaf mass on a stack with friction: how the leaves' inertia is integrated
/// (docs/time-integration.md, "Mode cvode with leaf mass").
enum class LeafInertia {
    automatic,  ///< massive where every contact row has an elastic layer, modal otherwise
    massive,    ///< every DOF of the stack in CVODE (BDF); needs elastic contact everywhere
    modal,      ///< the stack's modes below CvodeOptions::modal_cutoff_rad_per_s, a massless contact layer
};
template <>
const std::vector<EnumWord<LeafInertia>>& enum_words<LeafInertia>();
const char* to_string(LeafInertia kind);
/// Parses "auto" | "massive" | "modal"; throws InputError naming `field`.
LeafInertia parse_leaf_inertia(const std::string& text, const std::string& field);

/// Options of mode "cvode" (see cvode_stepper.hpp).
struct CvodeOptions {
    double rtol = 1e-8;          ///< CVODE relative tolerance [-]
    double atol_m = 1e-12;       ///< absolute tolerance on w [m]; on w_dot it is atol_m * omega, on the
                                 ///< dissipated energy atol_m * k * (amplitude scale) (see cvode_stepper.cpp)
    double max_step_s = 0.0;     ///< largest internal step [s]; 0 = no limit
    long max_steps = 10000000;   ///< limit on CVODE's internal steps over the whole run
    double modal_cutoff_rad_per_s = 0.0;  ///< leaf inertia with friction only: the stack's modes up to this
                                          ///< circular frequency carry the inertia, those above respond
                                          ///< quasi-statically [rad/s]; 0 = 10 x the stack's first
                                          ///< frequency (docs/time-integration.md)
    LeafInertia leaf_inertia = LeafInertia::automatic;  ///< leaf mass with friction: massive or modal
};

/// Structural (Rayleigh) damping of the leaves, C = alpha M + beta K (M the consistent mass of
/// the leaves and R, K the leaves' stiffness; the elastic layer is not damped): the modal damping
/// ratio of a mode of circular frequency omega is zeta = alpha / (2 omega) + beta omega / 2.
/// Off by default: a leaf spring's steel is lightly damped, and the friction between the leaves
/// is the damping stackbeam computes. Taken by mode newmark with massive leaves and mode cvode with the massive stack only
/// (docs/time-integration.md, "Structural damping").
struct StructuralDamping {
    double rayleigh_alpha_per_s = 0.0;  ///< alpha [1/s], >= 0
    double rayleigh_beta_s = 0.0;       ///< beta [s], >= 0
    /// The elastic layer's normal retardation time tau_L [s], >= 0 (Kelvin-Voigt): on every closed
    /// pair with a layer a normal dashpot eta = tau_L k_n [N s/m] (k_n = 1 / c_n the pair's layer
    /// stiffness [N/m]; per unit area tau_L times the layer's normal stiffness [Pa/m]) in parallel
    /// with the spring, its force -eta ds_n/dt. Damps a contact point's own vibration on the layer
    /// (zeta = tau_L omega / 2 at omega ~ 1e5-1e6 rad/s) and leaves the stack's motion (omega < 1e2
    /// rad/s) undamped to ~1e-4 at tau_L = 1e-6 s. Its work is damping energy. Taken by mode cvode
    /// with the whole massive stack only (docs/time-integration.md, "Structural damping"). 0: none.
    double layer_normal_time_s = 0.0;
    /// Rayleigh damping of the leaves on (the layer's dashpots apart).
    bool active() const noexcept { return rayleigh_alpha_per_s > 0.0 || rayleigh_beta_s > 0.0; }
};

struct SimulationOptions {
    Mode mode = Mode::closed_form;
    double dt_s = 1e-3;        ///< time step [s] (paper: 1e-3); in mode cvode the output interval
    CvodeOptions cvode;        ///< mode cvode only
    double t_end_s = 0.6;      ///< end time [s]
    Loading loading;           ///< how the spring is loaded (loading.hpp); default: the paper's initial conditions
    /// Contact solver and its tolerance (paper: ||v|| < 2e-6 m). The default, SolverKind::exact,
    /// is the same in every mode and for every entry point (library, scenario file, command
    /// line): the step's solver in modes closed-form and newmark, the per-step check's solver
    /// in mode cvode (whose event solver is always exact). The paper cases' cvode runs give
    /// byte-identical records and event logs with exact and with accelerated as the check.
    SolverOptions solver;
    TauRule tau_rule = TauRule::current;
    /// Dense or sparse contact problem (mode closed-form); automatic by problem size.
    ContactPath contact_path = ContactPath::automatic;
    /// Sparse path only: how its exact solver solves the linear problems and the transitions
    /// (contact.hpp; the defaults are the measured choices, docs/decisions/).
    SparsePathTuning sparse_tuning;
    /// Throw SolverError when a step's contact solve does not converge (default);
    /// if false the step is kept and flagged by its residual.
    bool stop_on_nonconvergence = true;
    /// Mode newmark with massive leaves: the normal restitution coefficient e [-] of the
    /// impact law, 0 <= e <= 1. A normal component that closes in a step leaves it with
    /// its relative velocity reversed to -e times its approach velocity at the step's
    /// start (0: perfectly inelastic, the default; 1: elastic); every other held component
    /// ends with relative velocity 0. Docs: docs/time-integration.md.
    double restitution = 0.0;
    /// The caller's stop check, polled while a run integrates (mode cvode: every 64 internal
    /// steps inside the event driver, so a stalled run can be interrupted between outputs;
    /// every mode: before each output step in simulate()). When it returns true the run ends
    /// with RunStopped (errors.hpp) at the time reached; the records so far stay delivered.
    /// Empty (the default): never stops. It must be cheap and safe to call from the run's thread
    /// (e.g. reading a std::sig_atomic_t set by a signal handler).
    std::function<bool()> stop_requested;
    /// Structural damping of the leaves (mode newmark with massive leaves, mode cvode with the massive stack).
    StructuralDamping damping;
    /// Throws InputError when a value is out of range; its field() is the member's path
    /// ("dt_s", "cvode.rtol", "solver.tolerance_m": option_table.hpp gives the scenario key
    /// and the command-line flag of each).
    void validate() const;
};

/// The contact path `options.contact_path` resolves to on `system`: automatic gives
/// sparse when the solver is exact and system.num_components() >= kSparsePathMinComponents,
/// dense otherwise. Throws InputError for the sparse path with a solver other than exact.
ContactPath choose_contact_path(const System& system, const SimulationOptions& options);

// The assembly of a spring that needs it (needs_assembly: a leaf with a free camber,
// LeafSpec::free_camber_m, an interference, InterfaceSpec::initial_gap_m < 0, or rebound clips,
// which close initial gaps wider than their clearance): every run of mode
// closed-form, newmark and cvode's massive stack starts from the assembled, pre-stressed stack. The leaves start in their
// free shapes, anchored there (d_t = 0), touching wherever their offsets d_n (interface gap plus
// the free shapes' difference, PairSpec::initial_gap_m) are <= 0; the centre bolt (the rigid
// body's seat) and the clamps pull them together in one quasi-static, monotonic load step with
// no force on R: the contact problem of that step (the interfaces' Coulomb friction included,
// incremental from the free shapes) resolves the interference; pairs that stick keep their
// anchors and tangential forces as the initial sticking state, the others are re-anchored where
// they slid to. Gravity's static step then follows from the assembled state, then w(0), w'(0).
// A stepper that does not assemble (mode cvode with massless leaves, its modal and
// held-for-good leaf-inertia steppers) refuses such a model where it is chosen (make_stepper):
// an InputError naming leaves[i].free_camber_m (or free_radius_m), clips[0] or
// interfaces[i].initial_gap_m, and the steppers that take the assembly.
//
// Structural damping (SimulationOptions::damping) is taken by mode newmark with massive leaves
// and mode cvode with the massive stack only; elsewhere make_stepper refuses it (InputError
// naming damping.rayleigh_alpha_per_s or _beta_s).

/// Throws InputError when the model's initial conditions contradict the loading
/// (a prescribed displacement fixes w(0) and w'(0) itself).
void require_loading_fits(const ModelSpec& model, const Loading& loading);

struct RunReport;  // run_report.hpp

/// One contact pair at one time (simulate's per-pair output; meshed part, signs of
/// conventions.hpp).
struct PairRecord {
    int pair = 0;             ///< index in System::pairs()
    int interface_index = 0;  ///< interface i: leaf i above, leaf i+1 below
    double x_m = 0.0;         ///< position along the leaves [m]
    PairState state = PairState::open;
    double p_n_n = 0.0;       ///< normal force [N], < 0 compression (0 when the pair has no normal row)
    double p_t_n = 0.0;       ///< tangential (friction) force on the upper leaf, +x [N] (0: no tangential row)
    double gap_m = 0.0;       ///< normal gap d_n - approach [m]: > 0 open, 0 closed (0: no normal row)
    double slip_m = 0.0;      ///< tangential displacement of the upper surface relative to the lower, +x [m]
                              ///< (elastic interface: the slider's, i.e. without the layer's elastic shear c_L p_t)
};
/// Receives the pairs at each record's time (t [s], one entry per System::pairs()).
using PairObserver = std::function<void(double t_s, const std::vector<PairRecord>&)>;

/// Receives every leaf's nodes at each record's time (t [s], one entry per leaf; Stepper::nodes()).
using NodeObserver = std::function<void(double t_s, const std::vector<LeafNodes>&)>;

/// Runs from t = 0 to options.t_end_s in options.mode; the first record is the
/// initial state, then one per dt_s (a step of the closed-form mode, an output time
/// of the cvode mode). `on_step` (optional) sees every record as it is made;
/// `report` (optional) receives the counters and, in mode cvode, the event log;
/// `on_pairs` (optional) sees every pair at every record's time; `on_nodes` (optional)
/// every leaf's nodal displacements there (off by default: they cost a solve per record in
/// the massless modes and memory if kept). Per record: on_step, on_pairs, on_nodes.
std::vector<StepRecord> simulate(const System& system, const SimulationOptions& options,
                                 const std::function<void(const StepRecord&)>& on_step = {},
                                 RunReport* report = nullptr, const PairObserver& on_pairs = {},
                                 const NodeObserver& on_nodes = {});

}  // namespace stackbeam
