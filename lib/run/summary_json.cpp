// A run's JSON summary (run/summary_json.hpp), with nlohmann-json (private to the library).
#include "stackbeam/run/summary_json.hpp"

#include <nlohmann/json.hpp>

namespace stackbeam {

namespace {

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

std::string summary_json(const RunSummary& summary, const Model& model, const SummaryContext& context) {
    const SimulationOptions& options = summary.options;
    const RunStats& s = summary.stats;
    const LoopFigures& loop = summary.loop;
    const bool interrupted = summary.interrupted;
    const StepRecord& last = s.last;
    const bool cvode = summary.stepper.cvode_stats;
    nlohmann::json j;
    j["setup"] = summary.setup;
    j["interrupted"] = interrupted;
    if (interrupted && context.signal != 0) j["signal"] = context.signal;
    if (interrupted && !context.interrupted_note.empty()) j["interrupted_note"] = context.interrupted_note;
    j["t_reached_s"] = summary.t_reached_s;
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
    const RunReport& report = summary.report;
    j["counts"] = {{"records", s.records},
                   {"steps", interrupted ? s.records - 1 : report.steps},
                   {"contact_iterations", interrupted ? s.contact_iterations : report.contact_iterations},
                   {"factorizations", report.factorizations},
                   {"events", report.events.size()}};
    if (cvode && !interrupted)
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
    j["energy_j"] = {{"initial", s.initial_energy_j()},
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
    j["wall_time_s"] = summary.wall_s;
    j["outputs"] = {{"csv", context.csv_file},
                    {"events", context.events_file},
                    {"pairs", context.pairs_file},
                    {"nodes", context.nodes_file}};
    return j.dump(2);
}

}  // namespace stackbeam
