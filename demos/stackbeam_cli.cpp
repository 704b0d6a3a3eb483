/// @file stackbeam_cli.cpp
/// `stackbeam`: the command line of the stackbeam library.
///
/// The physical problem: a leaf spring made of elastic leaves (Bernoulli-Euler
/// beams, massless) stacked on top of each other and held together by narrow
/// clamps. The leaves can slide on each other against Coulomb friction. A rigid
/// body R (the axle seat with its mass) is attached at midspan and starts moving
/// normal to the stack; the friction between the leaves makes the spring
/// hysteretic, so the vibration of R decays. This program simulates the built-in
/// example of Lee & Lim (1992), section 5: three leaves 0.5 x 0.05 x 0.005 m,
/// E = 2e10 Pa, pinned at both ends, four clamps at x = 0.1 ... 0.4 m, a 20 kg
/// body at midspan moving at 2 m/s, in one of three cases (bonded leaves,
/// friction mu = 0.5 with clamp force 1000 N, frictionless). Geometry:
/// ../shared/reference-example.md; signs and units: include/stackbeam/conventions.hpp.
///
///   stackbeam simulate --case friction --t-end 2 --out friction.csv
///   stackbeam simulate --case friction --mode cvode --rtol 1e-8 --events events.csv --out friction.csv
///   stackbeam simulate --scenario scenarios/paper_friction.toml   (any stack: scenarios/README.md;
///                      integrator options and --out given here override the file's)
///
/// writes one CSV row per time step (closed-form) or output time (cvode, every --dt),
/// columns of stackbeam::step_record_columns(); --events writes the cvode event log.
/// Every file is written to FILE.partial and renamed to FILE only when the whole run
/// succeeded. Exit status: 0 success, 2 bad input, 3 solver failure, 1 other errors.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <limits>
#include <set>
#include <string>
#include <utility>

#include "gnuplot.hpp"
#include "stackbeam/io/csv.hpp"
#include "stackbeam/time/cvode_stepper.hpp"
#include "stackbeam/errors.hpp"
#include "stackbeam/post/hysteresis.hpp"
#include "stackbeam/model/model.hpp"
#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/io/scenario.hpp"
#include "stackbeam/time/simulation.hpp"
#include "stackbeam/fe/system.hpp"

