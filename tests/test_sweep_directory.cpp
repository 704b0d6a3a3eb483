// The sweep directory's ownership and limits (study/sweep_output.hpp, study/sweep.hpp;
// issue 41 items 2, 3, 6, 7): one owner per directory (flock), journal rows checked against
// their points, damaged rows dropped by line with the rows after them kept, per-point files
// never reused from another run, points made lazily with a stated limit, inputs that are not
// regular files refused by name. No point is simulated here: rows are made by hand (their
// figures are not physics, only the bookkeeping is checked), so every case takes milliseconds.
#define BOOST_TEST_MODULE sweep_directory
#include <boost/test/unit_test.hpp>

#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "stackbeam/errors.hpp"
#include "stackbeam/io/scenario.hpp"
#include "stackbeam/study/sweep.hpp"
#include "stackbeam/study/sweep_output.hpp"

using namespace stackbeam;
namespace fs = std::filesystem;

namespace {

const std::string kSource = std::string(STACKBEAM_SOURCE_DIR) + "/tests/sweep/in_code.toml";

SweepSpec map_with_mu(const std::string& mu_values) {
    return parse_sweep_spec("scenario = \"rig_small.toml\"\n"
                            "[[axes]]\nkey = \"loading.displacement_m.amplitude\"\nvalues = [0.01, 0.02]\n"
                            "[[axes]]\nkey = \"interfaces[*].friction_coefficient\"\nvalues = " + mu_values + "\n",
                            kSource);
}

/// A fresh, empty directory under the build's temporary folder.
std::string fresh_dir(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / ("stackbeam_test_sweep_directory_" + std::to_string(::getpid())) / name;
    fs::remove_all(dir);
    fs::create_directories(dir.parent_path());
    return dir.string();
}

/// A hand-made ok row of point `index`: its figures are its index (bookkeeping only).
PointResult row_of(int index) {
    PointResult r;
    r.index = index;
    r.figures.assign(point_figure_columns().size(), static_cast<double>(index));
    r.wall_s = 0.5;
    return r;
}

/// A fresh directory `name` (fresh_dir) holding a sweep of `points` with the rows of its first
/// `rows` points (row_of), its lock released.
std::string directory_with_rows(const std::string& name, const SweepPoints& points, int rows) {
    const std::string dir = fresh_dir(name);
    SweepDirectory d(dir, points, false, false);
    for (int i = 0; i < rows; ++i) d.record(row_of(i));
    return dir;
}

std::string read(const std::string& path) {
    std::ifstream in(path);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

std::vector<std::string> lines_of(const std::string& path) {
    std::vector<std::string> lines;
    std::istringstream in(read(path));
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
}

template <class F>
std::string error_of(F&& f) {
    try {
        f();
    } catch (const std::exception& e) {
        return e.what();
    }
    return "";
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

// Issue 41 item 2: a second sweep on a directory in use is refused, naming the holder; the
// lock goes with its holder (a process's death closes the descriptor the same way).
BOOST_AUTO_TEST_CASE(second_owner_refused) {
    const SweepSpec spec = map_with_mu("[0.3, 0.5]");
    const SweepPoints points(spec);
    const std::string dir = fresh_dir("owner");
    {
        SweepDirectory first(dir, points, false, false);
        // another open file description: flock refuses it as it refuses another process
        const std::string e = error_of([&] { SweepDirectory second(dir, points, false, false); });
        BOOST_TEST(has(e, "--out-dir: '" + dir + "' is in use by another sweep (pid " + std::to_string(::getpid())));
        BOOST_TEST(has(e, "spec " + kSource));
        // --restart does not delete what the holder writes
        const std::string r = error_of([&] { SweepDirectory again(dir, points, true, false); });
        BOOST_TEST(has(r, "is in use by another sweep"));
        first.record(row_of(0));
    }
    SweepDirectory after(dir, points, false, false);  // released: resumed
    BOOST_TEST(after.finished_count() == 1);
}

// Issue 41 item 2, the relabelling: another spec's rows in the journal (as a --restart of
// mapY beside a running map left them) are refused by line and value, never reused.
BOOST_AUTO_TEST_CASE(journal_rows_checked_against_points) {
    const SweepSpec map = map_with_mu("[0.3, 0.5]");
    const SweepSpec mapY = map_with_mu("[0.3, 0.4]");
    const SweepPoints points(map), pointsY(mapY);
    const std::string dir = directory_with_rows("relabel", points, 4);
    const std::string journal = dir + "/finished.csv";
    const auto lines = lines_of(journal);
    BOOST_REQUIRE_EQUAL(lines.size(), 6u);  // the spec's id, the header, 4 rows
    BOOST_TEST(lines[0] == "# stackbeam sweep journal: spec " + sweep_spec_id(map) + " (" + kSource + ")");
    BOOST_TEST(sweep_spec_id(map) != sweep_spec_id(mapY));
    // mapY's journal holding map's rows: its spec.json and id line say mapY, the rows map's values
    fs::remove(dir + "/spec.json");
    {
        SweepDirectory y(dir, pointsY, true, false);  // --restart: mapY's spec.json and journal
    }
    std::ofstream(journal, std::ios::app) << lines[3] << "\n";  // point 1: mu = 0.5, a row of map
    const std::string e = error_of([&] { SweepDirectory y(dir, pointsY, false, false); });
    BOOST_TEST(has(e, journal + " line 3: the row of point 1 has interfaces[*].friction_coefficient = 0.5, but point 1 "
                                "of this spec has interfaces[*].friction_coefficient = 0.4"));
    // a journal whose id line is another spec's is refused by the id too
    const std::string dir2 = fresh_dir("relabel_id");
    { SweepDirectory d(dir2, points, false, false); }
    fs::copy_file(dir + "/spec.json", dir2 + "/spec.json", fs::copy_options::overwrite_existing);  // mapY's
    const std::string e2 = error_of([&] { SweepDirectory y(dir2, pointsY, false, false); });
    BOOST_TEST(has(e2, "line 1 says '# stackbeam sweep journal: spec " + sweep_spec_id(map)));
}

// Issue 41 item 7: a damaged row in the middle is named by its line; the rows after it are kept.
BOOST_AUTO_TEST_CASE(damaged_middle_row_keeps_later_rows) {
    const SweepSpec spec = map_with_mu("[0.3, 0.5]");
    const SweepPoints points(spec);
    const std::string dir = directory_with_rows("damaged", points, 4);
    const std::string journal = dir + "/finished.csv";
    auto lines = lines_of(journal);
    lines[3] = "1,0.01,0.5,ok,,not a number";  // point 1's row, damaged (line 4 of the file)
    {
        std::ofstream out(journal, std::ios::trunc);
        for (const auto& l : lines) out << l << "\n";
        out << "3,0.02,";  // and a last row cut by a crash
    }
    SweepDirectory d(dir, points, false, false);
    BOOST_TEST(d.finished_count() == 3);  // points 0, 2, 3: the rows after the damaged one kept
    BOOST_TEST(!d.finished()[1]);
    BOOST_TEST(d.results()[3].figures[0] == 3.0);
    BOOST_REQUIRE_EQUAL(d.notes().size(), 2u);
    BOOST_TEST(has(d.notes()[0], journal + " line 4: a damaged row was dropped"));
    BOOST_TEST(has(d.notes()[1], journal + " line 7: a row cut short"));
    // the journal is repaired whole: the id, the header and the three good rows
    BOOST_TEST(lines_of(journal).size() == 5u);
}

// Issue 41 item 3: the per-point files of points without a row are another run's: removed when
// the directory is opened, and a point's scenario is written by the run that writes its row.
BOOST_AUTO_TEST_CASE(stale_point_files_rewritten) {
    const SweepSpec old_spec = map_with_mu("[0.3, 0.5]");
    const SweepSpec spec = map_with_mu("[0.3, 0.4]");
    const SweepPoints old_points(old_spec), points(spec);
    const std::string dir = directory_with_rows("stale", old_points, 4);
    const std::string scenario1 = point_file(dir, "scenarios", 1, "toml");
    BOOST_TEST(has(read(scenario1), "friction_coefficient = 0.5"));
    // the journal and tables gone, the scenarios left: the new spec's run must not reuse them
    for (const char* f : {"finished.csv", "points.csv", "sweep.json", "spec.json"}) fs::remove(fs::path(dir) / f);
    SweepDirectory d(dir, points, false, false);
    BOOST_TEST(!fs::exists(scenario1));  // no row owns it: removed
    d.record(row_of(1));
    const std::string text = read(scenario1);
    BOOST_TEST(has(text, "friction_coefficient = 0.4"));
    BOOST_TEST(!has(text, "friction_coefficient = 0.5"));
    BOOST_TEST(text.substr(text.find('\n') + 1) == points.point(1).scenario_text);  // the point's own file
}

// Issue 41 item 6: a million points are refused at once with the size; the lazy points are the
// expanded ones, figure for figure, and making point 0 costs no memory proportional to the count.
BOOST_AUTO_TEST_CASE(point_limit_and_lazy_points) {
    const std::string e = error_of([&] {
        parse_sweep_spec("scenario = \"rig_small.toml\"\n[[axes]]\nkey = \"loading.displacement_m.amplitude\"\n"
                         "from = 0.01\nto = 0.02\ncount = 1000000\n",
                         kSource);
    });
    BOOST_TEST(has(e, "axes: the spec has 1000000 points (product of 1000000 values): at most 100000 points"));
    const std::string e2 = error_of([&] {
        parse_sweep_spec("scenario = \"rig_small.toml\"\n"
                         "[[axes]]\nkey = \"loading.displacement_m.amplitude\"\nfrom = 0.01\nto = 0.02\ncount = 1000\n"
                         "[[axes]]\nkey = \"loading.displacement_m.frequency_hz\"\nfrom = 1.0\nto = 2.0\ncount = 1000\n",
                         kSource);
    });
    BOOST_TEST(has(e2, "the spec has 1000000 points (product of 1000 x 1000 values)"));
    // the largest allowed: 100,000 points; only point 0 is made (lazily): the memory growth it
    // costs is the base document and one point, far below 100,000 x ~17 kB = 1.7 GB (bound: 64 MB)
    rusage before{};
    ::getrusage(RUSAGE_SELF, &before);
    const SweepSpec big = parse_sweep_spec("scenario = \"rig_small.toml\"\n"
                                           "[[axes]]\nkey = \"loading.displacement_m.amplitude\"\nfrom = 0.01\nto = 0.02\n"
                                           "count = 1000\n[[axes]]\nkey = \"interfaces[*].friction_coefficient\"\n"
                                           "from = 0.1\nto = 0.5\ncount = 100\n",
                                           kSource);
    const SweepPoints lazy(big);
    BOOST_TEST(lazy.size() == 100000);
    const SweepPoint p0 = lazy.point(0), last = lazy.point(99999);
    rusage after{};
    ::getrusage(RUSAGE_SELF, &after);
    BOOST_TEST(after.ru_maxrss - before.ru_maxrss < 64 * 1024);  // kB
    BOOST_TEST(to_string(last.values[0]) == "0.02");
    BOOST_TEST(to_string(last.values[1]) == "0.5");
    // lazy point i is expand_points' point i, text for text
    const SweepSpec small = map_with_mu("[0.3, 0.5]");
    const auto all = expand_points(small);
    const SweepPoints made(small);
    BOOST_REQUIRE_EQUAL(made.size(), static_cast<int>(all.size()));
    for (int i = 0; i < made.size(); ++i) BOOST_TEST(made.point(i).scenario_text == all[static_cast<std::size_t>(i)].scenario_text);
}

// Issue 41 items 6, 7: inputs that are not regular files are refused by name before any read
// (a FIFO without a writer would block, /dev/zero would fill memory); keys and paths by name.
BOOST_AUTO_TEST_CASE(bad_inputs_named) {
    const std::string dir = fresh_dir("inputs");
    fs::create_directories(dir);
    const std::string fifo = dir + "/fifo.toml";
    BOOST_REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
    auto spec_with = [&](const std::string& scenario) {
        return error_of([&] {
            parse_sweep_spec("scenario = \"" + scenario + "\"\n[[axes]]\nkey = \"x\"\nvalues = [1]\n", dir + "/spec.toml");
        });
    };
    BOOST_TEST(has(spec_with("/dev/zero"), "scenario: the base scenario file '/dev/zero' is a character device: a regular file is required"));
    BOOST_TEST(has(spec_with(dir), "'" + dir + "' is a directory: a regular file is required"));
    BOOST_TEST(has(spec_with(fifo), "is a FIFO (named pipe): a regular file is required"));
    BOOST_TEST(has(error_of([&] { load_scenario(fifo); }), "is a FIFO (named pipe)"));
    BOOST_TEST(has(error_of([&] { load_sweep_spec("/dev/zero"); }), "spec: the sweep spec file '/dev/zero' is a character device"));
    // the spec as its own scenario
    const std::string self = dir + "/self.toml";
    std::ofstream(self) << "scenario = \"self.toml\"\n[[axes]]\nkey = \"x\"\nvalues = [1]\n";
    BOOST_TEST(has(error_of([&] { load_sweep_spec(self); }), "self.toml:1: scenario: value '" + self + "' is the sweep spec itself"));
    // a file over the cap (16 MiB): refused by its size, before reading it
    const std::string huge = dir + "/huge.toml";
    { std::ofstream(huge) << "# x\n"; }
    fs::resize_file(huge, 17 * 1024 * 1024);
    BOOST_TEST(has(spec_with(huge), "has 17825792 bytes: at most 16777216 are read"));
    // a 20-digit index: named, not std::stoul's bare "stoul"
    const std::string e = error_of([&] {
        parse_sweep_spec("scenario = \"rig_small.toml\"\n[[axes]]\nkey = \"leaves[99999999999999999999].height_m\"\n"
                         "values = [0.01]\n",
                         kSource);
    });
    BOOST_TEST(has(e, "axes[0].key: value 'leaves[99999999999999999999].height_m' is not a key path: index "
                      "'[99999999999999999999]' is too large"));
    fs::remove_all(dir);
}

// Issue 43 (decision 061), issue 44 (decision 068): a sweep directory begun before the points table had
// the windup columns, or also the stress columns
// (stress_max_abs_pa, fatigue_least_safety_factor) cannot be resumed, its rows two cells short: a
// named error that says so and what to do (--restart, or another --out-dir), never a row dropped as
// "damaged" one by one; --restart then starts it over. The old directory is made from a new one by
// taking the two columns out of its journal and the "stresses" key out of its spec.json, as the
// older program wrote them. A directory begun with [outputs] stresses = false is refused when the
// spec now asks for them (its rows' columns would stay empty), and the other way round. A refused
// directory releases its lock: the --restart right after it, in the same process, is not refused
// as "in use" (it was: the lock's descriptor stayed open when the constructor threw).
BOOST_AUTO_TEST_CASE(directory_from_before_the_stress_columns_named) {
    const SweepSpec spec = map_with_mu("[0.3, 0.5]");
    const SweepPoints points(spec);
    const std::string dir = directory_with_rows("before_stresses", points, 2);
    const std::string journal = dir + "/finished.csv";
    auto lines = lines_of(journal);
    BOOST_REQUIRE_EQUAL(lines.size(), 4u);  // the spec's id, the header, 2 rows
    auto cells = [](const std::string& line) {
        std::vector<std::string> c(1);
        for (char ch : line) {
            if (ch == ',') c.emplace_back();
            else c.back().push_back(ch);
        }
        return c;
    };
    const auto header = cells(lines[1]);
    // the older journals, each as that program wrote it: without the windup columns (decision 068), and
    // from before both the stress columns and those; the newest journal's lines kept to write them from
    const std::vector<std::string> windup = {"windup_stiffness_n_m_per_rad", "windup_loop_area_j", "windup_loss_factor",
                                             "longitudinal_compliance_m_per_n", "tangent_vertical_rate_n_per_m"};
    const std::vector<std::string> stress = {"stress_max_abs_pa", "fatigue_least_safety_factor"};
    const auto newest = lines;
    for (const bool before_stresses : {false, true}) {
        std::vector<std::string> dropped = windup;
        if (before_stresses) dropped.insert(dropped.end(), stress.begin(), stress.end());
        std::vector<std::size_t> keep;
        for (std::size_t i = 0; i < header.size(); ++i)
            if (std::find(dropped.begin(), dropped.end(), header[i]) == dropped.end()) keep.push_back(i);
        BOOST_REQUIRE_EQUAL(keep.size() + dropped.size(), header.size());
        {
            std::ofstream old(journal, std::ios::trunc);
            old << newest[0] << "\n";
            for (std::size_t k = 1; k < newest.size(); ++k) {
                const auto c = cells(newest[k]);
                for (std::size_t i = 0; i < keep.size(); ++i) old << (i ? "," : "") << c[keep[i]];
                old << "\n";
            }
        }
        if (before_stresses) {
            std::string text = read(dir + "/spec.json");
            const std::size_t at = text.find(",\n  \"stresses\": false");
            BOOST_REQUIRE(at != std::string::npos);
            text.erase(at, std::string(",\n  \"stresses\": false").size());
            std::ofstream(dir + "/spec.json", std::ios::trunc) << text;
        }
        const std::string windup_named = "the windup columns windup_stiffness_n_m_per_rad, windup_loop_area_j, "
                                         "windup_loss_factor, longitudinal_compliance_m_per_n and "
                                         "tangent_vertical_rate_n_per_m";
        const std::string e = error_of([&] { SweepDirectory d(dir, points, false, false); });
        BOOST_TEST(has(e, "--out-dir: '" + journal + "' was written before the points table had " +
                              (before_stresses ? "the stress columns stress_max_abs_pa and fatigue_least_safety_factor and " : "") +
                              windup_named +
                              " (an older stackbeam): its rows cannot be resumed; use --restart to discard them and run "
                              "every point again, or another --out-dir"),
                   e);
    }
    {
        SweepDirectory again(dir, points, true, false);  // --restart
        BOOST_TEST(again.finished_count() == 0);
        again.record(row_of(1));
    }
    // another header (a column renamed): the first difference named, the same advice
    lines = lines_of(journal);
    {
        std::ofstream other(journal, std::ios::trunc);
        std::string h = lines[1];
        h.replace(h.find("loop_area_j"), std::string("loop_area_j").size(), "loop_area");
        other << lines[0] << "\n" << h << "\n" << lines[2] << "\n";
    }
    const std::string e2 = error_of([&] { SweepDirectory d(dir, points, false, false); });
    BOOST_TEST(has(e2, "has other columns than this program writes (another version?): column 6 is 'loop_area', this "
                       "program writes 'loop_area_j': its rows cannot be resumed; use --restart"),
               e2);

    // the stresses switched on after the directory was begun (and off again): refused by name
    const std::string dir2 = fresh_dir("stresses_switched");
    { SweepDirectory d(dir2, points, false, false); }
    const SweepSpec with = parse_sweep_spec("scenario = \"rig_small.toml\"\n[outputs]\nstresses = true\n"
                                            "[[axes]]\nkey = \"loading.displacement_m.amplitude\"\nvalues = [0.01, 0.02]\n"
                                            "[[axes]]\nkey = \"interfaces[*].friction_coefficient\"\nvalues = [0.3, 0.5]\n",
                                            kSource);
    BOOST_TEST(sweep_spec_id(with) == sweep_spec_id(spec));  // the journal's id: the points' values only
    const SweepPoints with_points(with);
    const std::string e3 = error_of([&] { SweepDirectory d(dir2, with_points, false, false); });
    BOOST_TEST(has(e3, "holds the results of another sweep: it was begun with [outputs] stresses = false, the spec now "
                       "says true (its rows' stress columns would be empty where the new rows' are not); use another "
                       "directory, or --restart"),
               e3);
    fs::remove_all(dir);
    fs::remove_all(dir2);
}
