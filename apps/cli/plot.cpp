// --plot: PNG figures of a run with gnuplot (demos/gnuplot.hpp) from its CSV.
#include "plot.hpp"

#include <cstdlib>
#include <fstream>
#include <stdexcept>

#include "gnuplot.hpp"
#include "options.hpp"
#include "stackbeam/io/csv.hpp"

namespace stackbeam::cli {

namespace {

/// 1-based column of `name` in the records' CSV (for gnuplot).
int column_of(const std::string& name) {
    const auto cols = step_record_columns();
    for (std::size_t i = 0; i < cols.size(); ++i)
        if (cols[i] == name) return static_cast<int>(i) + 1;
    throw std::logic_error("no CSV column " + name);
}

/// PNG figures of a run with gnuplot from its CSV: displacement, forces, friction
/// force at the probe, and the loop (spring force against w). Returns the files
/// written, or a note why none were.
}  // namespace

std::optional<std::string> plot_terminal(std::string& note) {
    using namespace stackbeam::demo;
    if (!gnuplot_on_path()) {
        note = "gnuplot is not on PATH: no figures (install gnuplot-nox)";
        return std::nullopt;
    }
    auto terminal = png_terminal();
    if (!terminal) note = "gnuplot has neither the pngcairo nor the png terminal: no figures";
    return terminal;
}

std::vector<std::string> plot_run(const std::string& csv, const std::string& prefix, std::string& note,
                                  const std::vector<std::pair<double, double>>& fitted_loop) {
    using namespace stackbeam::demo;
    const auto terminal = plot_terminal(note);
    if (!terminal) return {};
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
    std::string fitted;
    if (!fitted_loop.empty()) {
        const std::string data = prefix + "_fancher_loop.csv";
        std::ofstream d(data);
        if (!d) throw ArgumentError("--plot: cannot write '" + data + "'");
        d.precision(17);
        for (const auto& [wm, fn] : fitted_loop) d << wm << "," << fn << "\n";
        d.close();
        if (!d) throw std::runtime_error("writing '" + data + "' failed");
        fitted = ", '" + data + "' using (1000*$1):2 with lines dt 2 lw 2 title 'Fancher model, fitted to the last cycle'";
    }
    fig("loop", "force-deflection loop", "w [mm]", "spring force [N]",
        f + " using (1000*$" + std::to_string(w) + "):" + std::to_string(sf) + " with lines lw 1.5 " +
            (fitted.empty() ? "notitle" : "title 'run'") + fitted);
    g.close();
    if (!g) throw std::runtime_error("writing '" + script_path + "' failed");
    if (std::system(("gnuplot " + shell_quote(script_path)).c_str()) != 0) {
        note = "gnuplot failed on " + script_path;
        return {};
    }
    return files;
}

}  // namespace stackbeam::cli
