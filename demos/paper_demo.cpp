/// @file paper_demo.cpp
/// The main job of stackbeam: the example of Lee & Lim (1992), section 5.
///
/// The physical problem: a leaf spring of three identical steel-like leaves
/// (0.5 m long, 0.05 m wide, 0.005 m high, E = 2e10 Pa, massless), stacked and
/// pinned at both ends, held together by four narrow clamps at x = 0.1, 0.2,
/// 0.3, 0.4 m (clamp force 1000 N). A rigid body of 20 kg is attached at
/// midspan and starts at w = 0 with a velocity of 2 m/s normal to the stack.
/// Three cases of the interface law between the leaves:
///   bonded        leaves tied together: one beam 0.015 m high (analytic sinusoid)
///   friction      Coulomb friction mu = 0.5: hysteresis, decaying vibration
///   frictionless  mu = 0: three beams side by side (analytic sinusoid)
/// Geometry as read in docs/method.md (section 5); signs: include/stackbeam/conventions.hpp.
///
/// For each case it runs both time-stepping modes with the paper's settings
/// (t_end 0.6 s, 2.0 s for friction):
///   closed-form  the paper's exact step with linearly interpolated contact forces, dt = 1e-3 s
///   cvode        SUNDIALS CVODE between contact events (rtol 1e-8), root-finding on every
///                stick-slip and open-close transition, output every 1e-3 s
/// and prints a comparison table per case (max deviation between the modes, deviation
/// from a reference, steps, right-hand sides, contact iterations, events, wall time,
/// energy balance), writes the time series (and cvode's event log) as CSV to
/// --out-dir and, if gnuplot is on PATH, PNG figures with both modes overlaid.
/// References: bonded/frictionless, the sinusoid of the discretised stiffness (and
/// the one-beam analytic values for comparison); friction, a closed-form run at dt = 1e-4 s.
///
///   paper_demo [--out-dir DIR]      (default out/)
///
/// Exit status: 0 success, 1 a run or a figure failed, 2 bad arguments.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "gnuplot.hpp"
#include "stackbeam/io/csv.hpp"
#include "stackbeam/time/cvode_stepper.hpp"
#include "stackbeam/errors.hpp"
#include "stackbeam/post/hysteresis.hpp"
#include "stackbeam/fe/modal.hpp"
#include "stackbeam/model/model.hpp"
#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/time/simulation.hpp"
#include "stackbeam/fe/system.hpp"

namespace fs = std::filesystem;
using stackbeam::Mode;
using stackbeam::PaperCase;
using stackbeam::StepRecord;

