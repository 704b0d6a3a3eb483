// The figures of a sweep (sweep_plot.hpp): gnuplot scripts and PNGs in DIR/figures/.
#include "sweep_plot.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "gnuplot.hpp"
#include "plot.hpp"
#include "stackbeam/study/sweep_output.hpp"

namespace stackbeam::cli {

namespace {

namespace fs = std::filesystem;

/// The point of a product sweep at one index per axis (the last axis varies fastest).
int product_index(const SweepSpec& spec, const std::vector<std::size_t>& at) {
    int index = 0;
    for (std::size_t a = 0; a < spec.axes.size(); ++a)
        index = index * static_cast<int>(spec.axes[a].values.size()) + static_cast<int>(at[a]);
    return index;
}

bool numeric(const SweepAxis& axis) {
    for (const AxisValue& v : axis.values)
        if (!std::holds_alternative<double>(v) && !std::holds_alternative<long long>(v)) return false;
    return true;
}

double as_number(const AxisValue& v) {
    if (const auto* d = std::get_if<double>(&v)) return *d;
    return static_cast<double>(std::get<long long>(v));
}

/// A file name part from a key: letters and digits kept, every other run of characters one '_'.
std::string file_part(const std::string& key) {
    std::string s;
    for (char c : key) {
        const bool keep = std::isalnum(static_cast<unsigned char>(c)) != 0;
        if (keep) s += c;
        else if (!s.empty() && s.back() != '_') s += '_';
    }
    while (!s.empty() && s.back() == '_') s.pop_back();
    return s;
}

/// Log scale for an axis whose values are positive and span a factor above 20.
bool log_scale(const SweepAxis& axis) {
    double lo = INFINITY, hi = 0.0;
    for (const AxisValue& v : axis.values) {
        const double x = as_number(v);
        if (!(x > 0.0)) return false;
        lo = std::min(lo, x);
        hi = std::max(hi, x);
    }
    return hi > 20.0 * lo;
}

}  // namespace

std::vector<std::string> plot_sweep(const std::string& directory, const SweepSpec& spec,
                                    const SweepPoints& points, const std::vector<PointResult>& results,
                                    std::string& note) {
    using namespace stackbeam::gnuplot;
    const auto terminal = plot_terminal(note);
    if (!terminal) return {};
    const fs::path dir = fs::path(directory) / "figures";
    fs::create_directories(dir);
    const std::string script_path = (dir / "figures.gp").string();
    std::ofstream g(script_path);
    if (!g) throw std::runtime_error("cannot write '" + script_path + "'");
    g << "set datafile separator ','\nset terminal " << *terminal << " size 1000,760 noenhanced\nset grid\nset key below\n";
    std::vector<std::string> files;
    // the two kinds of loop a point may have written (sweep_output: write_point_files), each file t,
    // x, y: the vertical loop (w [m], spring force [N]) and a windup run's windup loop (theta_R [rad],
    // the seat's moment [N m]); each drawn in families of its own
    struct LoopKind {
        const char* suffix;  ///< of loops/point-NNNN<suffix>.csv
        const char* name;    ///< of the figures' files: NAME_along_KEY.png, NAME.png
        const char* what;    ///< the figures' title: WHAT along KEY
        const char* labels;  ///< gnuplot's axis labels (x in milli-units)
    };
    const LoopKind kinds[] = {{"", "loops", "loops", "set xlabel 'w [mm]'\nset ylabel 'spring force [N]'\n"},
                              {"-windup", "windup_loops", "windup loops", "set xlabel 'seat rotation [mrad]'\nset ylabel 'seat moment [N m]'\n"}};
    // the k-th loop of a figure in colour k; Fancher's fitted loop (when there is one, vertical loops
    // only) over it, thin and dashed in the same colour, without a key entry (the title says what dashed is)
    bool fitted = false;
    auto loop_curve = [&](const LoopKind& kind, int i, int k, const std::string& title) {
        const std::string colour = " lc " + std::to_string(k + 1);
        std::string c = "'" + point_file(directory, "loops", i, "csv", kind.suffix) +
                        "' using (1000*$2):3 skip 1 with lines lw 1.5" + colour + " title '" + title + "'";
        const std::string fit = point_file(directory, "loops", i, "csv", "-fancher");
        if (*kind.suffix == '\0' && fs::exists(fit)) {
            c += ", '" + fit + "' using (1000*$2):3 skip 1 with lines lw 0.8 dt 2" + colour + " notitle";
            fitted = true;
        }
        return c;
    };
    auto fitted_note = [&] { return fitted ? std::string("\\n(dashed: Fancher's model fitted to each loop)") : std::string(); };
    const std::size_t n_axes = spec.axes.size();
    // 1. loop families, of each kind
    for (const LoopKind& kind : kinds) {
        auto has_loop = [&](int i) { return fs::exists(point_file(directory, "loops", i, "csv", kind.suffix)); };
        if (spec.combine == Combine::product) {
            std::vector<std::size_t> middle(n_axes);
            for (std::size_t a = 0; a < n_axes; ++a) middle[a] = spec.axes[a].values.size() / 2;
            for (std::size_t a = 0; a < n_axes; ++a) {
                if (spec.axes[a].values.size() < 2) continue;
                std::string curves, fixed;
                fitted = false;
                int k_curve = 0;
                for (std::size_t b = 0; b < n_axes; ++b)
                    if (b != a) fixed += (fixed.empty() ? "" : ", ") + spec.axes[b].key + " = " + to_string(spec.axes[b].values[middle[b]]);
                for (std::size_t k = 0; k < spec.axes[a].values.size(); ++k) {
                    auto at = middle;
                    at[a] = k;
                    const int i = product_index(spec, at);
                    if (!has_loop(i)) continue;
                    curves += (curves.empty() ? "" : ", ") +
                              loop_curve(kind, i, k_curve++, spec.axes[a].key + " = " + to_string(spec.axes[a].values[k]));
                }
                if (curves.empty()) continue;
                files.push_back((dir / (std::string(kind.name) + "_along_" + file_part(spec.axes[a].key) + ".png")).string());
                g << "set output '" << files.back() << "'\nset title \"" << kind.what << " along " << spec.axes[a].key
                  << (fixed.empty() ? "" : "\\n(" + fixed + ")") << fitted_note() << "\"\n" << kind.labels << "plot " << curves
                  << "\n";
            }
        } else {
            std::string curves;
            fitted = false;
            int k_curve = 0;
            for (int i = 0; i < points.size(); ++i) {
                if (!has_loop(i)) continue;
                const std::vector<AxisValue> values = points.values(i);
                std::string title;
                for (std::size_t a = 0; a < n_axes; ++a) title += (a ? ", " : "") + to_string(values[a]);
                curves += (curves.empty() ? "" : ", ") + loop_curve(kind, i, k_curve++, title);
            }
            if (!curves.empty()) {
                files.push_back((dir / (std::string(kind.name) + ".png")).string());
                g << "set output '" << files.back() << "'\nset title \"" << kind.what << fitted_note() << "\"\n" << kind.labels
                  << "plot " << curves << "\n";
            }
        }
    }
    // 2. maps over the first two numeric axes with two or more values (the others at their middle value)
    std::vector<std::size_t> map_axes;
    for (std::size_t a = 0; a < n_axes && map_axes.size() < 2; ++a)
        if (spec.axes[a].values.size() >= 2 && numeric(spec.axes[a])) map_axes.push_back(a);
    if (spec.combine == Combine::product && map_axes.size() == 2) {
        const std::size_t ax = map_axes[0], ay = map_axes[1];
        std::vector<std::size_t> at(n_axes);
        for (std::size_t a = 0; a < n_axes; ++a) at[a] = spec.axes[a].values.size() / 2;
        const std::string data = (dir / "map.csv").string();
        // the maps: the vertical loop's loss factor and dynamic rate, a windup run's windup stiffness and
        // loss factor; each drawn where some point has it (map.csv has them all, NaN where none)
        struct Map {
            const char* column;  ///< point_figure_columns' name
            const char* name;    ///< map_NAME.png
            const char* label;   ///< the figure's title
            std::size_t index;   ///< its place in PointResult::figures
            bool any;            ///< some point has it
        };
        Map maps[] = {{"loss_factor", "loss_factor", "loss factor [-]", 0, false},
                      {"dynamic_rate_n_per_m", "dynamic_rate", "dynamic rate [N/m]", 0, false},
                      {"windup_stiffness_n_m_per_rad", "windup_stiffness", "windup stiffness [N m/rad]", 0, false},
                      {"windup_loss_factor", "windup_loss_factor", "windup loss factor [-]", 0, false}};
        const auto& columns = point_figure_columns();
        std::ofstream d(data);
        d << "# " << spec.axes[ax].key << "," << spec.axes[ay].key;
        for (Map& m : maps) {
            m.index = static_cast<std::size_t>(std::find(columns.begin(), columns.end(), m.column) - columns.begin());
            d << "," << m.column;
        }
        d << "\n";
        for (std::size_t i = 0; i < spec.axes[ax].values.size(); ++i) {
            for (std::size_t j = 0; j < spec.axes[ay].values.size(); ++j) {
                at[ax] = i;
                at[ay] = j;
                const PointResult& r = results.at(static_cast<std::size_t>(product_index(spec, at)));
                char cell[64];
                std::snprintf(cell, sizeof cell, "%.17g,%.17g", as_number(spec.axes[ax].values[i]), as_number(spec.axes[ay].values[j]));
                d << cell;
                for (Map& m : maps) {
                    const double v = r.figures.size() > m.index ? r.figures[m.index] : NAN;
                    m.any = m.any || std::isfinite(v);
                    std::snprintf(cell, sizeof cell, ",%.17g", v);
                    d << cell;
                }
                d << "\n";
            }
            d << "\n";
        }
        d.close();
        std::string fixed;
        for (std::size_t b = 0; b < n_axes; ++b)
            if (b != ax && b != ay)
                fixed += (fixed.empty() ? "" : ", ") + spec.axes[b].key + " = " + to_string(spec.axes[b].values[at[b]]);
        bool set_up = false;
        for (std::size_t k = 0; k < std::size(maps); ++k) {
            if (!maps[k].any) continue;
            if (!set_up) {  // a square per point coloured by its value, the value written above it (no
                            // interpolation between points: a map of a few points shows what was computed)
                g << "set datafile missing 'nan'\nunset key\nset offsets graph 0.08, graph 0.08, graph 0.1, graph 0.08\n"
                  << "set palette rgb 33,13,10\nset xlabel '" << spec.axes[ax].key << "'\nset ylabel '" << spec.axes[ay].key << "'\n"
                  << (log_scale(spec.axes[ax]) ? "set logscale x\n" : "") << (log_scale(spec.axes[ay]) ? "set logscale y\n" : "");
                set_up = true;
            }
            const std::string col = std::to_string(k + 3);
            files.push_back((dir / ("map_" + std::string(maps[k].name) + ".png")).string());
            g << "set output '" << files.back() << "'\nset title \"" << maps[k].label << (fixed.empty() ? "" : "\\n(" + fixed + ")")
              << "\"\nplot '" << data << "' using 1:2:" << col << " with points pt 5 ps 5 lc palette, '' using 1:2:(sprintf('%.4g', $"
              << col << ")) with labels offset 0,1.8\n";
        }
    }
    g.close();
    if (files.empty()) {
        note = "no point has a loop (no periodic loading?)";
        return {};
    }
    if (std::system(("gnuplot " + shell_quote(script_path) + " 2>/dev/null").c_str()) != 0) {
        note = "gnuplot failed on " + script_path;
        return {};
    }
    return files;
}

}  // namespace stackbeam::cli
