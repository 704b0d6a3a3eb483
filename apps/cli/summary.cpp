// The results of a run: the text summary on stdout and the --summary JSON file.
#include "summary.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "stackbeam/errors.hpp"

namespace stackbeam::cli {

void print_summary(const SimulateRequest& request, const System& system, const RunResult& result) {
    const RunSummary& summary = result.summary;
    const SimulationOptions& options = summary.options;
    const RunStats& s = summary.stats;
    const LoopFigures& loop = summary.loop;
    const StepRecord& last = s.last;
    const long steps = s.records - 1;  // the first record is the initial state
    std::printf("%smode %s, solver %s, dt %g s, t_end %g s\n", request.setup.c_str(), to_string(options.mode),
                to_string(options.solver.kind), options.dt_s, options.t_end_s);
    if (summary.stepper.cvode_stats) {
        const auto& cs = summary.report.cvode;
        std::printf("cvode                      rtol %g, atol %g m; %ld steps, %ld RHS evaluations, %ld root evaluations\n",
                    options.cvode.rtol, options.cvode.atol_m, cs.steps, cs.rhs_evaluations, cs.root_evaluations);
        std::printf("events                     %ld event times (%ld found by the per-step check), %zu transitions, "
                    "%ld restarts, %ld mode factorisations\n",
                    cs.events, cs.missed_events, summary.report.events.size(), cs.restarts, cs.mode_factorizations);
        if (cs.retained_modes > 0)
            std::printf("leaf inertia               %d modes up to %g rad/s carry it, the rest quasi-static "
                        "(massless contact layer)\n",
                        cs.retained_modes, cs.modal_cutoff_rad_per_s);
        std::printf("outputs                    %ld (every %g s)\n", steps, options.dt_s);
    } else {
        std::printf("contact path               %s (%d contact components)\n",
                    to_string(summary.contact_path), summary.contact_components);
        std::printf("steps                      %ld\n", steps);
    }
    for (const std::string& note : summary.model_adjustments)  // Model::adjustments(): close clamps merged
        std::printf("model adjustment           %s\n", note.c_str());
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
                last.energy_balance_error_j, s.max_abs_balance_j, s.initial_energy_j(), last.external_work_j,
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
    if (const auto& wf = summary.windup) {  // docs/windup.md, "The windup figures"
        if (const auto& m = wf->windup)
            std::printf("windup loop                t %.6g to %.6g s: stiffness %.6g N m/rad, area %.6g J per cycle "
                        "(friction work %.6g J), loss factor %.4g\n",
                        m->t_start_s, m->t_end_s, m->secant_stiffness_n_per_m, m->loop_area_j, m->dissipated_j,
                        m->loss_factor);
        else
            std::printf("windup loop                none (%s)\n", wf->windup_note.c_str());
        if (wf->longitudinal)
            std::printf("longitudinal compliance    %.6g m/N\n", wf->longitudinal_compliance_m_per_n);
        if (!std::isnan(wf->vertical_rate_n_per_m))
            std::printf("vertical rate (same run)   %.6g N/m\n", wf->vertical_rate_n_per_m);
        if (const auto& t = wf->tangent)
            std::printf("seat tangent stiffness     at t %.6g s (%d stick, %d slip, %d open): k_ww %.6g N/m, k_theta %.6g N m/rad, "
                        "vertical rate (seat free to turn) %.6g N/m\n",
                        t->t_s, t->stick, t->slip, t->open, t->matrix[0][0], t->matrix[1][1], t->vertical_rate_n_per_m);
        else
            std::printf("seat tangent stiffness     none (%s)\n", wf->tangent_note.c_str());
    }
    if (summary.stepper.impact_loss)
        std::printf("impact loss                %.6g J (kinetic energy of the leaves at the end %.6g J)\n",
                    last.impact_loss_j, last.leaf_kinetic_energy_j);
    if (const auto& rs = summary.stresses)  // stresses [Pa], tension positive; x [m], t [s]
        for (const LeafExtremes& e : rs->summary.extremes)
            std::printf("stress leaf %-2d             largest tension %.6g Pa (x %.4g m, t %.6g s, %s fibre), "
                        "largest compression %.6g Pa (x %.4g m, t %.6g s, %s fibre)\n",
                        e.leaf, e.tension.stress_pa, e.tension.x_m, e.tension.t_s, to_string(e.tension.fibre),
                        e.compression.stress_pa, e.compression.x_m, e.compression.t_s, to_string(e.compression.fibre));
    else if (!summary.stresses_note.empty())
        std::printf("stresses                   none (%s)\n", summary.stresses_note.c_str());
    std::printf("wall time                  %.3f s\n", summary.wall_s);
    const SummaryContext& f = result.files;
    std::printf("output                     %s\n", f.csv_file.c_str());
    if (!f.events_file.empty()) std::printf("event log                  %s\n", f.events_file.c_str());
    if (!f.pairs_file.empty()) std::printf("pairs                      %s\n", f.pairs_file.c_str());
    if (!f.nodes_file.empty()) std::printf("nodes                      %s\n", f.nodes_file.c_str());
    if (!f.stresses_file.empty()) std::printf("stresses                   %s\n", f.stresses_file.c_str());
}

SummaryContext summary_context(const RunResult& result) {
    SummaryContext c = result.files;
    c.signal = result.signal;
    if (result.signal != 0)
        c.interrupted_note = "stopped by a signal at t_reached_s: the rows up to it are in the .partial files "
                             "(kept under that name: not a complete run); no event log";
    return c;
}

void write_json_summary(const SimulateRequest& request, const Model& model, const RunResult& result) {
    const std::string partial = request.summary + ".partial";
    std::ofstream out(partial, std::ios::out | std::ios::trunc);
    if (!out) throw ArgumentError("--summary: cannot open '" + partial + "' for writing");
    out << summary_json(result.summary, model, summary_context(result)) << "\n";
    out.close();
    if (out.fail()) throw std::runtime_error("writing '" + partial + "' failed");
    if (std::rename(partial.c_str(), request.summary.c_str()) != 0)
        throw std::runtime_error("cannot rename '" + partial + "' to '" + request.summary + "'");
}

}  // namespace stackbeam::cli
