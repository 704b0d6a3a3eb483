// A run's JSON summary (run/summary_json.hpp), with nlohmann-json (private to the library).
#include "stackbeam/run/summary_json.hpp"

#include <cmath>

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

/// A number, null when it is not one (NaN), "infinite" for +infinity (a life without damage).
nlohmann::json number_json(double v) {
    if (std::isnan(v)) return nullptr;
    if (std::isinf(v)) return v > 0 ? "infinite" : "-infinite";
    return v;
}

nlohmann::json extreme_json(const StressExtreme& e) {
    return {{"stress_pa", number_json(e.stress_pa)}, {"x_m", number_json(e.x_m)}, {"t_s", number_json(e.t_s)}, {"fibre", to_string(e.fibre)}};
}

nlohmann::json spot_json(const FatigueSpot& s) {
    return {{"x_m", s.x_m}, {"fibre", to_string(s.fibre)}, {"amplitude_pa", s.amplitude_pa}, {"mean_pa", s.mean_pa}};
}

/// The stresses section (RunSummary::stresses): per leaf its extremes, the cycle's largest range
/// and, with a material, the least fatigue safety factor and the shortest life; per interface
/// the peak pressure. Stresses [Pa], x [m], t [s].
nlohmann::json stresses_json(const RunStresses& rs) {
    const StressSummary& s = rs.summary;
    nlohmann::json leaves = nlohmann::json::array();
    for (std::size_t l = 0; l < s.extremes.size(); ++l) {
        nlohmann::json leaf = {{"leaf", s.extremes[l].leaf},
                               {"largest_tension", extreme_json(s.extremes[l].tension)},
                               {"largest_compression", extreme_json(s.extremes[l].compression)}};
        if (l < s.cycle.size()) {  // the leaf's largest range over its nodes and fibres
            const LeafCycle& c = s.cycle[l];
            LargestRange r;
            r.leaf = c.leaf;
            for (std::size_t i = 0; i < c.x_m.size(); ++i)
                for (const Fibre f : {Fibre::top, Fibre::bottom}) {
                    const FibreCycle& fc = f == Fibre::top ? c.top[i] : c.bottom[i];
                    if (fc.range_pa > r.range_pa || std::isnan(r.x_m)) r = {c.leaf, c.x_m[i], f, fc.range_pa, fc.mean_pa};
                }
            leaf["cycle_largest_range"] = {{"range_pa", r.range_pa}, {"mean_pa", number_json(r.mean_pa)},
                                           {"x_m", number_json(r.x_m)}, {"fibre", to_string(r.fibre)}};
        }
        nlohmann::json fatigue = nullptr;
        if (l < s.fatigue.size() && s.fatigue[l].has_material) {
            const LeafFatigue& f = s.fatigue[l].fatigue;
            fatigue = {{"least_safety_factor", f.has_safety_factor ? number_json(f.least_safety_factor) : nullptr},
                       {"shortest_life_repetitions", f.has_life ? number_json(f.shortest_life_repetitions) : nullptr},
                       {"damage_per_repetition", f.has_life ? number_json(f.damage_per_repetition) : nullptr}};
            if (f.has_safety_factor) fatigue["safety_spot"] = spot_json(f.safety_spot);
            if (f.has_life) fatigue["life_spot"] = spot_json(f.life_spot);
        }
        leaf["fatigue"] = fatigue;
        leaves.push_back(leaf);
    }
    nlohmann::json interfaces = nlohmann::json::array();
    for (const InterfaceRunPeak& p : rs.interfaces)
        interfaces.push_back({{"interface", p.peak.interface_index},
                              {"peak_pressure_pa", p.peak.pressure_pa},
                              {"line_load_n_per_m", p.peak.line_load_n_per_m},
                              {"x_m", number_json(p.peak.x_m)},
                              {"t_s", number_json(p.t_s)}});
    const LargestRange& r = s.largest_range;
    return {{"samples", s.samples},
            {"cycle", {{"t_start_s", s.cycle_start_s},
                       {"t_end_s", s.cycle_end_s},
                       {"samples", s.cycle_samples},
                       {"counting", s.counting == CycleCounting::periodic ? "periodic" : "rainflow"},
                       {"largest_range", {{"leaf", r.leaf}, {"x_m", number_json(r.x_m)}, {"fibre", to_string(r.fibre)},
                                          {"range_pa", r.range_pa}, {"mean_pa", number_json(r.mean_pa)}}}}},
            {"leaves", leaves},
            {"interfaces", interfaces}};
}

