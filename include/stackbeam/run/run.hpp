#pragma once
/// @file run.hpp
/// The run layer: one run of a scenario and its summary, for every front-end (the command
/// line, the Python module, and what calls a run next: an FMU, a calibration). A front-end
/// fills a RunRequest, implements a RunSink if it streams rows (to files, to arrays), calls
/// run_scenario() and formats the RunSummary it gets (summary_json.hpp: the JSON summary).
/// The library writes nothing here: every row goes to the caller's sink.
///
/// Adding an output: a flag in RunOutputs, a callback in RunSink (default: ignore), one
/// line in run_scenario's per-record callback (to the record loop it shares with simulate(),
/// lib/time/record_loop.hpp); a figure of the summary: a member of RunSummary (or
/// of RunStats, gathered per record) and its key in summary_json. Every front-end then has it.
///
/// Interruption: the stop check (RunRequest::stop) is polled before each record is handed to
/// the sink and, through SimulationOptions::stop_requested, inside the steppers' long steps
/// (mode cvode: every 64 internal steps). When it answers true the run ends without an
/// exception: RunSummary::interrupted, the records handed over so far (the record in progress
/// is dropped), no loop figures and a default RunReport.
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "stackbeam/fe/system.hpp"
#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/post/stresses.hpp"
#include "stackbeam/run/loop_figures.hpp"
#include "stackbeam/time/run_report.hpp"
#include "stackbeam/time/simulation.hpp"

