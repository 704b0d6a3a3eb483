// `stackbeam fit SPEC.toml` (fit.hpp): the calibration of stackbeam/study/fit.hpp with its
// files. A stopped fit (SIGINT / SIGTERM) keeps DIR/history.csv; the same command again
// starts from its last accepted values (--restart: from the spec's starts).
#include "fit.hpp"

#include <nlohmann/json.hpp>

#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "gnuplot.hpp"
#include "options.hpp"
#include "stackbeam/study/fit.hpp"

namespace stackbeam::cli {

namespace {

namespace fs = std::filesystem;

std::atomic<bool> g_fit_stop{false};
std::atomic<int> g_fit_signal{0};
static_assert(std::atomic<bool>::is_always_lock_free, "the stop flag is set from a signal handler");

extern "C" void on_fit_signal(int signal) {
    g_fit_signal = signal;
    g_fit_stop = true;
}

std::string csv_number(double x) { return round_trip_text(x); }

/// The last accepted row of an earlier history.csv: its values, or empty.
std::vector<double> last_values(const fs::path& history, std::size_t n) {
    std::ifstream in(history);
    std::string line, last;
    std::getline(in, line);  // header
    while (std::getline(in, line)) {
        std::istringstream cells(line);
        std::string cell;
        std::vector<std::string> c;
        while (std::getline(cells, cell, ',')) c.push_back(cell);
        if (c.size() == 5 + n && c[3] == "1") last = line;
    }
    std::vector<double> values;
    if (last.empty()) return values;
    std::istringstream cells(last);
    std::string cell;
    for (int k = 0; std::getline(cells, cell, ','); ++k)
        if (k >= 5) values.push_back(std::strtod(cell.c_str(), nullptr));
    return values;
}

void write_outputs(const FitSpec& spec, const FitResult& r, const fs::path& dir, bool plot) {
    std::ofstream(dir / "fitted.toml") << "# " << spec.scenario_path << " with the values fitted by stackbeam fit "
                                       << spec.source << "\n" << r.fitted_scenario_text;
    {
        std::ofstream loops(dir / "loops.csv");
        loops << "loop,branch,w_m,measured_force_n,fitted_force_n\n";
        for (const FitLoopResult& l : r.loops)
            for (std::size_t i = 0; i < l.w_m.size(); ++i)
                loops << l.name << "," << l.branch[i] << "," << csv_number(l.w_m[i]) << "," << csv_number(l.measured_force_n[i])
                      << "," << csv_number(l.fitted_force_n[i]) << "\n";
    }
    nlohmann::ordered_json j;
    j["spec"] = spec.source;
    j["scenario"] = spec.scenario_path;
    auto number = [](double x) { return std::isfinite(x) ? nlohmann::ordered_json(x) : nlohmann::ordered_json(nullptr); };
    for (const FitParameterResult& p : r.parameters)
        j["parameters"].push_back({{"key", p.key}, {"value", p.value}, {"standard_error", number(p.standard_error)},
                                   {"lower", p.lower}, {"upper", p.upper}, {"at_bound", p.at_bound},
                                   {"identifiable", p.identifiable}, {"note", p.note}});
    for (const auto& row : r.correlation) {
        nlohmann::ordered_json a = nlohmann::ordered_json::array();
        for (double x : row) a.push_back(number(x));
        j["correlation"].push_back(a);
    }
    j["warnings"] = r.warnings;
    j["cost"] = r.cost;
    j["residual_count"] = r.residual_count;
    j["runs"] = r.runs;
    j["iterations"] = r.iterations;
    j["best_start"] = r.best_start;
    j["converged"] = r.converged;
    j["stopped"] = r.stopped;
    j["termination"] = r.termination;
    for (const FitLoopResult& l : r.loops)
        j["loops"].push_back({{"name", l.name}, {"rms_force_error_n", l.rms_force_error_n},
                              {"loop_area_j", {{"measured", l.measured_area_j}, {"fitted", l.fitted_area_j}}},
                              {"secant_stiffness_n_per_m", {{"measured", l.measured_secant_n_per_m}, {"fitted", l.fitted_secant_n_per_m}}},
                              {"dynamic_rate_n_per_m", {{"measured", l.measured_dynamic_rate_n_per_m}, {"fitted", l.fitted_dynamic_rate_n_per_m}}}});
    std::ofstream(dir / "fit.json") << j.dump(2) << "\n";
    if (!plot) return;
    if (!gnuplot::gnuplot_on_path()) {
        std::printf("figure                     none: gnuplot not found (loops.csv has the loops)\n");
        return;
    }
    const auto terminal = gnuplot::png_terminal();
    if (!terminal) return;
    std::ofstream gp(dir / "loops.gp");
    gp << "set terminal " << *terminal << " size 900,650\nset output 'loops.png'\nset datafile separator ','\n"
       << "set key top left\nset grid\nset xlabel 'w [mm]'\nset ylabel 'F [N]'\nset title 'measured and fitted loops'\nplot ";
    for (std::size_t l = 0; l < r.loops.size(); ++l) {
        const std::string name = r.loops[l].name;
        gp << (l ? ", " : "") << "'loops.csv' using (strcol(1) eq '" << name << "' ? 1000*$3 : NaN):4 with points pt 7 ps 0.4 title '"
           << name << " measured', 'loops.csv' using (strcol(1) eq '" << name << "' ? 1000*$3 : NaN):5 with points pt 1 ps 0.5 title '"
           << name << " fitted'";
    }
    gp << "\n";
    gp.close();
    const std::string command = "cd " + gnuplot::shell_quote(dir.string()) + " && gnuplot loops.gp >/dev/null 2>&1";
    if (std::system(command.c_str()) == 0) std::printf("figure                     %s\n", (dir / "loops.png").c_str());
}

}  // namespace

CLI::App* add_fit_command(CLI::App& app, FitArgs& args) {
    CLI::App& fit = *app.add_subcommand("fit", "Fit scenario keys (friction, interface stiffness, preload, ...) to measured "
                                               "force-displacement loops (docs/calibration.md)");
    fit.add_option("spec", args.spec, "The fit spec (TOML): base scenario, measured loops, parameters (docs/calibration.md)")->required();
    fit.add_option("--jobs,-j", args.jobs, "Threads for the runs (0: the machine's cores)")->check(CLI::Range(0, 1024));
    fit.add_option("--out-dir", args.out_dir, "Output directory (default: the spec's [outputs] directory, else SPEC_fit)");
    fit.add_flag("--restart", args.restart, "Start from the spec's starting values, not from an earlier history.csv");
    fit.add_flag("--no-plot", args.no_plot, "No gnuplot figure");
    fit.add_option("--stop-after", args.stop_after, "tests: stop as on SIGINT after this many iterations")
        ->check(CLI::Range(0, 1000000));
    return &fit;
}

int run_fit_command(const FitArgs& args) {
    const FitSpec spec = load_fit_spec(args.spec);  // every input checked before any run
    fs::path dir = !args.out_dir.empty() ? fs::path(args.out_dir)
                   : !spec.output_directory.empty() ? fs::path(spec.output_directory)
                                                     : fs::path(fs::path(args.spec).stem().string() + "_fit");
    fs::create_directories(dir);
    const fs::path history_path = dir / "history.csv";
    FitOptions options;
    options.jobs = args.jobs;
    options.stop = &g_fit_stop;
    const bool resume = !args.restart && fs::exists(history_path);
    if (resume) {
        options.start_values = last_values(history_path, spec.parameters.size());
        if (!options.start_values.empty()) {
            std::printf("resuming from %s's last accepted values:", history_path.c_str());
            for (double x : options.start_values) std::printf(" %s", round_trip_text(x).c_str());
            std::printf(" (--restart: from the spec's starts)\n");
        }
    }
    std::ofstream history(history_path, resume ? std::ios::app : std::ios::trunc);
    if (!resume || fs::file_size(history_path) == 0) {
        history << "start,iteration,cost,accepted,runs";
        for (const auto& p : spec.parameters) history << "," << p.key;
        history << "\n";
    }
    int iterations = 0;
    options.on_iteration = [&](const FitIteration& it) {
        history << it.start << "," << it.iteration << "," << csv_number(it.cost) << "," << (it.accepted ? 1 : 0) << ","
                << it.runs;
        for (double x : it.values) history << "," << csv_number(x);
        history << "\n" << std::flush;
        std::printf("start %d iteration %3d  cost %-12.6g runs %4d ", it.start, it.iteration, it.cost, it.runs);
        for (std::size_t j = 0; j < it.values.size(); ++j)
            std::printf(" %s = %.6g", spec.parameters[j].key.c_str(), it.values[j]);
        std::printf("%s\n", it.accepted ? "" : "  (step rejected)");
        std::fflush(stdout);
        if (args.stop_after > 0 && ++iterations >= args.stop_after) g_fit_stop = true;
    };
    std::signal(SIGINT, on_fit_signal);
    std::signal(SIGTERM, on_fit_signal);
    const FitResult r = fit(spec, options);
    history.close();
    if (r.stopped) {
        std::printf("stopped: %s keeps the iterations; run the same command again to resume\n", history_path.c_str());
        return 128 + (g_fit_signal != 0 ? g_fit_signal.load() : SIGINT);  // --stop-after: as SIGINT
    }
    std::printf("\nfit of %s (%d runs, %d iterations, start %d of %d): %s\n", spec.source.c_str(), r.runs, r.iterations,
                r.best_start + 1, resume ? 1 : spec.starts, r.termination.c_str());
    for (const FitParameterResult& p : r.parameters)
        std::printf("  %-45s %-14.8g +- %-12.4g%s\n", p.key.c_str(), p.value, p.standard_error,
                    p.identifiable ? "" : "  NOT IDENTIFIABLE");
    std::printf("  residual: sum r^2/2 = %.6g over %d residuals\n", r.cost, r.residual_count);
    for (const FitLoopResult& l : r.loops)
        std::printf("  %s: RMS force error %.4g N; loop area %.5g J measured, %.5g J fitted\n", l.name.c_str(),
                    l.rms_force_error_n, l.measured_area_j, l.fitted_area_j);
    for (const std::string& w : r.warnings) std::printf("warning: %s\n", w.c_str());
    write_outputs(spec, r, dir, !args.no_plot);
    std::printf("outputs                    %s/ (fitted.toml, fit.json, history.csv, loops.csv)\n", dir.c_str());
    return exit_ok;
}

}  // namespace stackbeam::cli