/// A loop's figures as the "hysteresis" section names them, with its pair's own names (`x`: the
/// displacement's key with its unit, e.g. "seat_rotation_rad"; `f`: the force's; `rate`: the
/// stiffness's unit, e.g. "n_m_per_rad").
nlohmann::json loop_json(const HysteresisMetrics& m, const std::string& x, const std::string& f, const std::string& rate) {
    return {{"t_start_s", m.t_start_s},
            {"t_end_s", m.t_end_s},
            {"loop_area_j", m.loop_area_j},
            {"friction_work_j", m.dissipated_j},
            {"secant_stiffness_" + rate, m.secant_stiffness_n_per_m},
            {"dynamic_rate_" + rate, m.dynamic_rate_n_per_m},
            {"loss_factor", m.loss_factor},
            {"energy_loss_factor", m.energy_loss_factor},
            {"equivalent_damping_ratio", m.equivalent_damping_ratio},
            {x + "_min", m.w_min_m},
            {x + "_max", m.w_max_m},
            {f + "_min", m.force_min_n},
            {f + "_max", m.force_max_n}};
}

/// The windup section (RunSummary::windup; docs/windup.md, "The windup figures"): k_theta [N m/rad],
/// the loop's area [J per cycle] and loss factors, the longitudinal compliance [m/N], the vertical
/// rate [N/m]; null and a note for a figure the run does not give.
nlohmann::json windup_json(const WindupFigures& f) {
    nlohmann::json j;
    if (const auto& m = f.windup) {
        j["stiffness_n_m_per_rad"] = m->secant_stiffness_n_per_m;
        j["loop_area_j"] = m->loop_area_j;
        j["loss_factor"] = m->loss_factor;
        j["energy_loss_factor"] = m->energy_loss_factor;
        j["loop"] = loop_json(*m, "seat_rotation_rad", "seat_moment_n_m", "n_m_per_rad");
    } else {
        for (const char* k : {"stiffness_n_m_per_rad", "loop_area_j", "loss_factor", "energy_loss_factor", "loop"}) j[k] = nullptr;
        j["note"] = f.windup_note;
    }
    j["longitudinal_compliance_m_per_n"] = number_json(f.longitudinal_compliance_m_per_n);
    if (const auto& m = f.longitudinal) j["longitudinal_loop"] = loop_json(*m, "seat_axial_m", "longitudinal_force_n", "n_per_m");
    else {
        j["longitudinal_loop"] = nullptr;
        j["longitudinal_note"] = f.longitudinal_note;
    }
    j["vertical_rate_n_per_m"] = number_json(f.vertical_rate_n_per_m);
    if (const auto& t = f.tangent) {  // K_t over (w, theta_R, u_R): N/m, N/rad, N m/rad, ... (loop_figures.hpp)
        nlohmann::json matrix = nlohmann::json::array();
        for (const auto& row : t->matrix) matrix.push_back({number_json(row[0]), number_json(row[1]), number_json(row[2])});
        j["seat_tangent_stiffness"] = {{"t_s", t->t_s},
                                       {"stick", t->stick},
                                       {"slip", t->slip},
                                       {"open", t->open},
                                       {"dofs", {"w_m", "seat_rotation_rad", "seat_axial_m"}},
                                       {"matrix", matrix},
                                       {"vertical_rate_n_per_m", number_json(t->vertical_rate_n_per_m)}};
    } else {
        j["seat_tangent_stiffness"] = nullptr;
        j["seat_tangent_stiffness_note"] = f.tangent_note;
    }
    return j;
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
    // what Model::build changed in the spec (close clamps merged): only when it changed something
    if (!summary.model_adjustments.empty()) j["model_adjustments"] = summary.model_adjustments;
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
    j["windup"] = summary.windup ? windup_json(*summary.windup) : nullptr;
    if (summary.stresses) j["stresses"] = stresses_json(*summary.stresses);
    else if (!summary.stresses_note.empty()) {  // asked, none made
        j["stresses"] = nullptr;
        j["stresses_note"] = summary.stresses_note;
    }
    j["wall_time_s"] = summary.wall_s;
    j["outputs"] = {{"csv", context.csv_file},
                    {"events", context.events_file},
                    {"pairs", context.pairs_file},
                    {"nodes", context.nodes_file}};
    if (!context.stresses_file.empty()) j["outputs"]["stresses"] = context.stresses_file;
    return j.dump(2);
}

}  // namespace stackbeam
