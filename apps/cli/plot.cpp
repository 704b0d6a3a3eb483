// --plot: PNG figures of a run with gnuplot (apps/common/gnuplot.hpp) from its CSV.
#include "plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
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
    using namespace stackbeam::gnuplot;
    if (!gnuplot_on_path()) {
        note = "gnuplot is not on PATH: no figures (install gnuplot-nox)";
        return std::nullopt;
    }
    auto terminal = png_terminal();
    if (!terminal) note = "gnuplot has neither the pngcairo nor the png terminal: no figures";
    return terminal;
}

std::vector<std::string> plot_run(const std::string& csv, const std::string& prefix, std::string& note,
                                  const std::vector<std::pair<double, double>>& fitted_loop, bool windup, bool probe) {
    using namespace stackbeam::gnuplot;
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
    if (probe)  // a model without a probe pair (one leaf, no clamp) has no friction force to draw (the column is nan)
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
    if (windup)  // the windup loop: the moment on the spring at the seat against the seat's rotation
        fig("windup_loop", "windup loop", "seat rotation [mrad]", "seat moment [N m]",
            f + " using (1000*$" + std::to_string(column_of("seat_rotation")) + "):" +
                std::to_string(column_of("seat_moment")) + " with lines lw 1.5 notitle");
    g.close();
    if (!g) throw std::runtime_error("writing '" + script_path + "' failed");
    if (std::system(("gnuplot " + shell_quote(script_path)).c_str()) != 0) {
        note = "gnuplot failed on " + script_path;
        return {};
    }
    return files;
}

double stack_figure_scale(double stack_height_m, double max_abs_w_m) {
    if (!(max_abs_w_m > 0.0)) return 1.0;
    const double target = 2.0 * stack_height_m / max_abs_w_m;
    const double decade = std::pow(10.0, std::floor(std::log10(target)));
    for (double m : {5.0, 2.0, 1.0})
        if (m * decade <= target * (1.0 + 1e-12)) return m * decade;
    return decade;
}

namespace {

/// y of a leaf's drawn axis at x [m] (linear between its nodes).
double drawn_axis_m(const LeafNodes& leaf, double height_m, double scale, double x_m) {
    const auto& xs = leaf.x_m;
    if (xs.empty()) return height_m;
    const auto it = std::lower_bound(xs.begin(), xs.end(), x_m);
    std::size_t j = static_cast<std::size_t>(it - xs.begin());
    if (j == 0) return height_m + scale * leaf.w_m.front();
    if (j >= xs.size()) return height_m + scale * leaf.w_m.back();
    const double a = (x_m - xs[j - 1]) / (xs[j] - xs[j - 1]);
    return height_m + scale * ((1.0 - a) * leaf.w_m[j - 1] + a * leaf.w_m[j]);
}

}  // namespace