namespace {

constexpr int exit_ok = 0;
constexpr int exit_other = 1;
constexpr int exit_input = 2;
constexpr int exit_solver = 3;

/// Bad command-line input; reported like stackbeam::InputError.
struct ArgumentError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// Parses a finite double > 0 from `text`, all of it, or throws naming `option`.
double parse_positive(const std::string& option, const std::string& text, const char* unit) {
    const std::string allowed = std::string("must be a finite number > 0 [") + unit + "]";
    const char* begin = text.c_str();
    char* end = nullptr;
    errno = 0;
    const double value = std::strtod(begin, &end);
    if (text.empty() || end == begin || *end != '\0')
        throw ArgumentError(option + ": value '" + text + "' is not a number: " + allowed);
    if (!std::isfinite(value) || value <= 0.0)
        throw ArgumentError(option + ": value '" + text + "' is not allowed: " + allowed);
    if (errno == ERANGE)  // underflow to a denormal or zero
        throw ArgumentError(option + ": value '" + text + "' is out of range: " + allowed);
    return value;
}

/// --beam-density: a finite density >= 0 [kg/m^3] (0: massless leaves, the paper).
double parse_density(const std::string& option, const std::string& text) {
    if (text == "0") return 0.0;
    const char* begin = text.c_str();
    char* end = nullptr;
    const double value = std::strtod(begin, &end);
    if (text.empty() || end == begin || *end != '\0' || !std::isfinite(value) || value < 0.0)
        throw ArgumentError(option + ": value '" + text +
                            "' is not allowed: must be a finite number >= 0 [kg/m^3] (0: massless leaves, the paper)");
    return value;
}

/// Parses an integer >= 1 from `text`, all of it, or throws naming `option`.
int parse_count(const std::string& option, const std::string& text) {
    const std::string allowed = "must be an integer >= 1";
    const char* begin = text.c_str();
    char* end = nullptr;
    errno = 0;
    const long value = std::strtol(begin, &end, 10);
    if (text.empty() || end == begin || *end != '\0')
        throw ArgumentError(option + ": value '" + text + "' is not an integer: " + allowed);
    if (errno == ERANGE || value < 1 || value > std::numeric_limits<int>::max())
        throw ArgumentError(option + ": value '" + text + "' is not allowed: " + allowed);
    return static_cast<int>(value);
}

/// Text of the options of `simulate`, as given (defaults as documented).
struct SimulateArgs {
    std::string case_name;
    std::string scenario;
    std::string mode = "closed-form";
    std::string t_end = "0.6";
    std::string dt = "1e-3";
    std::string elements = "20";
    bool full_model = false;
    std::string tol = "2e-6";
    std::string solver;  // default: exact (closed-form), accelerated (cvode)
    std::string rtol = "1e-8";
    std::string atol = "1e-12";
    std::string max_step = "";
    std::string max_steps = "10000000";
    std::string modal_cutoff = "0";
    std::string restitution = "0";
    std::string events;
    std::string alpha_fraction = "0.9";
    std::string max_iterations = "200000";
    std::string contact_path = "auto";
    std::string beam_density = "0";
    std::string out;
    std::string summary;  ///< JSON summary file
    std::string pairs;    ///< per-pair CSV file
    std::string plot;     ///< PNG file prefix
    std::string gravity;  ///< g [m/s^2] on R
    bool quiet = false;
    std::set<std::string> given;  ///< the options given on the command line
};

/// A file written as FILE.partial and renamed to FILE when the whole run succeeded.
class PartialFile {
public:
    PartialFile(const std::string& path, const std::string& option) : path_(path), partial_(path + ".partial") {
        if (path_.empty()) return;
        stream_.open(partial_, std::ios::out | std::ios::trunc);
        if (!stream_) throw ArgumentError(option + ": cannot open '" + partial_ + "' for writing");
    }
    bool active() const { return !path_.empty(); }
    std::ofstream& stream() { return stream_; }
    const std::string& partial() const { return partial_; }
    /// Closes and renames; throws if writing failed.
    void commit() {
        if (!active()) return;
        stream_.close();
        if (stream_.fail()) throw std::runtime_error("writing '" + partial_ + "' failed");
        if (std::rename(partial_.c_str(), path_.c_str()) != 0)
            throw std::runtime_error("cannot rename '" + partial_ + "' to '" + path_ + "'");
    }
    /// Removes the partial file (bad input found before any result).
    void discard() {
        if (!active()) return;
        stream_.close();
        std::remove(partial_.c_str());
    }

private:
    std::string path_, partial_;
    std::ofstream stream_;
};

/// Progress on stderr when it is a terminal (and not --quiet): a line rewritten at
/// most every 0.2 s wall time.
class Progress {
public:
    Progress(bool enabled, double t_end_s) : enabled_(enabled && isatty(fileno(stderr)) != 0), t_end_(t_end_s) {}
    void update(double t_s) {
        if (!enabled_) return;
        const auto now = std::chrono::steady_clock::now();
        if (shown_ && now - last_ < std::chrono::milliseconds(200)) return;
        last_ = now;
        shown_ = true;
        std::fprintf(stderr, "\rstackbeam: t = %.4g of %.4g s (%3.0f %%)", t_s, t_end_, 100.0 * t_s / t_end_);
        std::fflush(stderr);
    }
    void finish() {
        if (enabled_ && shown_) std::fprintf(stderr, "\r%60s\r", "");
    }

private:
    bool enabled_;
    double t_end_;
    bool shown_ = false;
    std::chrono::steady_clock::time_point last_;
};

/// 1-based column of `name` in the records' CSV (for gnuplot).
int column_of(const std::string& name) {
    const auto cols = stackbeam::step_record_columns();
    for (std::size_t i = 0; i < cols.size(); ++i)
        if (cols[i] == name) return static_cast<int>(i) + 1;
    throw std::logic_error("no CSV column " + name);
}

/// PNG figures of a run with gnuplot from its CSV: displacement, forces, friction
/// force at the probe, and the loop (spring force against w). Returns the files
/// written, or a note why none were.
std::vector<std::string> plot_run(const std::string& csv, const std::string& prefix, std::string& note) {
    using namespace stackbeam::demo;
    if (!gnuplot_on_path()) {
        note = "gnuplot is not on PATH: no figures (install gnuplot-nox)";
        return {};
    }
    const auto terminal = png_terminal();
    if (!terminal) {
        note = "gnuplot has neither the pngcairo nor the png terminal: no figures";
        return {};
    }
    const std::string script_path = prefix + "_figures.gp";
    std::ofstream g(script_path);
    if (!g) throw ArgumentError("--plot: cannot write '" + script_path + "'");
    std::vector<std::string> files;
    auto fig = [&](const std::string& name, const std::string& title, const std::string& xl, const std::string& yl,
                   const std::string& curves) {
        files.push_back(prefix + "_" + name + ".png");
        g << "set output '" << files.back() << "'\nset title '" << title << "'\nset xlabel '" << xl
          << "'\nset ylabel '" << yl << "'\nplot " << curves << "\n";
    };
    const std::string f = "'" + csv + "'";
    const int t = column_of("t"), w = column_of("w"), fm = column_of("force_on_mass"),
              pf = column_of("probe_friction_force"), sf = column_of("spring_force"), ef = column_of("external_force"),
              yb = column_of("base_displacement");
    g << "set datafile separator ','\nset terminal " << *terminal << " size 1000,620\nset grid\nset key top right\n";
    fig("displacement", "displacement of R", "t [s]", "[mm]",
        f + " using " + std::to_string(t) + ":(1000*$" + std::to_string(w) + ") with lines lw 2 title 'w (deflection)', " +
            f + " using " + std::to_string(t) + ":(1000*($" + std::to_string(w) + "+$" + std::to_string(yb) +
            ")) with lines dt 2 title 'w + y_b (absolute)'");
    fig("force", "forces on R", "t [s]", "[N]",
        f + " using " + std::to_string(t) + ":" + std::to_string(sf) + " with lines lw 2 title 'spring force', " + f +
            " using " + std::to_string(t) + ":" + std::to_string(ef) + " with lines dt 2 title 'external force', " + f +
            " using " + std::to_string(t) + ":" + std::to_string(fm) + " with lines dt 3 title 'm d^2w/dt^2'");
    fig("friction", "friction force at the probe pair", "t [s]", "[N]",
        f + " using " + std::to_string(t) + ":" + std::to_string(pf) + " with lines lw 2 title 'p_t'");
    fig("loop", "force-deflection loop", "w [mm]", "spring force [N]",
        f + " using (1000*$" + std::to_string(w) + "):" + std::to_string(sf) + " with lines lw 1.5 notitle");
    g.close();
    if (!g) throw std::runtime_error("writing '" + script_path + "' failed");
    if (std::system(("gnuplot " + shell_quote(script_path)).c_str()) != 0) {
        note = "gnuplot failed on " + script_path;
        return {};
    }
    return files;
}

/// Sets the integrator options from the command line: all of them (with their
/// defaults) for --case, only those given explicitly over a scenario's values.
void apply_simulation_options(const SimulateArgs& a, bool only_given, stackbeam::SimulationOptions& options) {
    auto use = [&](const char* option) { return !only_given || a.given.count(option) > 0; };
    if (use("--mode")) options.mode = stackbeam::parse_mode(a.mode, "--mode");
    if (use("--dt")) options.dt_s = parse_positive("--dt", a.dt, "s");
    if (use("--t-end")) options.t_end_s = parse_positive("--t-end", a.t_end, "s");
    // cvode: by default the paper's projected iteration (eq. 17, E = per-pair block inverse) checks each step
    if (use("--solver"))
        options.solver.kind = stackbeam::parse_solver_kind(
            a.solver.empty() ? (options.mode == stackbeam::Mode::cvode ? "accelerated" : "exact") : a.solver, "--solver");
    if (use("--rtol")) options.cvode.rtol = parse_positive("--rtol", a.rtol, "-");
    if (use("--atol")) options.cvode.atol_m = parse_positive("--atol", a.atol, "m");
    if (use("--max-step") && !a.max_step.empty()) options.cvode.max_step_s = parse_positive("--max-step", a.max_step, "s");
    if (use("--max-steps")) options.cvode.max_steps = parse_count("--max-steps", a.max_steps);
    if (use("--restitution")) {
        options.restitution = a.restitution == "0" ? 0.0 : parse_positive("--restitution", a.restitution, "-; 0 to 1");
        if (options.restitution > 1.0)
            throw ArgumentError("--restitution: value '" + a.restitution +
                                "' is not allowed: the restitution coefficient must be in [0, 1]");
    }
    if (use("--modal-cutoff"))
        options.cvode.modal_cutoff_rad_per_s =
            a.modal_cutoff == "0" ? 0.0 : parse_positive("--modal-cutoff", a.modal_cutoff, "rad/s; 0: the default");
    if (use("--contact-path")) options.contact_path = stackbeam::parse_contact_path(a.contact_path, "--contact-path");
    if (use("--tol")) options.solver.tolerance_m = parse_positive("--tol", a.tol, "m");
    if (use("--alpha-fraction")) {
        options.solver.alpha_fraction = parse_positive("--alpha-fraction", a.alpha_fraction, "-");
        if (options.solver.alpha_fraction >= 1.0)
            throw ArgumentError("--alpha-fraction: value '" + a.alpha_fraction +
                                "' is not allowed: must be a number in (0, 1), a fraction of the stability bound");
    }
    if (use("--max-iterations")) options.solver.max_iterations = parse_count("--max-iterations", a.max_iterations);
}

int run_simulate(const SimulateArgs& a) {
    // --- validate every argument before any work ---------------------------------
    stackbeam::SimulationOptions options;
    stackbeam::ModelSpec spec;
    std::string out = a.out;
    std::string events = a.events;
    std::string summary = a.summary, pairs = a.pairs, plot = a.plot;
    std::string setup;  // first line of the summary
    if (!a.scenario.empty()) {
        // A scenario file; options given on the command line override its values.
        const stackbeam::Scenario scenario = stackbeam::load_scenario(a.scenario);
        spec = scenario.model;
        options = scenario.simulation;
        apply_simulation_options(a, true, options);
        if (out.empty()) out = scenario.outputs.csv_path;
        if (out.empty())
            throw ArgumentError("--out: an output file name is required (none given, and " + a.scenario +
                                " has no outputs.csv_path)");
        if (events.empty()) events = scenario.outputs.events_path;
        if (summary.empty()) summary = scenario.outputs.summary_path;
        if (pairs.empty()) pairs = scenario.outputs.pairs_path;
        if (plot.empty()) plot = scenario.outputs.plot_prefix;
        if (a.given.count("--beam-density"))
            for (auto& leaf : spec.leaves) leaf.density_kg_per_m3 = parse_density("--beam-density", a.beam_density);
        setup = "scenario " + a.scenario + (scenario.description.empty() ? "" : " (" + scenario.description + ")") + "\n";
    } else {
        if (a.case_name.empty()) throw ArgumentError("--case or --scenario: one of them is required");
        const stackbeam::PaperCase pcase = stackbeam::parse_paper_case(a.case_name, "--case");
        apply_simulation_options(a, false, options);
        stackbeam::PaperExampleOptions example;
        example.elements_per_half_leaf = parse_count("--elements", a.elements);
        example.symmetry = a.full_model ? stackbeam::Symmetry::full : stackbeam::Symmetry::half;
        if (out.empty()) throw ArgumentError("--out: an output file name is required");
        spec = stackbeam::paper_example(pcase, example);
        for (auto& leaf : spec.leaves) leaf.density_kg_per_m3 = parse_density("--beam-density", a.beam_density);
        setup = std::string("case ") + stackbeam::to_string(pcase) + ", " + std::to_string(example.elements_per_half_leaf) +
                " elements per half leaf (" + (a.full_model ? "full" : "half") + " model), ";
    }
    if (a.given.count("--gravity")) {
        // parse_positive refuses 0; gravity 0 is "none": accept it explicitly
        options.loading.gravity_m_per_s2 = a.gravity == "0" ? 0.0 : parse_positive("--gravity", a.gravity, "m/s^2");
    }
    if ((a.scenario.empty() || a.given.count("--beam-density")) && options.mode == stackbeam::Mode::closed_form &&
        parse_density("--beam-density", a.beam_density) > 0.0)
        throw ArgumentError("--beam-density: value '" + a.beam_density + "' needs --mode newmark (or cvode, bonded and "
                            "frictionless stacks so far): mode closed-form treats the leaves as massless, the paper");
    const bool cvode = options.mode == stackbeam::Mode::cvode;
    if (!cvode && !events.empty())
        throw ArgumentError("--events: the event log exists in mode cvode only (mode " +
                            std::string(stackbeam::to_string(options.mode)) + ")");
    options.validate();

    // --- build ----------------------------------------------------------------------
    const auto t0 = std::chrono::steady_clock::now();
    const stackbeam::Model model = stackbeam::Model::build(spec);
    const stackbeam::System system(model);
    if (const std::string advice = stackbeam::friction_mesh_advice(model); !advice.empty())
        std::cerr << "stackbeam: note: " << advice << "\n";
    const stackbeam::ContactPath path = stackbeam::choose_contact_path(system, options);

    // --- run, streaming rows to FILE.partial ----------------------------------------
    PartialFile csv(out, "--out");
    PartialFile pairs_csv(pairs, "--pairs");
    PartialFile json(summary, "--summary");
    stackbeam::write_csv_header(csv.stream());
    if (pairs_csv.active()) pairs_csv.stream() << "t,pair,interface,x,state,p_n,p_t,gap,slip\n";
    pairs_csv.stream().precision(17);

    long steps = -1;  // the first record is the initial state
    long total_iterations = 0;
    int max_iterations = 0;
    std::vector<stackbeam::StepRecord> records;
    stackbeam::RunReport report;
    Progress progress(!a.quiet, options.t_end_s);
    stackbeam::PairObserver on_pairs;
    if (pairs_csv.active())
        on_pairs = [&](double t, const std::vector<stackbeam::PairRecord>& prs) {
            auto& o = pairs_csv.stream();
            for (const auto& p : prs)
                o << t << ',' << p.pair << ',' << p.interface_index << ',' << p.x_m << ',' << stackbeam::to_string(p.state)
                  << ',' << p.p_n_n << ',' << p.p_t_n << ',' << p.gap_m << ',' << p.slip_m << '\n';
        };
    try {
        records = stackbeam::simulate(system, options, [&](const stackbeam::StepRecord& r) {
            stackbeam::write_csv_row(csv.stream(), r);
            ++steps;
            total_iterations += r.contact_iterations;
            max_iterations = std::max(max_iterations, r.contact_iterations);
            progress.update(r.t_s);
        }, &report, on_pairs);
        progress.finish();
    } catch (const stackbeam::InputError&) {
        // bad input found when the run starts (e.g. an option the mode cannot use): no rows to keep
        progress.finish();
        csv.discard();
        pairs_csv.discard();
        json.discard();
        throw;
    } catch (...) {
        progress.finish();
        csv.stream().flush();
        pairs_csv.stream().flush();
        json.discard();
        std::cerr << "stackbeam: note: " << out << " was not written; the rows up to the failure are in "
                  << csv.partial() << "\n";
        throw;
    }
    const stackbeam::StepRecord last = records.back();
    if (!events.empty()) {
        PartialFile ev(events, "--events");
        stackbeam::write_events_csv(ev.stream(), report.events);
        ev.commit();
    }
    csv.commit();
    pairs_csv.commit();
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    // --- loop figures: the last period of a periodic loading -------------------------
    std::optional<stackbeam::HysteresisMetrics> loop;
    std::string loop_note;
    if (options.loading.period_s() > 0.0) {
        try {
            const auto cyc = stackbeam::last_cycle(records, options.loading.period_s());
            loop = stackbeam::hysteresis_metrics(records, cyc.first, cyc.second);
        } catch (const stackbeam::InputError& e) {
            loop_note = e.what();
        }
    } else {
        loop_note = "no periodic loading: no steady cycle";
    }
    double max_balance = 0.0;
    for (const auto& r : records) max_balance = std::max(max_balance, std::abs(r.energy_balance_error_j));

    // --- summary ----------------------------------------------------------------------
    // the initial energy: the body's, and the leaves' in mode newmark (the first record)
    const double e0 = records.front().kinetic_energy_j + records.front().strain_energy_j;
    std::printf("%smode %s, solver %s, dt %g s, t_end %g s\n", setup.c_str(), stackbeam::to_string(options.mode),
                stackbeam::to_string(options.solver.kind), options.dt_s, options.t_end_s);
    if (cvode) {
        const auto& cs = report.cvode;
        std::printf("cvode                      rtol %g, atol %g m; %ld steps, %ld RHS evaluations, %ld root evaluations\n",
                    options.cvode.rtol, options.cvode.atol_m, cs.steps, cs.rhs_evaluations, cs.root_evaluations);
        std::printf("events                     %ld event times (%ld found by the per-step check), %zu transitions, "
                    "%ld restarts, %ld mode factorisations\n",
                    cs.events, cs.missed_events, report.events.size(), cs.restarts, cs.mode_factorizations);
        if (cs.retained_modes > 0)
            std::printf("leaf inertia               %d modes up to %g rad/s carry it, the rest quasi-static "
                        "(massless contact layer)\n",
                        cs.retained_modes, cs.modal_cutoff_rad_per_s);
        std::printf("outputs                    %ld (every %g s)\n", steps, options.dt_s);
    } else {
        std::printf("contact path               %s (%d contact components)\n", stackbeam::to_string(path),
                    system.num_components());
        std::printf("steps                      %ld\n", steps);
    }
    std::printf("contact iterations         total %ld, max per step %d, mean per step %.2f\n", total_iterations,
                max_iterations, steps > 0 ? static_cast<double>(total_iterations) / steps : 0.0);
    std::printf("final state                t %.6g s, w %.6g m, w_dot %.6g m/s\n", last.t_s, last.w_m,
                last.w_dot_m_per_s);
    std::printf("loading                    %s%s\n", stackbeam::to_string(options.loading.kind),
                options.loading.gravity_m_per_s2 > 0.0
                    ? (", gravity " + std::to_string(options.loading.gravity_m_per_s2) + " m/s^2").c_str()
                    : "");
    std::printf("energy balance error       %.3e J at the end, %.3e J largest (initial energy %.6g J, external work %.6g J, "
                "dissipated %.6g J)\n",
                last.energy_balance_error_j, max_balance, e0, last.external_work_j, last.dissipated_energy_j);
    if (loop) {
        std::printf("loop                       t %.6g to %.6g s: area %.6g J per cycle (friction work %.6g J), secant stiffness %.6g N/m,\n"
                    "                           dynamic rate %.6g N/m, loss factor %.4g, equivalent damping ratio %.4g\n",
                    loop->t_start_s, loop->t_end_s, loop->loop_area_j, loop->dissipated_j, loop->secant_stiffness_n_per_m,
                    loop->dynamic_rate_n_per_m, loop->loss_factor, loop->equivalent_damping_ratio);
    } else {
        std::printf("loop                       none (%s)\n", loop_note.c_str());
    }
    if (options.mode == stackbeam::Mode::newmark)
        std::printf("impact loss                %.6g J (kinetic energy of the leaves at the end %.6g J)\n",
                    last.impact_loss_j, last.leaf_kinetic_energy_j);
    std::printf("wall time                  %.3f s\n", wall_s);
    std::printf("output                     %s\n", out.c_str());
    if (!events.empty()) std::printf("event log                  %s\n", events.c_str());
    if (pairs_csv.active()) std::printf("pairs                      %s\n", pairs.c_str());
    if (!plot.empty()) {
        std::string note;
        const auto files = plot_run(out, plot, note);
        for (const auto& f : files) std::printf("figure                     %s\n", f.c_str());
        if (files.empty()) std::printf("figures                    none: %s\n", note.c_str());
    }
    if (json.active()) {
        nlohmann::json j;
        j["setup"] = setup;
        j["mode"] = stackbeam::to_string(options.mode);
        j["solver"] = stackbeam::to_string(options.solver.kind);
        j["dt_s"] = options.dt_s;
        j["t_end_s"] = options.t_end_s;
        const stackbeam::FrictionMeshRatio kappa = stackbeam::friction_mesh_ratio(model);
        j["friction_mesh_ratio"] = {{"kappa", kappa.ratio},
                                    {"interface", kappa.interface_index},
                                    {"pair_spacing_m", kappa.pair_spacing_m},
                                    {"spacing_for_kappa_one_m", kappa.spacing_for_one_m}};
        j["loading"] = {{"kind", stackbeam::to_string(options.loading.kind)},
                        {"gravity_m_per_s2", options.loading.gravity_m_per_s2},
                        {"period_s", options.loading.period_s()}};
        j["counts"] = {{"records", records.size()},
                       {"steps", report.steps},
                       {"contact_iterations", report.contact_iterations},
                       {"factorizations", report.factorizations},
                       {"events", report.events.size()}};
        if (cvode)
            j["cvode"] = {{"rtol", options.cvode.rtol},          {"atol_m", options.cvode.atol_m},
                          {"steps", report.cvode.steps},         {"rhs_evaluations", report.cvode.rhs_evaluations},
                          {"event_times", report.cvode.events},  {"missed_events", report.cvode.missed_events},
                          {"restarts", report.cvode.restarts}};
        if (cvode && report.cvode.retained_modes > 0) {
            j["cvode"]["retained_modes"] = report.cvode.retained_modes;
            j["cvode"]["modal_cutoff_rad_per_s"] = report.cvode.modal_cutoff_rad_per_s;
        }
        double wmin = last.w_m, wmax = last.w_m, fmin = last.spring_force_n, fmax = last.spring_force_n;
        for (const auto& r : records) {
            wmin = std::min(wmin, r.w_m);
            wmax = std::max(wmax, r.w_m);
            fmin = std::min(fmin, r.spring_force_n);
            fmax = std::max(fmax, r.spring_force_n);
        }
        j["extremes"] = {{"w_min_m", wmin}, {"w_max_m", wmax}, {"spring_force_min_n", fmin}, {"spring_force_max_n", fmax}};
        j["final"] = {{"t_s", last.t_s}, {"w_m", last.w_m}, {"w_dot_m_per_s", last.w_dot_m_per_s}};
        j["energy_j"] = {{"initial", e0},
                         {"external_work", last.external_work_j},
                         {"dissipated", last.dissipated_energy_j},
                         {"kinetic", last.kinetic_energy_j},
                         {"strain", last.strain_energy_j},
                         {"balance_error_final", last.energy_balance_error_j},
                         {"balance_error_max_abs", max_balance}};
        if (loop) {
            j["hysteresis"] = {{"t_start_s", loop->t_start_s},
                               {"t_end_s", loop->t_end_s},
                               {"loop_area_j", loop->loop_area_j},
                               {"friction_work_j", loop->dissipated_j},
                               {"secant_stiffness_n_per_m", loop->secant_stiffness_n_per_m},
                               {"dynamic_rate_n_per_m", loop->dynamic_rate_n_per_m},
                               {"loss_factor", loop->loss_factor},
                               {"energy_loss_factor", loop->energy_loss_factor},
                               {"equivalent_damping_ratio", loop->equivalent_damping_ratio},
                               {"w_min_m", loop->w_min_m},
                               {"w_max_m", loop->w_max_m},
                               {"force_min_n", loop->force_min_n},
                               {"force_max_n", loop->force_max_n}};
        } else {
            j["hysteresis"] = nullptr;
            j["hysteresis_note"] = loop_note;
        }
        j["wall_time_s"] = wall_s;
        j["outputs"] = {{"csv", out}, {"events", events}, {"pairs", pairs}};
        json.stream() << j.dump(2) << "\n";
        json.commit();
        std::printf("summary                    %s\n", summary.c_str());
    }
    return exit_ok;
}

/// The command-line option behind a library field, or "" if none.
std::string option_of_field(const std::string& field) {
    static const std::pair<const char*, const char*> map[] = {
        {"dt", "--dt"},
        {"t_end", "--t-end"},
        {"solver.tolerance_m", "--tol"},
        {"solver.alpha_fraction", "--alpha-fraction"},
        {"solver.max_iterations", "--max-iterations"},
        {"elements_per_half_leaf", "--elements"},
        {"rtol", "--rtol"},
        {"atol", "--atol"},
        {"max_step", "--max-step"},
        {"max_steps", "--max-steps"},
        {"modal_cutoff", "--modal-cutoff"},
        {"restitution", "--restitution"},
        {"contact_path", "--contact-path"},
    };
    for (const auto& [f, o] : map)
        if (field == f) return o;
    return "";
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"stackbeam: vibration of a stacked-beam leaf spring with Coulomb friction between the leaves\n"
                 "(Lee & Lim 1992, section 5 example: three leaves, four clamps, 20 kg body at 2 m/s)",
                 "stackbeam"};
    app.require_subcommand(1);
    app.footer("Examples:\n  stackbeam simulate --case friction --t-end 2 --out friction.csv\n"
               "  stackbeam simulate --scenario scenarios/paper_friction.toml\n"
               "Exit status: 0 success, 2 bad input, 3 solver failure, 1 other errors.");