namespace {

const stackbeam::PaperExampleOptions kExample{};  // the paper's settings
const double kMass = kExample.mass_kg;               // m [kg], 20
const double kVelocity = kExample.initial_velocity_m_per_s;  // v0 [m/s], 2
constexpr double kDtPaper = 1e-3;   // [s]
constexpr double kDtFine = 1e-4;    // friction reference [s]
constexpr double kDtCheck = 2e-4;   // checks that the reference has converged [s]
constexpr double kRtol = 1e-8;      // cvode's relative tolerance [-]

/// The time-stepping modes run for every case.
const std::vector<Mode> kModes = {Mode::closed_form, Mode::cvode};
const std::vector<PaperCase> kCases = {PaperCase::bonded, PaperCase::friction, PaperCase::frictionless};

double t_end_of(PaperCase c) { return c == PaperCase::friction ? 2.0 : 0.6; }

/// One simulation and what the table reports about it.
struct Run {
    PaperCase pcase{};
    Mode mode{};
    double dt_s = 0.0;
    bool ok = false;
    std::string error;
    std::vector<StepRecord> records;
    long total_iterations = 0;
    int max_iterations = 0;
    double wall_s = 0.0;
    stackbeam::RunReport report;  ///< steps, counters and (cvode) the event log
    double k_discretised = 0.0;  ///< tied (bonded) or free (frictionless) stiffness of the mesh [N/m]
    std::string csv_file;        ///< name inside the output directory ("" if none)
    long steps() const { return records.empty() ? 0 : static_cast<long>(records.size()) - 1; }
};

Run run_case(PaperCase c, Mode mode, double dt_s, double t_end_s) {
    Run run;
    run.pcase = c;
    run.mode = mode;
    run.dt_s = dt_s;
    const auto t0 = std::chrono::steady_clock::now();
    try {
        const stackbeam::Model model = stackbeam::Model::build(stackbeam::paper_example(c));
        const stackbeam::System system(model);
        run.k_discretised = c == PaperCase::bonded ? system.tied_stiffness_n_per_m() : system.free_stiffness_n_per_m();
        stackbeam::SimulationOptions options;
        options.mode = mode;
        options.dt_s = dt_s;
        options.t_end_s = t_end_s;
        options.cvode.rtol = kRtol;
        // cvode: the paper's projected iteration (eq. 17, E = per-pair block inverse) checks each step
        if (mode == Mode::cvode) options.solver.kind = stackbeam::SolverKind::accelerated;
        // Collected as they are made, so a failed run still has its records up to the failure.
        stackbeam::simulate(system, options, [&run](const StepRecord& r) { run.records.push_back(r); }, &run.report);
        for (std::size_t i = 1; i < run.records.size(); ++i) {
            run.total_iterations += run.records[i].contact_iterations;
            run.max_iterations = std::max(run.max_iterations, run.records[i].contact_iterations);
        }
        run.ok = true;
    } catch (const stackbeam::SolverError& e) {
        std::ostringstream s;
        s << "solver failure at step " << e.step() << " (t = " << e.time_s() << " s, residual " << e.residual()
          << "): " << e.what();
        run.error = s.str();
    } catch (const std::exception& e) {
        run.error = e.what();
    }
    run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return run;
}

/// Max over the records of |w(t) - v0/omega sin(omega t)|, omega = sqrt(k/m) [m].
double max_deviation_from_sinusoid(const std::vector<StepRecord>& records, double k) {
    const double omega = std::sqrt(k / kMass);
    double dev = 0.0;
    for (const auto& r : records) dev = std::max(dev, std::abs(r.w_m - kVelocity / omega * std::sin(omega * r.t_s)));
    return dev;
}

/// w of `fine` at time t, linear interpolation between its records.
double interpolate_w(const std::vector<StepRecord>& fine, double t) {
    auto it = std::lower_bound(fine.begin(), fine.end(), t, [](const StepRecord& r, double x) { return r.t_s < x; });
    if (it == fine.begin()) return it->w_m;
    if (it == fine.end()) return fine.back().w_m;
    const auto& b = *it;
    const auto& a = *(it - 1);
    const double s = (t - a.t_s) / (b.t_s - a.t_s);
    return a.w_m + s * (b.w_m - a.w_m);
}

/// Max over the records of `coarse` (up to the end of `fine`) of |w - w_fine| [m].
double max_deviation_from_run(const std::vector<StepRecord>& coarse, const std::vector<StepRecord>& fine) {
    double dev = 0.0;
    for (const auto& r : coarse)
        if (r.t_s <= fine.back().t_s + 1e-12) dev = std::max(dev, std::abs(r.w_m - interpolate_w(fine, r.t_s)));
    return dev;
}

double max_abs_w(const std::vector<StepRecord>& records) {
    double m = 0.0;
    for (const auto& r : records) m = std::max(m, std::abs(r.w_m));
    return m;
}

/// Writes `records` to dir/name via dir/name.partial (renamed when complete).
void write_csv_file(const fs::path& dir, const std::string& name, const std::vector<StepRecord>& records) {
    const fs::path final_path = dir / name;
    const fs::path partial = dir / (name + ".partial");
    {
        std::ofstream out(partial, std::ios::out | std::ios::trunc);
        if (!out) throw std::runtime_error("cannot open '" + partial.string() + "' for writing");
        stackbeam::write_csv(out, records);
        out.close();
        if (out.fail()) throw std::runtime_error("writing '" + partial.string() + "' failed");
    }
    fs::rename(partial, final_path);
}

std::string csv_name(PaperCase c, Mode m, const std::string& suffix = "") {
    return std::string(stackbeam::to_string(c)) + "_" + stackbeam::to_string(m) + suffix + ".csv";
}

// --- gnuplot -----------------------------------------------------------------------

using stackbeam::gnuplot::gnuplot_on_path;
using stackbeam::gnuplot::png_terminal;
using stackbeam::gnuplot::shell_quote;

/// A gnuplot script drawing the figures from the CSV files in the same directory,
/// both modes overlaid (closed-form solid, cvode dashed).
/// Columns (1-based): 1 t, 2 w, 3 w_dot, 4 force_on_mass, 5 probe_friction_force.
/// `figures` receives the names of the PNG files the script writes.
std::string figure_script(const std::string& terminal, const std::map<PaperCase, std::vector<const Run*>>& runs,
                          const std::string& friction_reference_csv, std::vector<std::string>& figures) {
    std::ostringstream g;
    const auto output = [&](const std::string& png) {
        figures.push_back(png);
        return "\nset output '" + png + "'\n";
    };
    g << "# generated by paper_demo: figures of the paper's section 5 example, both modes\n"
      << "set datafile separator ','\n"
      << "set terminal " << terminal << (terminal == "pngcairo" ? " enhanced font 'Sans,11'" : " enhanced")
      << " size 1000,620\n"
      << "set grid\nset key inside top right box opaque\n"
      << "# head room above the curves for the key\n"
      << "set offsets 0, 0, graph 0.25, 0\n";
    // one curve per mode: closed-form solid blue, cvode dashed orange
    const auto mode_curves = [&](const std::vector<const Run*>& rs, const std::string& using_expr,
                                 const std::string& what) {
        std::ostringstream s;
        bool first = true;
        for (const Run* r : rs) {
            const bool cv = r->mode == Mode::cvode;
            s << (first ? "" : ", ") << "'" << r->csv_file << "' using " << using_expr << " with lines lw "
              << (cv ? "1.5 dt 2 lc rgb '#ff7f0e'" : "2 lc rgb '#1f77b4'") << " title '" << what
              << (cv ? "cvode (rtol 1e-8)" : "closed-form (dt = 1 ms)") << "'";
            first = false;
        }
        return s.str();
    };
    const auto sinusoid_curve = [&](const Run& run, const char* label) {
        const double k = run.k_discretised;
        const double omega = std::sqrt(k / kMass);
        const auto analytic = stackbeam::paper_analytic(run.pcase);
        std::ostringstream s;
        s << ", 1000*" << kVelocity / omega << "*sin(" << omega << "*x) with lines lw 1 dt 3 lc rgb '#d62728' title "
          << "sprintf('" << label << " (k = %.0f N/m, omega = %.3f rad/s)', " << k << ", " << omega << ")"
          << ", 1000*" << analytic.amplitude_m << "*sin(" << analytic.omega_rad_per_s
          << "*x) with lines lw 1 dt 4 lc rgb '#2ca02c' title "
          << "sprintf('one-beam analytic (k = %.0f N/m)', " << analytic.stiffness_n_per_m << ")";
        return s.str();
    };
    for (PaperCase c : {PaperCase::bonded, PaperCase::frictionless}) {
        const auto it = runs.find(c);
        if (it == runs.end() || it->second.empty()) continue;
        const std::string name = stackbeam::to_string(c);
        g << output("fig_displacement_" + name + ".png")
          << "set title \"Displacement of the 20 kg body, " << name << " case (three leaves)\"\n"
          << "set xlabel 'time t [s]'\nset ylabel 'displacement w [mm]'\nset samples 2000\n"
          << "plot " << mode_curves(it->second, "1:($2*1000)", "stackbeam, ")
          << sinusoid_curve(*it->second.front(), "analytic, mesh stiffness") << "\n";
    }
    const auto fr = runs.find(PaperCase::friction);
    if (fr != runs.end() && !fr->second.empty()) {
        const auto& rs = fr->second;
        g << output("fig_displacement_friction.png")
          << "set title \"Displacement of the 20 kg body, friction case (mu = 0.5, clamp force 1000 N)\"\n"
          << "set xlabel 'time t [s]'\nset ylabel 'displacement w [mm]'\n"
          << "plot " << mode_curves(rs, "1:($2*1000)", "stackbeam, ");
        if (!friction_reference_csv.empty())
            g << ", '" << friction_reference_csv
              << "' using 1:($2*1000) with lines lw 1 dt 3 lc rgb '#d62728' title 'reference, closed-form dt = 0.1 ms'";
        g << "\n";
        g << output("fig_friction_force_friction.png")
          << "set title \"Friction force on the upper interface at the left clamp (x = 0.1 m), friction case\"\n"
          << "set xlabel 'time t [s]'\nset ylabel 'tangential contact force p_t [N] (> 0 pushes the upper leaf in +x)'\n"
          << "plot " << mode_curves(rs, "1:5", "p_t at the probe pair, ") << "\n";
        g << output("fig_hysteresis_friction.png")
          << "set title \"Force on the body vs its displacement, friction case (hysteresis loop, 0 - 2 s)\"\n"
          << "set xlabel 'displacement w [mm]'\nset ylabel 'force on the body m d^2w/dt^2 [N]'\n"
          << "plot " << mode_curves(rs, "($2*1000):4", "");
        // The frictionless stack's line -k w for comparison (the bonded line is 9x steeper and
        // would squash the loop).
        const auto fl = runs.find(PaperCase::frictionless);
        if (fl != runs.end() && !fl->second.empty())
            g << ", '" << fl->second.front()->csv_file << "' using ($2*1000):4 with lines lw 1 lc rgb '#7f7f7f' title "
              << "'frictionless stack (k = 12,000 N/m), for comparison'";
        g << "\n";
    }
    if (!runs.empty()) {
        g << output("fig_displacement_all.png")
          << "set title 'Displacement of the 20 kg body, the three cases (solid: closed-form, dashed: cvode)'\n"
          << "set xlabel 'time t [s]'\nset ylabel 'displacement w [mm]'\nset xrange [0:0.6]\nplot ";
        const char* colours[] = {"#1f77b4", "#d62728", "#2ca02c"};
        int i = 0;
        bool first = true;
        for (const auto& [c, rs] : runs) {
            for (const Run* r : rs) {
                const bool cv = r->mode == Mode::cvode;
                g << (first ? "" : ", ") << "'" << r->csv_file << "' using 1:($2*1000) with lines lw "
                  << (cv ? "1.5 dt 2" : "2") << " lc rgb '" << colours[i % 3] << "' title '" << stackbeam::to_string(c)
                  << ", " << stackbeam::to_string(r->mode) << "'";
                first = false;
            }
            ++i;
        }
        g << "\nset xrange [*:*]\n";
    }
    g << "unset output\n";
    return g.str();
}

void print_usage(std::ostream& os) {
    os << "usage: paper_demo [--out-dir DIR] [--beam-density KG_PER_M3]\n"
          "Runs the paper's section 5 example (three leaves, four clamps, 20 kg body at 2 m/s) in the\n"
          "bonded, friction and frictionless cases; prints a table, writes CSV time series and, if gnuplot\n"
          "is on PATH, PNG figures to DIR (default out/). Then a rig test of the friction spring (its\n"
          "hysteresis loop). With --beam-density > 0 also the three cases with leaves of that density\n"
          "(mode newmark) against the massless runs and the eigen-solve.\n";
}

/// Mean circular frequency [rad/s] from the upward zero crossings of w (w(0) = 0 rising counts).
double measured_omega(const std::vector<StepRecord>& r) {
    std::vector<double> t{0.0};
    for (std::size_t i = 1; i < r.size(); ++i)
        if (r[i - 1].w_m < 0.0 && r[i].w_m >= 0.0)
            t.push_back(r[i - 1].t_s + (r[i].t_s - r[i - 1].t_s) * (-r[i - 1].w_m) / (r[i].w_m - r[i - 1].w_m));
    if (t.size() < 2) return 0.0;
    return 2.0 * M_PI * static_cast<double>(t.size() - 1) / (t.back() - t.front());
}

/// First maximum of w [m] (the first peak of the response).
double first_peak(const std::vector<StepRecord>& r) {
    for (std::size_t i = 1; i + 1 < r.size(); ++i)
        if (r[i].w_m >= r[i - 1].w_m && r[i].w_m > r[i + 1].w_m) return r[i].w_m;
    return 0.0;
}

/// The rig test of the friction spring: +-20 mm triangle stroke at 1 Hz, three cycles,
/// the last one's loop figures (hysteresis.hpp). Writes rig_friction.csv. False on failure.
bool rig_section(const fs::path& out_dir) {
    std::printf("Rig test of the friction spring: the rig holds R and strokes it +-20 mm (triangle, 1 Hz, constant\n"
                "speed), 3 cycles, closed-form quasi-static steps of 1 ms; the last cycle's loop:\n");
    try {
        stackbeam::PaperExampleOptions o;
        o.initial_velocity_m_per_s = 0.0;
        const stackbeam::System system(stackbeam::Model::build(stackbeam::paper_example(PaperCase::friction, o)));
        stackbeam::SimulationOptions options;
        options.dt_s = 1e-3;
        options.t_end_s = 3.0;
        options.solver.tolerance_m = 1e-9;
        options.loading.kind = stackbeam::LoadingKind::prescribed_displacement;
        options.loading.displacement_m.shape = stackbeam::TimeFunction::Shape::triangle;
        options.loading.displacement_m.amplitude = 0.02;
        options.loading.displacement_m.frequency_hz = 1.0;
        const auto records = stackbeam::simulate(system, options);
        const auto cyc = stackbeam::last_cycle(records, options.loading.period_s());
        const auto h = stackbeam::hysteresis_metrics(records, cyc.first, cyc.second);
        std::printf("  loop area (dissipated per cycle)  %.5f J   (friction work of the cycle %.5f J)\n"
                    "  secant stiffness                  %.1f N/m (no contact force %.1f, every pair stuck %.1f)\n"
                    "  dynamic rate |F1/w1|              %.1f N/m\n"
                    "  loss factor (first harmonics)     %.4f\n"
                    "  equivalent viscous damping ratio  %.4f\n"
                    "  force range                       %.1f to %.1f N\n",
                    h.loop_area_j, h.dissipated_j, h.secant_stiffness_n_per_m, system.free_stiffness_n_per_m(),
                    system.tied_stiffness_n_per_m(), h.dynamic_rate_n_per_m, h.loss_factor, h.equivalent_damping_ratio,
                    h.force_min_n, h.force_max_n);
        write_csv_file(out_dir, "rig_friction.csv", records);
        std::printf("wrote %s (the loop: columns w and spring_force)\n\n", (out_dir / "rig_friction.csv").string().c_str());
        return true;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "paper_demo: error: rig test: %s\n", e.what());
        return false;
    }
}

