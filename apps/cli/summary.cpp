// The results of a run: the text summary on stdout and the --summary JSON file.
#include "summary.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "stackbeam/errors.hpp"

namespace stackbeam::cli {

namespace {

/// The initial energy: the body's, and the leaves' in mode newmark (the first record).
double initial_energy(const RunStats& s) { return s.first.kinetic_energy_j + s.first.strain_energy_j; }

/// The contact law of every interface; for an elastic one the layer used (interface_layer):
/// k_n, k_t [Pa/m] and the decay length l [m].
nlohmann::json interfaces_json(const Model& model) {
    nlohmann::json list = nlohmann::json::array();
    const ModelSpec& spec = model.spec();
    for (std::size_t i = 0; i < spec.interfaces.size(); ++i) {
        const InterfaceContact contact = spec.interfaces[i].contact;
        nlohmann::json f = {{"index", i}, {"contact", to_string(contact)}};
        if (contact == InterfaceContact::elastic) {
            const InterfaceLayer layer = interface_layer(spec, static_cast<int>(i));
            f["normal_stiffness_pa_per_m"] = layer.normal_stiffness_pa_per_m;
            f["tangential_stiffness_pa_per_m"] = layer.tangential_stiffness_pa_per_m;
            f["decay_length_m"] = layer.decay_length_m;
        }
        list.push_back(f);
    }
    return list;
}

}  // namespace

LoopFigures loop_figures(const RunRequest& request, const RunResult& result) {
    LoopFigures loop;
    const double period = request.options.loading.period_s();
    if (result.signal != 0) {
        loop.note = "interrupted run: no loop figures";
    } else if (period > 0.0) {
        try {
            const auto cyc = last_cycle(result.records, period);
            loop.metrics = hysteresis_metrics(result.records, cyc.first, cyc.second);
        } catch (const InputError& e) {
            loop.note = e.what();
        }
        if (const auto& m = loop.metrics) {
            // the records hysteresis_metrics read (t in [t_start, t_end]); the sweep's point
            // figures (lib/study/sweep.cpp) make the same call
            try {
                const FancherLoopFit fit = fit_fancher_loop(result.records, m->t_start_s, m->t_end_s);
                loop.fancher = fit.fit;
                for (std::size_t i = 0; i < fit.w_m.size(); ++i) loop.fancher_loop.emplace_back(fit.w_m[i], fit.model_force_n[i]);
            } catch (const InputError& e) {
                loop.fancher_note = e.what();
            }
        }
    } else {
        loop.note = "no periodic loading: no steady cycle";
    }
    return loop;
}

void print_summary(const RunRequest& request, const System& system, const RunResult& result, const LoopFigures& loop) {
    const SimulationOptions& options = request.options;
    const RunStats& s = result.stats;
    const StepRecord& last = s.last;
    const long steps = s.records - 1;  // the first record is the initial state
    std::printf("%smode %s, solver %s, dt %g s, t_end %g s\n", request.setup.c_str(), to_string(options.mode),
                to_string(options.solver.kind), options.dt_s, options.t_end_s);
    if (options.mode == Mode::cvode) {
        const auto& cs = result.report.cvode;
        std::printf("cvode                      rtol %g, atol %g m; %ld steps, %ld RHS evaluations, %ld root evaluations\n",
                    options.cvode.rtol, options.cvode.atol_m, cs.steps, cs.rhs_evaluations, cs.root_evaluations);
        std::printf("events                     %ld event times (%ld found by the per-step check), %zu transitions, "
                    "%ld restarts, %ld mode factorisations\n",
                    cs.events, cs.missed_events, result.report.events.size(), cs.restarts, cs.mode_factorizations);
        if (cs.retained_modes > 0)
            std::printf("leaf inertia               %d modes up to %g rad/s carry it, the rest quasi-static "
                        "(massless contact layer)\n",
                        cs.retained_modes, cs.modal_cutoff_rad_per_s);
        std::printf("outputs                    %ld (every %g s)\n", steps, options.dt_s);
    } else {
        std::printf("contact path               %s (%d contact components)\n",
                    to_string(choose_contact_path(system, options)), system.num_components());
        std::printf("steps                      %ld\n", steps);
    }
    const ModelSpec& spec = system.model().spec();
    for (std::size_t i = 0; i < spec.interfaces.size(); ++i)
        if (spec.interfaces[i].contact == InterfaceContact::elastic) {
            const InterfaceLayer layer = interface_layer(spec, static_cast<int>(i));
            std::printf("interface %-2zu               elastic: k_n %.4g Pa/m, k_t %.4g Pa/m, decay length %.4g m\n", i,
                        layer.normal_stiffness_pa_per_m, layer.tangential_stiffness_pa_per_m, layer.decay_length_m);
        }
    std::printf("contact iterations         total %ld, max per step %d, mean per step %.2f\n", s.contact_iterations,
                s.max_contact_iterations, steps > 0 ? static_cast<double>(s.contact_iterations) / steps : 0.0);
    std::printf("final state                t %.6g s, w %.6g m, w_dot %.6g m/s\n", last.t_s, last.w_m,
                last.w_dot_m_per_s);
    std::printf("loading                    %s%s\n", to_string(options.loading.kind),
                options.loading.gravity_m_per_s2 > 0.0
                    ? (", gravity " + std::to_string(options.loading.gravity_m_per_s2) + " m/s^2").c_str()
                    : "");
    std::printf("energy balance error       %.3e J at the end, %.3e J largest (initial energy %.6g J, external work %.6g J, "
                "dissipated %.6g J)\n",
                last.energy_balance_error_j, s.max_abs_balance_j, initial_energy(s), last.external_work_j,
                last.dissipated_energy_j);
    if (const auto& m = loop.metrics) {
        std::printf("loop                       t %.6g to %.6g s: area %.6g J per cycle (friction work %.6g J), secant stiffness %.6g N/m,\n"
                    "                           dynamic rate %.6g N/m, loss factor %.4g, equivalent damping ratio %.4g\n",
                    m->t_start_s, m->t_end_s, m->loop_area_j, m->dissipated_j, m->secant_stiffness_n_per_m,
                    m->dynamic_rate_n_per_m, m->loss_factor, m->equivalent_damping_ratio);
    } else {
        std::printf("loop                       none (%s)\n", loop.note.c_str());
    }
    if (const auto& fit = loop.fancher) {
        const FancherParameters& p = fit->parameters;
        std::printf("fancher fit                upper %.6g N/m w + %.6g N, lower %.6g N/m w + %.6g N, beta %.4g m;\n"
                    "                           RMS error %.4g N = %.3g %% of the force range (%d iterations%s)\n",
                    p.upper_rate_n_per_m, p.upper_offset_n, p.lower_rate_n_per_m, p.lower_offset_n, p.beta_m,
                    fit->rms_error_n, 100.0 * fit->rms_error_relative, fit->iterations,
                    fit->converged ? "" : ", NOT converged");
    } else if (!loop.fancher_note.empty()) {
        std::printf("fancher fit                none (%s)\n", loop.fancher_note.c_str());
    }
    if (options.mode == Mode::newmark)
        std::printf("impact loss                %.6g J (kinetic energy of the leaves at the end %.6g J)\n",
                    last.impact_loss_j, last.leaf_kinetic_energy_j);
    std::printf("wall time                  %.3f s\n", result.wall_s);
    std::printf("output                     %s\n", result.csv_file.c_str());
    if (!result.events_file.empty()) std::printf("event log                  %s\n", result.events_file.c_str());
    if (!result.pairs_file.empty()) std::printf("pairs                      %s\n", result.pairs_file.c_str());
    if (!result.nodes_file.empty()) std::printf("nodes                      %s\n", result.nodes_file.c_str());
}

std::string json_summary(const RunRequest& request, const Model& model, const RunResult& result, const LoopFigures& loop) {
    const SimulationOptions& options = request.options;
    const RunStats& s = result.stats;
    const StepRecord& last = s.last;
    const bool cvode = options.mode == Mode::cvode;
    nlohmann::json j;
    j["setup"] = request.setup;
    j["interrupted"] = result.signal != 0;
    if (result.signal != 0) {
        j["signal"] = result.signal;
        j["interrupted_note"] = "stopped by a signal at t_reached_s: the rows up to it are in the .partial files "
                                "(kept under that name: not a complete run); no event log";
    }
    j["t_reached_s"] = last.t_s;
    j["mode"] = to_string(options.mode);
    j["solver"] = to_string(options.solver.kind);
    j["dt_s"] = options.dt_s;
    j["t_end_s"] = options.t_end_s;
    const FrictionMeshRatio kappa = friction_mesh_ratio(model);
    j["friction_mesh_ratio"] = {{"kappa", kappa.ratio},
                                {"interface", kappa.interface_index},
                                {"pair_spacing_m", kappa.pair_spacing_m},
                                {"spacing_for_kappa_one_m", kappa.spacing_for_one_m},
                                {"decay_length_m", kappa.decay_length_m},
                                {"elastic", kappa.elastic}};
    j["interfaces"] = interfaces_json(model);
    j["loading"] = {{"kind", to_string(options.loading.kind)},
                    {"gravity_m_per_s2", options.loading.gravity_m_per_s2},
                    {"period_s", options.loading.period_s()}};
    const RunReport& report = result.report;
    j["counts"] = {{"records", s.records},
                   {"steps", result.signal != 0 ? s.records - 1 : report.steps},
                   {"contact_iterations", result.signal != 0 ? s.contact_iterations : report.contact_iterations},
                   {"factorizations", report.factorizations},
                   {"events", report.events.size()}};
    if (cvode && result.signal == 0)
        j["cvode"] = {{"rtol", options.cvode.rtol},          {"atol_m", options.cvode.atol_m},
                      {"steps", report.cvode.steps},         {"rhs_evaluations", report.cvode.rhs_evaluations},
                      {"event_times", report.cvode.events},  {"missed_events", report.cvode.missed_events},
                      {"restarts", report.cvode.restarts}};
    if (cvode && report.cvode.retained_modes > 0) {
        j["cvode"]["retained_modes"] = report.cvode.retained_modes;
        j["cvode"]["modal_cutoff_rad_per_s"] = report.cvode.modal_cutoff_rad_per_s;
    }
    j["extremes"] = {{"w_min_m", s.w_min_m},
                     {"w_max_m", s.w_max_m},
                     {"spring_force_min_n", s.force_min_n},
                     {"spring_force_max_n", s.force_max_n}};
    j["final"] = {{"t_s", last.t_s}, {"w_m", last.w_m}, {"w_dot_m_per_s", last.w_dot_m_per_s}};
    j["energy_j"] = {{"initial", initial_energy(s)},
                     {"external_work", last.external_work_j},
                     {"dissipated", last.dissipated_energy_j},
                     {"kinetic", last.kinetic_energy_j},
                     {"strain", last.strain_energy_j},
                     {"balance_error_final", last.energy_balance_error_j},
                     {"balance_error_max_abs", s.max_abs_balance_j}};
    if (const auto& m = loop.metrics) {
        j["hysteresis"] = {{"t_start_s", m->t_start_s},
                           {"t_end_s", m->t_end_s},
                           {"loop_area_j", m->loop_area_j},
                           {"friction_work_j", m->dissipated_j},
                           {"secant_stiffness_n_per_m", m->secant_stiffness_n_per_m},
                           {"dynamic_rate_n_per_m", m->dynamic_rate_n_per_m},
                           {"loss_factor", m->loss_factor},
                           {"energy_loss_factor", m->energy_loss_factor},
                           {"equivalent_damping_ratio", m->equivalent_damping_ratio},
                           {"w_min_m", m->w_min_m},
                           {"w_max_m", m->w_max_m},
                           {"force_min_n", m->force_min_n},
                           {"force_max_n", m->force_max_n}};
    } else {
        j["hysteresis"] = nullptr;
        j["hysteresis_note"] = loop.note;
    }
    if (const auto& fit = loop.fancher) {
        const FancherParameters& p = fit->parameters;
        j["fancher"] = {{"upper_rate_n_per_m", p.upper_rate_n_per_m},
                        {"upper_offset_n", p.upper_offset_n},
                        {"lower_rate_n_per_m", p.lower_rate_n_per_m},
                        {"lower_offset_n", p.lower_offset_n},
                        {"beta_m", p.beta_m},
                        {"start_force_n", fit->start_force_n},
                        {"rms_error_n", fit->rms_error_n},
                        {"rms_error_relative", fit->rms_error_relative},
                        {"iterations", fit->iterations},
                        {"converged", fit->converged}};
    } else {
        j["fancher"] = nullptr;
        if (!loop.fancher_note.empty()) j["fancher_note"] = loop.fancher_note;
    }
    j["wall_time_s"] = result.wall_s;
    j["outputs"] = {{"csv", result.csv_file}, {"events", result.events_file}, {"pairs", result.pairs_file}, {"nodes", result.nodes_file}};
    return j.dump(2);
}

void write_json_summary(const RunRequest& request, const Model& model, const RunResult& result, const LoopFigures& loop) {
    const std::string partial = request.summary + ".partial";
    std::ofstream out(partial, std::ios::out | std::ios::trunc);
    if (!out) throw ArgumentError("--summary: cannot open '" + partial + "' for writing");
    out << json_summary(request, model, result, loop) << "\n";
    out.close();
    if (out.fail()) throw std::runtime_error("writing '" + partial + "' failed");
    if (std::rename(partial.c_str(), request.summary.c_str()) != 0)
        throw std::runtime_error("cannot rename '" + partial + "' to '" + request.summary + "'");
}

}  // namespace stackbeam::cli