namespace stackbeam {

/// The outputs a run makes besides its records, each handed to the RunSink at every record.
/// Off by default: in the massless modes pairs, nodes and stresses cost a solve per record.
struct RunOutputs {
    bool pairs = false;         ///< RunSink::on_pairs (Stepper::pairs())
    bool nodes = false;         ///< RunSink::on_nodes (Stepper::nodes())
    /// RunSink::on_stresses (Stepper::stresses(), post/stresses.hpp) and RunSummary::stresses (a
    /// StressMonitor fed every record, the interfaces' peak pressures)
    bool stresses = false;
    bool keep_records = true;   ///< RunSummary::records holds every record (the loop figures need them)
};

/// The caller's side of a run: sees every record as it is made. Per record: on_record, then
/// on_pairs, on_nodes, on_stresses for those RunOutputs asks. An exception thrown here ends the
/// run and reaches run_scenario's caller (e.g. a failed write, with the system's reason).
class RunSink {
public:
    virtual ~RunSink() = default;
    virtual void on_record(const StepRecord& record) { (void)record; }
    /// t [s], one entry per System::pairs()
    virtual void on_pairs(double t_s, const std::vector<PairRecord>& pairs) { (void)t_s, (void)pairs; }
    /// t [s], one entry per leaf
    virtual void on_nodes(double t_s, const std::vector<LeafNodes>& leaves) { (void)t_s, (void)leaves; }
    /// t [s], every leaf's resultants and fibre stresses and every pair's pressure
    virtual void on_stresses(double t_s, const Stresses& stresses) { (void)t_s, (void)stresses; }
};

/// The summary's first line (RunRequest::setup) for the paper's case `c` meshed by `options`:
/// "case friction, 20 elements per half leaf (half model), " (the mode follows on the same line).
std::string case_setup(PaperCase c, const PaperExampleOptions& options);

/// The summary's first line for a scenario read from `source` (its description, "" none):
/// "scenario FILE (DESCRIPTION)\n".
std::string scenario_setup(const std::string& source, const std::string& description);

/// One run, as a plain value: the integrator's options, what to output and where.
struct RunRequest {
    SimulationOptions options;    ///< its stop_requested is replaced by `stop` when that is given
    std::string setup;            ///< the summary's first line: the case or the scenario ("" none)
    RunOutputs outputs;
    RunSink* sink = nullptr;      ///< the caller's, outliving the call (nullptr: records only)
    std::function<bool()> stop;   ///< true: stop (interrupted); empty: options.stop_requested as given
};

/// What the summary needs of the records, gathered one record at a time (also complete for an
/// interrupted run). Energies [J], w [m], forces [N].
struct RunStats {
    StepRecord first, last;
    long records = 0;
    long contact_iterations = 0;  ///< sum over the records
    int max_contact_iterations = 0;
    double max_abs_balance_j = 0.0;
    double w_min_m = 0.0, w_max_m = 0.0, force_min_n = 0.0, force_max_n = 0.0;
    void add(const StepRecord& r);
    /// The initial energy: the body's, and the leaves' with leaf inertia (the first record).
    double initial_energy_j() const { return first.kinetic_energy_j + first.strain_energy_j; }
};

/// The stepper that runs a system with some options, as the registry describes it (its row of
/// lib/time/stepper_registry.hpp): what front-ends show without branching on the mode.
struct StepperDescription {
    std::string name;          ///< "cvode-massive", ...
    std::string description;   ///< "mode cvode with the whole massive stack", ...
    Mode mode = Mode::closed_form;
    bool cvode_stats = false;          ///< RunReport::cvode and the event log are filled
    bool impact_loss = false;          ///< StepRecord::impact_loss_j is meaningful
    bool leaf_kinetic_energy = false;  ///< StepRecord::leaf_kinetic_energy_j is meaningful
};

/// The registry's row for `system` and `options` (make_stepper's choice); throws InputError as
/// make_stepper for a combination no stepper takes.
StepperDescription describe_stepper(const System& system, const SimulationOptions& options);

/// What some stepper of the registry takes or gives, for the checks a front-end makes before it
/// has a system (StepperCapabilities' fields of the same meaning).
enum class StepperFeature {
    massive_leaves,  ///< leaves with density > 0
    event_log,       ///< RunReport::cvode and the event log
};

/// The modes with at least one stepper that has `feature`, each once, in the registry's order
/// (massive_leaves: newmark, cvode; event_log: cvode).
std::vector<Mode> modes_with(StepperFeature feature);

/// The words of `modes` joined by `separator` ("newmark or cvode").
std::string mode_list(const std::vector<Mode>& modes, const std::string& separator);

/// One interface's largest pressure over the run (clamps included, clips not): InterfacePeak
/// at the time t_s [s] it was reached (NaN: no pair on the interface).
struct InterfaceRunPeak {
    InterfacePeak peak;
    double t_s = std::numeric_limits<double>::quiet_NaN();
};

/// A run's stress figures (RunOutputs::stresses): the StressMonitor's summary over the records
/// (the cycle: the loading's last period [t_last - period, t_last] when the run lasts a period,
/// else the whole run) and every interface's peak pressure.
struct RunStresses {
    StressSummary summary;
    std::vector<InterfaceRunPeak> interfaces;  ///< one per interface (ModelSpec::interfaces order)
};

/// The result of run_scenario: what every front-end formats.
struct RunSummary {
    std::string setup;               ///< RunRequest::setup
    SimulationOptions options;       ///< the options run (without the stop check)
    StepperDescription stepper;
    ContactPath contact_path = ContactPath::automatic;  ///< the massless modes' path (choose_contact_path)
    int contact_components = 0;      ///< System::num_components()
    RunStats stats;
    std::vector<StepRecord> records; ///< every record (RunOutputs::keep_records), also when interrupted
    RunReport report;                ///< the stepper's counters and event log (default when interrupted)
    LoopFigures loop;                ///< the last cycle's figures (none when interrupted)
    /// The windup figures (loop_figures.hpp) of a run whose loading loads the seat (loads_the_seat);
    /// none otherwise and when interrupted
    std::optional<WindupFigures> windup;
    /// RunOutputs::stresses: the stress figures (none when not asked; when interrupted: stresses_note says)
    std::optional<RunStresses> stresses;
    std::string stresses_note;
    /// What Model::build changed in the user's spec (Model::adjustments(): close clamps merged),
    /// one sentence each; every front-end shows them with the answers (empty: nothing, no key)
    std::vector<std::string> model_adjustments;
    bool interrupted = false;        ///< the stop check ended the run
    double t_reached_s = 0.0;        ///< the last record's time [s]
    double wall_s = 0.0;             ///< wall time of the run [s] (the set-up of the stepper and the steps)
};

/// Runs `request` on `system` from t = 0 to options.t_end_s (as simulate(), the same records):
/// the records to the sink, the stats, the report, the loop figures. Throws as simulate() (an
/// InputError for bad options, SolverError), never for a stop (RunSummary::interrupted).
RunSummary run_scenario(const System& system, const RunRequest& request);

}  // namespace stackbeam