/// The three cases with leaves of density `rho` (mode newmark, dt = 0.1 ms) against the
/// massless closed-form runs and the eigen-solve of the stack with mass. False on failure.
bool inertia_section(double rho) {
    std::printf("Leaves with mass (density %g kg/m^3): mode newmark (average acceleration, dt = 0.1 ms, the paper's\n"
                "contact problem every step) against the massless closed-form run and the eigen-solve (modal.hpp),\n"
                "and mode cvode with leaf mass (rtol 1e-8; friction: modal inertia, massless contact layer):\n",
                rho);
    std::printf("%-13s %14s %14s %14s %14s %14s %14s %13s\n", "case", "omega [rad/s]", "eigen-solve", "massless",
                "1st peak [m]", "massless", "cvode", "impact [J]");
    bool ok = true;
    for (PaperCase c : kCases) {
        try {
            stackbeam::PaperExampleOptions o;
            const stackbeam::System light(stackbeam::Model::build(stackbeam::paper_example(c, o)));
            o.density_kg_per_m3 = rho;
            const stackbeam::System heavy(stackbeam::Model::build(stackbeam::paper_example(c, o)));
            stackbeam::SimulationOptions options;
            options.t_end_s = 0.3;
            const auto massless = stackbeam::simulate(light, options);
            options.mode = Mode::newmark;
            options.dt_s = 1e-4;
            const auto massive = stackbeam::simulate(heavy, options);
            options.mode = Mode::cvode;
            options.cvode.rtol = 1e-8;
            const auto cv = stackbeam::simulate(heavy, options);
            double eig = 0.0;
            if (c != PaperCase::friction) {
                const auto modal = stackbeam::modal_analysis(
                    heavy, c == PaperCase::bonded ? stackbeam::ModalTie::all : stackbeam::ModalTie::normal, 8);
                Eigen::Index k = 0;
                modal.w_amplitude.cwiseAbs().maxCoeff(&k);
                eig = modal.omega_rad_per_s[k];
            }
            std::printf("%-13s %14.3f %14s %14.3f %14.5f %14.5f %14.5f %13.3e\n", stackbeam::to_string(c),
                        measured_omega(massive), eig > 0.0 ? std::to_string(eig).substr(0, 8).c_str() : "-",
                        measured_omega(massless), first_peak(massive), first_peak(massless), first_peak(cv),
                        massive.back().impact_loss_j);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "paper_demo: error: case %s with leaf mass: %s\n", stackbeam::to_string(c), e.what());
            ok = false;
        }
    }
    std::printf("(omega from the upward zero crossings of w over 0.3 s; eigen-solve: the mode that moves R most, with\n"
                " every contact component tied (bonded) or the normal ones (frictionless); friction: no linear modes)\n\n");
    return ok;
}

}  // namespace