    SimulateArgs a;
    CLI::App* sim = app.add_subcommand("simulate", "Simulate the paper example and write one CSV row per time step");
    CLI::Option* case_opt = sim->add_option("--case", a.case_name, "the paper example: bonded | friction | frictionless")->type_name("CASE");
    CLI::Option* scenario_opt =
        sim->add_option("--scenario", a.scenario,
                        "a scenario file (TOML, scenarios/README.md) instead of --case; options given here override its values")
            ->type_name("FILE.toml")
            ->excludes(case_opt);
    sim->add_option("--mode", a.mode,
                    "time stepping: closed-form (the paper's exact step, fixed dt) | cvode (SUNDIALS CVODE, "
                    "root-finding on every stick-slip and open-close transition) | newmark (leaves with mass, "
                    "--beam-density: average-acceleration Newmark, fixed dt)")
        ->type_name("MODE")
        ->capture_default_str();
    sim->add_option("--t-end", a.t_end, "end time [s]")->type_name("S")->capture_default_str();
    sim->add_option("--dt", a.dt, "time step [s] (closed-form); output interval [s] (cvode)")->type_name("S")->capture_default_str();
    sim->add_option("--rtol", a.rtol, "cvode: relative tolerance [-]")->type_name("R")->capture_default_str();
    sim->add_option("--atol", a.atol, "cvode: absolute tolerance on w [m]")->type_name("A")->capture_default_str();
    sim->add_option("--max-step", a.max_step, "cvode: largest internal step [s] (default: no limit)")->type_name("S");
    sim->add_option("--max-steps", a.max_steps, "cvode: limit on CVODE's steps over the run")->type_name("N")->capture_default_str();
    sim->add_option("--restitution", a.restitution,
                    "newmark with --beam-density: the impact law's normal restitution coefficient, 0 (inelastic) to 1 "
                    "(elastic) [-]")
        ->type_name("E")
        ->capture_default_str();
    sim->add_option("--modal-cutoff", a.modal_cutoff,
                    "cvode with --beam-density on a stack with friction: the stack's modes up to this circular frequency "
                    "carry the inertia, those above respond quasi-statically [rad/s] (0: 10 x the first; docs/inertia.md)")
        ->type_name("RAD_PER_S")
        ->capture_default_str();
    sim->add_option("--events", a.events, "cvode: write the event log (time, interface, x, pair, transition) to this CSV")
        ->type_name("FILE.csv");
    sim->add_option("--elements", a.elements, "--case: elements per half leaf")->type_name("N")->capture_default_str()->excludes(scenario_opt);
    sim->add_flag("--full-model", a.full_model, "--case: mesh the whole spring instead of the symmetric half")->excludes(scenario_opt);
    sim->add_option("--tol", a.tol, "contact tolerance on ||v||_2 [m]")->type_name("M")->capture_default_str();
    sim->add_option("--solver", a.solver,
                    "contact solver: exact | accelerated | block-jacobi | paper (default: exact in closed-form; "
                    "accelerated, the paper's iteration with a block E, checking each step in cvode)")
        ->type_name("SOLVER");
    sim->add_option("--alpha-fraction", a.alpha_fraction,
                    "paper solver: alpha as a fraction (0 < F < 1) of its stability bound 2/lambda_max(W)")
        ->type_name("F")
        ->capture_default_str();
    sim->add_option("--max-iterations", a.max_iterations, "iteration limit per step of the iterative solvers")
        ->type_name("N")
        ->capture_default_str();
    sim->add_option("--contact-path", a.contact_path,
                    "contact problem: auto (dense below " + std::to_string(stackbeam::kSparsePathMinComponents) +
                        " contact components, else sparse) | dense | sparse (exact solver only)")
        ->type_name("PATH")
        ->capture_default_str();
    sim->add_option("--summary", a.summary, "write a JSON summary (counts, energies, loop figures) to this file")
        ->type_name("FILE");
    sim->add_option("--pairs", a.pairs, "write every contact pair at every output time (forces, gap, slip) to this CSV")
        ->type_name("FILE");
    sim->add_option("--plot", a.plot, "draw PNG figures with gnuplot: PREFIX_displacement/force/friction/loop.png")
        ->type_name("PREFIX");
    sim->add_option("--gravity", a.gravity, "weight of R: gravity [m/s^2] (static equilibrium first; 0: none)")
        ->type_name("G");
    sim->add_flag("--quiet", a.quiet, "no progress line on the terminal");
    sim->add_option("--beam-density", a.beam_density,
                    "density of every leaf [kg/m^3]: 0 = massless leaves (the paper), > 0 = leaves with mass "
                    "(mode newmark; mode cvode on bonded and frictionless stacks so far)")
        ->type_name("KG_PER_M3")
        ->capture_default_str();
    sim->add_option("--out", a.out,
                    "output CSV file (written as FILE.partial, renamed when complete); required unless the scenario names one")
        ->type_name("FILE.csv");

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::cerr << "stackbeam: error: " << e.what() << "\n(run 'stackbeam --help' or 'stackbeam simulate --help')\n";
        return exit_input;
    }

    for (const CLI::Option* option : sim->get_options())
        if (option->count() > 0) a.given.insert(option->get_name());

    try {
        if (sim->parsed()) return run_simulate(a);
        return exit_other;
    } catch (const ArgumentError& e) {
        std::cerr << "stackbeam: error: " << e.what() << "\n";
        return exit_input;
    } catch (const stackbeam::InputError& e) {
        // The library names its field ("dt: ..."); say the option instead ("--dt: ...").
        const std::string option = option_of_field(e.field());
        std::string message = e.what();
        const std::string prefix = e.field() + ": ";
        if (!option.empty() && message.rfind(prefix, 0) == 0) message = option + ": " + message.substr(prefix.size());
        std::cerr << "stackbeam: error: " << message << "\n";
        return exit_input;
    } catch (const stackbeam::SolverError& e) {
        std::cerr << "stackbeam: error: solver failure at step " << e.step() << " (t = " << e.time_s()
                  << " s, residual " << e.residual() << "): " << e.what() << "\n";
        return exit_solver;
    } catch (const std::exception& e) {
        std::cerr << "stackbeam: error: " << e.what() << "\n";
        return exit_other;
    }
}