std::vector<std::string> plot_stack(const System& system, const RunResult& result, const std::string& prefix,
                                    std::string& note, bool stress) {
    using namespace stackbeam::gnuplot;
    const auto terminal = plot_terminal(note);
    if (!terminal) return {};
    const Model& model = system.model();
    const auto& leaves = model.spec().leaves;
    const auto& heights = model.centroid_heights_m();
    const double x_r = model.nodes_x()[model.attachment_node()];
    const bool half = model.spec().symmetry == Symmetry::half;
    double stack_height = 0.0, max_w = 0.0;
    for (const auto& leaf : leaves) stack_height += leaf_thickness_m(leaf, x_r);
    const StackSnapshot* shots[2] = {&result.stack_at_max, &result.stack_at_min};
    const bool windup = result.snapshots_by_seat_rotation;
    for (const StackSnapshot* s : shots)
        for (const auto& leaf : s->nodes)
            for (double w : leaf.w_m) max_w = std::max(max_w, std::abs(w));
    const double scale = stack_figure_scale(stack_height, max_w);

    const std::string axes_path = prefix + "_stack_axes.dat", pairs_path = prefix + "_stack_pairs.dat";
    std::ofstream axes(axes_path), pairs(pairs_path);
    if (!axes) throw ArgumentError("--plot: cannot write '" + axes_path + "'");
    if (!pairs) throw ArgumentError("--plot: cannot write '" + pairs_path + "'");
    axes << "# x [mm], y [mm]: each leaf's axis at its height plus " << scale
         << " x its deflection; one block per leaf, one index per figure (w max, w min)\n";
    pairs << "# x [mm], y [mm] (midway between the two leaves' drawn axes), state (0 stick, 1 slip, 2 open)\n";
    for (const StackSnapshot* s : shots) {
        for (const auto& leaf : s->nodes) {
            for (std::size_t j = 0; j < leaf.x_m.size(); ++j)
                axes << 1000.0 * leaf.x_m[j] << ' ' << 1000.0 * (heights[leaf.leaf] + scale * leaf.w_m[j]) << '\n';
            axes << '\n';
        }
        axes << "\n";  // two blank lines: the next index
        for (const auto& p : s->pairs) {
            const int upper = p.interface_index, lower = upper + 1;
            if (lower >= static_cast<int>(s->nodes.size())) continue;
            const int code = p.state == PairState::stick ? 0 : p.state == PairState::slip ? 1 : 2;
            for (int side = 0; side < (half && std::abs(p.x_m - x_r) > model.x_tolerance_m() ? 2 : 1); ++side) {
                const double x = side == 0 ? p.x_m : 2.0 * x_r - p.x_m;
                const double y = 0.5 * (drawn_axis_m(s->nodes[upper], heights[upper], scale, x) +
                                        drawn_axis_m(s->nodes[lower], heights[lower], scale, x));
                pairs << 1000.0 * x << ' ' << 1000.0 * y << ' ' << code << '\n';
            }
        }
        pairs << "\n\n";
    }
    axes.close();
    pairs.close();
    if (!axes || !pairs) throw std::runtime_error("writing the deformed stack's data '" + axes_path + "' failed");
    // a windup run: the seat, a segment through each leaf's drawn axis at the seat of slope scale x theta_R
    // (the tied leaves turn with the seat), 6 % of the spring's length either side
    const std::string seat_path = prefix + "_stack_seat.dat";
    if (windup) {
        std::ofstream seat(seat_path);
        if (!seat) throw ArgumentError("--plot: cannot write '" + seat_path + "'");
        seat << "# x [mm], y [mm]: the seat on each leaf at it, slope " << scale << " x theta_R; one index per figure\n";
        double x_min = x_r, x_max = x_r;
        for (const auto& leaf : shots[0]->nodes)
            for (double x : leaf.x_m) x_min = std::min(x_min, x), x_max = std::max(x_max, x);
        const double half_m = 0.06 * (x_max - x_min);
        for (const StackSnapshot* s : shots) {
            for (const auto& leaf : s->nodes)
                for (std::size_t j = 0; j < leaf.x_m.size(); ++j)
                    if (std::abs(leaf.x_m[j] - x_r) <= model.x_tolerance_m()) {
                        const double y = heights[leaf.leaf] + scale * leaf.w_m[j], dy = scale * s->seat_rotation_rad * half_m;
                        seat << 1000.0 * (x_r - half_m) << ' ' << 1000.0 * (y - dy) << '\n'
                             << 1000.0 * (x_r + half_m) << ' ' << 1000.0 * (y + dy) << "\n\n";
                        break;
                    }
            seat << "\n";  // with the block's blank line, two: the next index
        }
        seat.close();
        if (!seat) throw std::runtime_error("writing the deformed stack's data '" + seat_path + "' failed");
    }

    // --stack-color stress: each leaf a band from its bottom to its top fibre (its drawn axis -+ half
    // its local thickness), a grid of two scans for gnuplot's pm3d: one index per figure and leaf
    const std::string band_path = prefix + "_stack_stress.dat";
    double sigma_max_mpa = 0.0;
    if (stress) {
        std::ofstream band(band_path);
        if (!band) throw ArgumentError("--plot: cannot write '" + band_path + "'");
        band << "# x [mm], y [mm], sigma [MPa] (tension positive): per figure (largest, smallest w) and leaf one "
                "index, its bottom fibre (the drawn axis - t/2) then its top fibre (+ t/2)\n";
        for (const StackSnapshot* s : shots) {
            if (s->stresses.size() != s->nodes.size())
                throw std::logic_error("plot_stack: the snapshot has no stresses (--stack-color stress)");
            for (std::size_t l = 0; l < s->stresses.size(); ++l) {
                const LeafStresses& ls = s->stresses[l];
                for (const double side : {-1.0, 1.0}) {
                    const auto& sigma = side > 0.0 ? ls.top_stress_pa : ls.bottom_stress_pa;
                    for (std::size_t j = 0; j < ls.x_m.size(); ++j) {
                        const double y = drawn_axis_m(s->nodes[l], heights[ls.leaf], scale, ls.x_m[j]) + 0.5 * side * ls.thickness_m[j];
                        band << 1000.0 * ls.x_m[j] << ' ' << 1000.0 * y << ' ' << sigma[j] / 1e6 << '\n';
                        sigma_max_mpa = std::max(sigma_max_mpa, std::abs(sigma[j]) / 1e6);
                    }
                    band << '\n';  // the next scan
                }
                band << "\n";  // two blank lines: the next index
            }
        }
        band.close();
        if (!band) throw std::runtime_error("writing the deformed stack's data '" + band_path + "' failed");
        if (!(sigma_max_mpa > 0.0)) sigma_max_mpa = 1.0;
    }

    const std::string script_path = prefix + "_stack.gp", png = prefix + "_stack.png";
    std::ofstream g(script_path);
    if (!g) throw ArgumentError("--plot: cannot write '" + script_path + "'");
    std::ostringstream scale_text;
    scale_text << scale;
    g << "set terminal " << *terminal << " size 1000,900\nset output '" << png << "'\nset grid\nset key outside bottom center horizontal\n"
      << "set multiplot layout 2,1 title 'deformed stack: the deflection drawn x " << scale_text.str()
      << " (the leaves at their heights in the stack)'\n";
    if (stress)  // blue compression, white 0, red tension: one scale for both figures; a map view
        g << "set view map\nset pm3d map interpolate 1,4 corners2color mean\nset palette defined (-1 '#3b4cc0', 0 '#f2f2f2', 1 '#b40426')\nset cbrange [" << -sigma_max_mpa << ":"
          << sigma_max_mpa << "]\nset cblabel 'fibre stress [MPa], tension positive'\n";
    for (int i = 0; i < 2; ++i) {
        std::ostringstream title;
        if (windup)
            title << (i == 0 ? "largest" : "smallest") << " seat rotation " << 1000.0 * shots[i]->seat_rotation_rad
                  << " mrad (w = " << 1000.0 * shots[i]->w_m << " mm) at t = " << shots[i]->t_s << " s";
        else
            title << (i == 0 ? "largest" : "smallest") << " w = " << 1000.0 * shots[i]->w_m << " mm at t = " << shots[i]->t_s << " s";
        g << "set title '" << title.str() << "'\nset xlabel 'x [mm]'\nset ylabel 'height + " << scale_text.str()
          << " x deflection [mm]'\n";
        if (stress) {  // a map of the bands, linear between the nodes and through the thickness (pm3d)
            const std::size_t leaves_drawn = shots[i]->stresses.size(), first = static_cast<std::size_t>(i) * leaves_drawn;
            g << "splot for [k=" << first << ":" << first + leaves_drawn - 1 << "] '" << band_path
              << "' index k using 1:2:(0):3 with pm3d notitle\n";
            continue;
        }
        g << "plot '" << axes_path << "' index " << i << " using 1:2 with lines lw 2 lc rgb 'black' title 'leaf axes', '"
          << pairs_path << "' index " << i << " using 1:($3==0?$2:1/0) with points pt 7 ps 0.8 lc rgb '#1a9850' title 'stick', '"
          << pairs_path << "' index " << i << " using 1:($3==1?$2:1/0) with points pt 7 ps 0.8 lc rgb '#d73027' title 'slip', '"
          << pairs_path << "' index " << i << " using 1:($3==2?$2:1/0) with points pt 6 ps 0.8 lc rgb '#4575b4' title 'open'"
          << (windup ? ", '" + seat_path + "' index " + std::to_string(i) + " using 1:2 with lines lw 4 lc rgb '#ff7f0e' title 'seat'" : "")
          << "\n";
    }
    g << "unset multiplot\n";
    g.close();
    if (!g) throw std::runtime_error("writing '" + script_path + "' failed");
    if (std::system(("gnuplot " + shell_quote(script_path)).c_str()) != 0) {
        note = "gnuplot failed on " + script_path;
        return {};
    }
    return {png};
}

}  // namespace stackbeam::cli