int main(int argc, char** argv) {
    fs::path out_dir = "out";
    double beam_density = 0.0;  // [kg/m^3]
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "-h" || arg == "--help") {
            print_usage(std::cout);
            return 0;
        } else if (arg == "--out-dir" && i + 1 < argc) {
            out_dir = argv[++i];
        } else if (arg.rfind("--out-dir=", 0) == 0) {
            out_dir = arg.substr(10);
        } else if (arg == "--beam-density" && i + 1 < argc) {
            const std::string text = argv[++i];
            char* end = nullptr;
            beam_density = std::strtod(text.c_str(), &end);
            if (text.empty() || *end != '\0' || !std::isfinite(beam_density) || beam_density < 0.0) {
                std::cerr << "paper_demo: error: --beam-density: value '" << text
                          << "' is not allowed: must be a finite number >= 0 [kg/m^3]\n";
                return 2;
            }
        } else {
            std::cerr << "paper_demo: error: unknown or incomplete argument '" << arg << "'\n";
            print_usage(std::cerr);
            return 2;
        }
    }
    if (out_dir.empty()) {
        std::cerr << "paper_demo: error: --out-dir: an empty directory name is not allowed\n";
        return 2;
    }
    try {
        fs::create_directories(out_dir);
        // Remove what an earlier run of the demo wrote here (only those names), so that no
        // stale CSV or figure is taken for a result of this run.
        for (const auto& entry : fs::directory_iterator(out_dir)) {
            const std::string name = entry.path().filename().string();
            bool ours = name == "figures.gp" || name == "fig_displacement_all.png" || name == "rig_friction.csv" ||
                        name == "fig_friction_force_friction.png" || name == "fig_hysteresis_friction.png";
            for (PaperCase c : kCases) {
                const std::string cs = stackbeam::to_string(c);
                ours = ours || name == "fig_displacement_" + cs + ".png";
                for (Mode m : kModes)
                    for (const char* suffix : {".csv", ".csv.partial", "_dt1e-4.csv", "_dt1e-4.csv.partial",
                                               "_events.csv", "_events.csv.partial"})
                        ours = ours || name == cs + "_" + stackbeam::to_string(m) + suffix;
            }
            if (ours && entry.is_regular_file()) fs::remove(entry.path());
        }
    } catch (const std::exception& e) {
        std::cerr << "paper_demo: error: --out-dir: cannot create '" << out_dir.string() << "': " << e.what() << "\n";
        return 2;
    }

    std::printf("stackbeam paper demo: Lee & Lim (1992) section 5, three leaves 0.5 x 0.05 x 0.005 m, E = 2e10 Pa,\n"
                "pinned ends, four clamps (1000 N), 20 kg body at midspan starting at 2 m/s; half model,\n"
                "20 elements per half leaf, contact tolerance 2e-6 m. Modes: closed-form (the paper's step, dt = 1 ms,\n"
                "exact contact solver) and cvode (CVODE Adams, rtol 1e-8, root-finding on every contact transition,\n"
                "the paper's projected iteration checking each step; output every 1 ms).\n\n");

    bool all_ok = true;
    std::vector<Run> runs;
    for (PaperCase c : kCases)
        for (Mode m : kModes) {
            runs.push_back(run_case(c, m, kDtPaper, t_end_of(c)));
            Run& run = runs.back();
            if (!run.ok) {
                all_ok = false;
                std::fprintf(stderr, "paper_demo: error: case %s, mode %s: %s\n", stackbeam::to_string(c),
                             stackbeam::to_string(m), run.error.c_str());
            }
        }

    // Friction reference: closed form at dt = 1e-4 s, and at 2e-4 s to show it has converged.
    Run fine = run_case(PaperCase::friction, Mode::closed_form, kDtFine, t_end_of(PaperCase::friction));
    Run check = run_case(PaperCase::friction, Mode::closed_form, kDtCheck, t_end_of(PaperCase::friction));
    for (const Run* r : {&fine, &check})
        if (!r->ok) {
            all_ok = false;
            std::fprintf(stderr, "paper_demo: error: friction reference at dt = %g s: %s\n", r->dt_s, r->error.c_str());
        }

    // --- table 1: per case, the two modes compared ----------------------------------------
    const double e0 = 0.5 * kMass * kVelocity * kVelocity;
    const auto reference_deviation = [&](const Run& run, std::string& reference) {
        if (!run.ok) return std::nan("");
        if (run.pcase != PaperCase::friction) {
            reference = "sinusoid of the mesh stiffness";
            return max_deviation_from_sinusoid(run.records, run.k_discretised);
        }
        if (!fine.ok) return std::nan("");
        reference = "closed-form run at dt = 1e-4 s";
        return max_deviation_from_run(run.records, fine.records);
    };
    const auto print_header = [] {
        std::printf("  %-12s %7s %9s %11s %7s %8s %12s %12s %12s\n", "mode", "steps", "RHS evals", "contact it.",
                    "events", "wall [s]", "E err end", "max|E err|", "dev ref [m]");
    };
    const auto print_row = [&](const Run& run, double dev) {
        if (!run.ok) {
            std::printf("  %-12s FAILED: %s\n", stackbeam::to_string(run.mode), run.error.c_str());
            return;
        }
        double max_energy_error = 0.0;
        for (const auto& r : run.records) max_energy_error = std::max(max_energy_error, std::abs(r.energy_balance_error_j));
        const bool cv = run.mode == Mode::cvode;
        std::printf("  %-12s %7ld %9s %11ld %7s %8.3f %12.3e %12.3e %12.3e\n", stackbeam::to_string(run.mode),
                    run.report.steps, cv ? std::to_string(run.report.cvode.rhs_evaluations).c_str() : "-",
                    run.report.contact_iterations, cv ? std::to_string(run.report.cvode.events).c_str() : "-",
                    run.wall_s, run.records.back().energy_balance_error_j, max_energy_error, dev);
    };
    for (PaperCase c : kCases) {
        std::printf("%s case, 0 - %g s\n", stackbeam::to_string(c), t_end_of(c));
        print_header();
        std::vector<const Run*> of_case;
        std::string reference;
        for (const Run& run : runs)
            if (run.pcase == c) {
                print_row(run, reference_deviation(run, reference));
                of_case.push_back(&run);
            }
        if (c == PaperCase::friction && fine.ok && check.ok)
            std::printf("  (reference check: closed-form at dt = %g s deviates %.3e m from the one at dt = %g s)\n",
                        kDtCheck, max_deviation_from_run(check.records, fine.records), kDtFine);
        if (of_case.size() == 2 && of_case[0]->ok && of_case[1]->ok) {
            const Run& cvr = of_case[0]->mode == Mode::cvode ? *of_case[0] : *of_case[1];
            std::printf("  max |w_closed-form - w_cvode| = %.3e m (max |w| %.4f m); reference of dev ref: %s\n",
                        max_deviation_from_run(of_case[0]->records, of_case[1]->records), max_abs_w(cvr.records),
                        reference.c_str());
            const auto& cs = cvr.report.cvode;
            long stick_slip = 0;
            for (const auto& e : cvr.report.events) stick_slip += e.is_stick_slip();
            std::printf("  cvode: %ld event times (%zu transitions, %ld stick-slip), %ld restarts, %ld mode "
                        "factorisations, %ld missed events found by the per-step check, max force jump at an "
                        "event %.2e N\n",
                        cs.events, cvr.report.events.size(), stick_slip, cs.restarts, cs.mode_factorizations,
                        cs.missed_events, cs.max_force_jump_n);
        }
        std::printf("\n");
    }
    std::printf("(steps: closed-form steps or CVODE steps; RHS evals: CVODE right-hand sides (closed-form evaluates its "
                "exact solution); contact it.: contact solver iterations;\n events: event times of cvode; E err: initial "
                "energy %.0f J - kinetic - strain - dissipated [J]; dev ref: max over t of |w - w_ref| [m])\n\n",
                e0);

    // --- table 2: the linear cases against the analytic figures -------------------------------
    std::printf("%-13s %-12s %13s %13s %11s %11s %11s %11s %13s %13s\n", "case", "mode", "k mesh [N/m]",
                "k 1-beam", "omega mesh", "omega 1-b", "ampl mesh", "ampl 1-b", "max |w| [m]", "dev 1-beam");
    for (const Run& run : runs) {
        if (!run.ok || run.pcase == PaperCase::friction) continue;
        const auto a = stackbeam::paper_analytic(run.pcase);
        const double omega = std::sqrt(run.k_discretised / kMass);
        std::printf("%-13s %-12s %13.1f %13.1f %11.4f %11.4f %11.5f %11.5f %13.5f %13.3e\n",
                    stackbeam::to_string(run.pcase), stackbeam::to_string(run.mode), run.k_discretised,
                    a.stiffness_n_per_m, omega, a.omega_rad_per_s, kVelocity / omega, a.amplitude_m,
                    max_abs_w(run.records), max_deviation_from_sinusoid(run.records, a.stiffness_n_per_m));
    }
    std::printf("(mesh: the discretised stack, bonded = all contact components tied; 1-beam: paper_analytic(), "
                "48EI/L^3 of the equivalent beam; omega [rad/s], amplitude v0/omega [m];\n dev 1-beam: max |w - "
                "v0/omega sin(omega t)| with the one-beam omega [m])\n\n");

    // --- the rig test's loop, and leaves with mass on request ----------------------------------
    if (!rig_section(out_dir)) all_ok = false;
    if (beam_density > 0.0 && !inertia_section(beam_density)) all_ok = false;

    // --- CSV files ----------------------------------------------------------------------------
    std::map<PaperCase, std::vector<const Run*>> plotted;
    std::string fine_csv;
    try {
        for (Run& run : runs) {
            if (run.records.empty()) continue;
            if (!run.ok) {  // the records up to the failure, never under the name of a complete run
                const std::string partial = csv_name(run.pcase, run.mode) + ".partial";
                std::ofstream out(out_dir / partial);
                stackbeam::write_csv(out, run.records);
                std::printf("wrote %s (the failed run up to its failure)\n", (out_dir / partial).string().c_str());
                continue;
            }
            run.csv_file = csv_name(run.pcase, run.mode);
            write_csv_file(out_dir, run.csv_file, run.records);
            std::printf("wrote %s\n", (out_dir / run.csv_file).string().c_str());
            plotted[run.pcase].push_back(&run);
            if (run.mode == Mode::cvode && !run.report.events.empty()) {
                const std::string name = csv_name(run.pcase, run.mode, "_events");
                const fs::path partial = out_dir / (name + ".partial");
                {
                    std::ofstream out(partial);
                    stackbeam::write_events_csv(out, run.report.events);
                    out.close();
                    if (out.fail()) throw std::runtime_error("writing '" + partial.string() + "' failed");
                }
                fs::rename(partial, out_dir / name);
                std::printf("wrote %s (the event log)\n", (out_dir / name).string().c_str());
            }
        }
        if (fine.ok) {
            fine.csv_file = csv_name(PaperCase::friction, Mode::closed_form, "_dt1e-4");
            write_csv_file(out_dir, fine.csv_file, fine.records);
            fine_csv = fine.csv_file;
            std::printf("wrote %s\n", (out_dir / fine.csv_file).string().c_str());
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "paper_demo: error: %s\n", e.what());
        return 1;
    }

    // --- figures --------------------------------------------------------------------------------
    if (!gnuplot_on_path()) {
        std::printf("gnuplot is not on PATH: no figures (install gnuplot-nox to get them)\n");
    } else if (const auto terminal = png_terminal(); !terminal) {
        std::printf("gnuplot has neither the pngcairo nor the png terminal: no figures\n");
    } else if (!plotted.empty()) {
        const fs::path script = out_dir / "figures.gp";
        std::vector<std::string> figures;
        {
            std::ofstream gp(script);
            gp << figure_script(*terminal, plotted, fine_csv, figures);
            if (!gp) {
                std::fprintf(stderr, "paper_demo: error: cannot write %s\n", script.string().c_str());
                return 1;
            }
        }
        const std::string cmd = "cd " + shell_quote(out_dir.string()) + " && gnuplot figures.gp";
        if (std::system(cmd.c_str()) != 0) {
            std::fprintf(stderr, "paper_demo: error: gnuplot failed on %s\n", script.string().c_str());
            return 1;
        }
        std::printf("wrote figures (gnuplot, %s terminal, script figures.gp) to %s:\n", terminal->c_str(),
                    out_dir.string().c_str());
        for (const auto& f : figures) std::printf("  %s\n", f.c_str());
    }

    if (!all_ok) {
        std::fprintf(stderr, "paper_demo: error: at least one run failed (see above)\n");
        return 1;
    }
    return 0;
}
