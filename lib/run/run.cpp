// The run layer (run/run.hpp): a run's record loop, its stats and its summary's figures.
#include "stackbeam/run/run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "stackbeam/errors.hpp"
#include "stackbeam/time/stepper.hpp"
#include "time/record_loop.hpp"
#include "time/stepper_registry.hpp"

namespace stackbeam {

std::string case_setup(PaperCase c, const PaperExampleOptions& options) {
    return std::string("case ") + to_string(c) + ", " + std::to_string(options.elements_per_half_leaf) +
           " elements per half leaf (" + word_of(options.symmetry) + " model), ";
}

std::string scenario_setup(const std::string& source, const std::string& description) {
    return "scenario " + source + (description.empty() ? "" : " (" + description + ")") + "\n";
}

void RunStats::add(const StepRecord& r) {
    if (records == 0) {
        first = r;
        w_min_m = w_max_m = r.w_m;
        force_min_n = force_max_n = r.spring_force_n;
    }
    last = r;
    ++records;
    contact_iterations += r.contact_iterations;
    max_contact_iterations = std::max(max_contact_iterations, r.contact_iterations);
    max_abs_balance_j = std::max(max_abs_balance_j, std::abs(r.energy_balance_error_j));
    w_min_m = std::min(w_min_m, r.w_m);
    w_max_m = std::max(w_max_m, r.w_m);
    force_min_n = std::min(force_min_n, r.spring_force_n);
    force_max_n = std::max(force_max_n, r.spring_force_n);
}

StepperDescription describe_stepper(const System& system, const SimulationOptions& options) {
    const detail::StepperCapabilities& row = detail::choose_stepper(system, options);
    StepperDescription d;
    d.name = row.name;
    d.description = row.description;
    d.mode = row.mode;
    d.cvode_stats = row.cvode_stats;
    d.impact_loss = row.impact_loss;
    d.leaf_kinetic_energy = row.leaf_kinetic_energy;
    return d;
}

std::vector<Mode> modes_with(StepperFeature feature) {
    std::vector<Mode> modes;
    for (const detail::StepperCapabilities& row : detail::stepper_registry()) {
        const bool has = feature == StepperFeature::massive_leaves ? row.massive_leaves : row.cvode_stats;
        if (has && std::find(modes.begin(), modes.end(), row.mode) == modes.end()) modes.push_back(row.mode);
    }
    return modes;
}

std::string mode_list(const std::vector<Mode>& modes, const std::string& separator) {
    std::string list;
    for (const Mode m : modes) list += (list.empty() ? "" : separator) + to_string(m);
    return list;
}

namespace {

/// Thrown inside the record loop when the stop check answers true between records.
struct StopSeen {};

/// The monitor's options for a run of `options` ending at t_last_s [s]: periodic when the run
/// lasts at least one period of a periodic loading, else the whole run (rainflow).
StressMonitorOptions monitor_options(const SimulationOptions& options, double t_last_s) {
    StressMonitorOptions o;
    const double period_s = options.loading.period_s();
    if (period_s > 0.0 && t_last_s >= period_s) o.period_s = period_s;
    o.t_end_s = t_last_s;  // the cycle's end (the whole run's without a period)
    return o;
}

/// Keeps each interface's largest pressure over the run and its time.
void add_peaks(std::vector<InterfaceRunPeak>& peaks, double t_s, const Stresses& s) {
    if (peaks.empty()) peaks.resize(s.interfaces.size());
    for (std::size_t i = 0; i < s.interfaces.size() && i < peaks.size(); ++i) {
        const InterfacePeak& p = s.interfaces[i];
        if (p.pair >= 0 && (std::isnan(peaks[i].t_s) || p.pressure_pa > peaks[i].peak.pressure_pa)) {
            peaks[i].peak = p;
            peaks[i].t_s = t_s;
        }
        peaks[i].peak.interface_index = p.interface_index;
    }
}

}  // namespace

RunSummary run_scenario(const System& system, const RunRequest& request) {
    const auto t0 = std::chrono::steady_clock::now();
    RunSummary summary;
    summary.setup = request.setup;
    summary.options = request.options;
    summary.options.stop_requested = nullptr;
    SimulationOptions options = request.options;
    if (request.stop) options.stop_requested = request.stop;
    const std::function<bool()>& stop = options.stop_requested;
    summary.contact_path = choose_contact_path(system, options);
    summary.contact_components = system.num_components();
    summary.model_adjustments = system.model().adjustments();
    RunSink none;
    RunSink& sink = request.sink ? *request.sink : none;
    const RunOutputs& out = request.outputs;
    try {
        // the record loop of simulate() (time/record_loop.hpp), with the stop check before each record is handed over
        std::optional<StressMonitor> monitor;  // only when asked: no cost otherwise
        std::vector<InterfaceRunPeak> peaks;
        bool started = false;
        // a windup run: the contact state of the last record, for the seat's tangent stiffness
        const bool windup = loads_the_seat(options.loading);
        const long last_record = detail::record_steps(options);
        long index = 0;
        std::vector<PairRecord> last_pairs;
        summary.report = detail::run_records(system, options, [&](const Stepper& stepper, const StepRecord& r) {
            if (!started) {  // record 0: make_stepper has validated the options
                started = true;
                summary.stepper = describe_stepper(system, options);
                const long n = detail::record_steps(options);
                if (out.keep_records) summary.records.reserve(static_cast<std::size_t>(n) + 1);
                if (out.stresses)
                    monitor.emplace(system.model().spec(), monitor_options(options, static_cast<double>(n) * options.dt_s));
            }
            if (stop && stop()) throw StopSeen{};  // the record in progress is dropped
            if (out.keep_records) summary.records.push_back(r);
            summary.stats.add(r);
            sink.on_record(r);
            if (out.pairs) sink.on_pairs(r.t_s, stepper.pairs());
            if (windup && index++ == last_record) last_pairs = stepper.pairs();
            if (out.nodes) sink.on_nodes(r.t_s, stepper.nodes());
            if (out.stresses) {
                const Stresses st = stepper.stresses();
                monitor->add(r.t_s, st);
                add_peaks(peaks, r.t_s, st);
                sink.on_stresses(r.t_s, st);
            }
        });
        summary.loop = loop_figures(summary.records, options.loading.period_s());
        if (windup) {
            summary.windup = windup_figures(summary.records, options.loading, summary.loop);
            try {
                summary.windup->tangent = seat_tangent_stiffness(system, last_pairs, summary.stats.last.t_s);
            } catch (const SolverError& e) {
                summary.windup->tangent_note = e.what();
            }
        }
        if (monitor) summary.stresses = RunStresses{monitor->summary(), std::move(peaks)};
    } catch (const StopSeen&) {
        summary.interrupted = true;
    } catch (const RunStopped&) {  // the stop check seen within a step
        summary.interrupted = true;
    }
    if (summary.interrupted) summary.loop.note = "interrupted run: no loop figures";
    if (out.stresses && summary.interrupted) summary.stresses_note = "interrupted run: no stress figures";
    summary.t_reached_s = summary.stats.last.t_s;
    summary.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return summary;
}

}  // namespace stackbeam
