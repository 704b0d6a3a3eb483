// `stackbeam sweep SPEC.toml`: the arguments, progress, signals, figures, MPI (sweep.hpp).
#include "sweep.hpp"

#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <mutex>
#include <thread>

#include "options.hpp"
#include "run.hpp"
#include "stackbeam/errors.hpp"
#include "stackbeam/study/sweep.hpp"
#include "stackbeam/study/sweep_output.hpp"
#include "sweep_mpi.hpp"
#include "sweep_plot.hpp"

namespace stackbeam::cli {

namespace {

std::atomic<bool> g_stop{false};
volatile std::sig_atomic_t g_signal = 0;

extern "C" void on_sweep_signal(int signal) {
    g_signal = signal;
    g_stop.store(true);  // lock-free (checked below): async-signal-safe
}

static_assert(std::atomic<bool>::is_always_lock_free, "the stop flag is set from a signal handler");

std::string clock_text(double s) {
    const long t = static_cast<long>(s + 0.5);
    char b[32];
    if (t >= 3600) std::snprintf(b, sizeof b, "%ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
    else std::snprintf(b, sizeof b, "%ld:%02ld", t / 60, t % 60);
    return b;
}

/// Points done of total, failed, elapsed, estimated time left: rewritten in place on a
/// terminal (stderr), one line per point with --progress on a pipe, nothing otherwise.
class SweepProgress {
public:
    SweepProgress(bool asked, int total, int done_before)
        : terminal_(isatty(fileno(stderr)) != 0), enabled_(terminal_ || asked), total_(total), done_(done_before),
          before_(done_before), t0_(std::chrono::steady_clock::now()) {}
    void point_done(bool failed) {
        ++done_;
        if (failed) ++failed_;
        if (!enabled_) return;
        const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
        const int run = done_ - before_;
        const double left = run > 0 ? elapsed / run * (total_ - done_) : 0.0;
        std::fprintf(stderr, "%ssweep: %d of %d points, %d failed, %s elapsed, ~%s left%s", terminal_ ? "\r" : "", done_,
                     total_, failed_, clock_text(elapsed).c_str(), clock_text(left).c_str(), terminal_ ? "   " : "\n");
        std::fflush(stderr);
        shown_ = true;
    }
    void finish() {
        if (terminal_ && shown_) std::fprintf(stderr, "\n");
    }
    int failed() const { return failed_; }

private:
    bool terminal_, enabled_;
    int total_, done_, before_, failed_ = 0;
    bool shown_ = false;
    std::chrono::steady_clock::time_point t0_;
};

}  // namespace

CLI::App* add_sweep_command(CLI::App& app, SweepArgs& a) {
    CLI::App& sweep = *app.add_subcommand("sweep", "Run a base scenario at many points (axes over any scenario key) on threads or "
                                                   "MPI ranks: a table of loop figures, resumable (docs/sweep.md)");
    sweep.footer("Exit status: 0 every point ok, 2 bad spec (nothing run), 3 some points failed (their rows say why),\n"
                 "130 / 143 stopped by SIGINT / SIGTERM (run the same command again to resume), 1 other errors.\n"
                 "Under MPI: mpirun -n N stackbeam sweep SPEC.toml (rank 0 writes DIR, every rank runs points).");
    sweep.add_option("spec", a.spec, "the sweep spec (TOML, docs/sweep.md): the base scenario and the axes")
        ->required()
        ->type_name("SPEC.toml");
    sweep.add_option("--jobs,-j", a.jobs,
                     "points run at once, on threads (default: the machine's cores; 1 per rank under mpirun)")
        ->type_name("N")
        ->check(CLI::Range(1, 4096));
    sweep.add_option("--out-dir", a.out_dir, "the results' directory (default: the spec's [outputs] directory)")
        ->type_name("DIR");
    sweep.add_flag("--restart", a.restart, "discard the results already in DIR and start over (default: resume)");
    sweep.add_flag("--keep-series", a.keep_series, "keep every point's records: DIR/series/point-NNNN.csv");
    sweep.add_flag("--progress", a.progress, "progress lines on stderr also when it is not a terminal");
    sweep.add_flag("--no-plot", a.no_plot, "no gnuplot figures");
    sweep.add_option("--stop-after", a.stop_after, "tests: stop as on SIGINT after this many points")
        ->group("")  // hidden
        ->check(CLI::Range(1, 1 << 30));
    return &sweep;
}

int run_sweep_command(const SweepArgs& a, MpiWorld world) {
    const auto t0 = std::chrono::steady_clock::now();
    // every point's scenario is read and checked before any run (and before DIR is touched)
    const SweepSpec spec = load_sweep_spec(a.spec);  // refuses more than max_sweep_points points, with the size
    const SweepPoints points(spec);                 // made one at a time: memory does not grow with the count
    const bool show = world.rank == 0 && (a.progress || isatty(fileno(stderr)) != 0);
    {
        // every point made and checked in turn (none kept), with progress from the start
        const bool terminal = isatty(fileno(stderr)) != 0;
        const int total = points.size();
        auto last = std::chrono::steady_clock::now();
        if (show)
            std::fprintf(stderr, "%ssweep: checking %d points%s", terminal ? "\r" : "", total, terminal ? "" : "\n");
        points.check_all([&](int checked) {
            if (!show || !terminal) return;
            const auto now = std::chrono::steady_clock::now();
            if (checked < total && now - last < std::chrono::milliseconds(200)) return;
            last = now;
            std::fprintf(stderr, "\rsweep: checking points: %d of %d", checked, total);
            std::fflush(stderr);
        });
        if (show && terminal) std::fprintf(stderr, "\n");
    }
    const std::string directory = !a.out_dir.empty() ? a.out_dir : spec.output_directory;
    if (directory.empty())
        throw ArgumentError("--out-dir: a results directory is required (none given, and " + a.spec +
                            " has no [outputs] directory)");
    if (world.active && world.size > 1 && a.jobs > 1)
        throw ArgumentError("--jobs: value " + std::to_string(a.jobs) +
                            " under mpirun: each rank runs one point at a time (start one rank per core)");
    const int jobs = world.active && world.size > 1 ? 1
                     : a.jobs > 0                   ? a.jobs
                                                    : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
    install_stop_handlers(on_sweep_signal);
    if (world.rank != 0) {
#ifdef STACKBEAM_WITH_MPI
        mpi_work(world, points, directory, a.keep_series, g_stop);
#endif
        return g_signal != 0 ? 128 + g_signal : exit_ok;
    }

    SweepDirectory out(directory, points, a.restart, a.keep_series);  // locked: a second sweep there is refused
    for (const std::string& note : out.notes()) std::fprintf(stderr, "stackbeam: note: %s\n", note.c_str());
    const int total = points.size();
    const int before = out.finished_count();
    if (before > 0 && before < total)
        std::printf("resuming                   %d of %d points finished in %s\n", before, total, directory.c_str());
    SweepProgress progress(a.progress, total, before);
    int recorded = 0;
    auto after_record = [&](bool failed) {
        progress.point_done(failed);
        if (a.stop_after > 0 && ++recorded >= a.stop_after) g_stop = true;
    };
    auto record = [&](const PointResult& r) {
        out.record(r);
        after_record(r.status != PointStatus::ok);
    };
    if (world.active && world.size > 1) {
#ifdef STACKBEAM_WITH_MPI
        std::vector<int> pending;
        for (int i = 0; i < total; ++i)
            if (!out.finished()[static_cast<std::size_t>(i)]) pending.push_back(i);
        mpi_serve(world, points, pending, g_stop, record, [&](const std::string& row) {
            out.record_row(row);
            after_record(out.results()[static_cast<std::size_t>(parse_point_row(spec, row).index)].status !=
                         PointStatus::ok);
        });
#endif
    } else {
        SweepRunOptions options;
        options.jobs = jobs;
        options.skip = out.finished();
        options.stop = &g_stop;
        run_sweep(points, options, record);
    }
    progress.finish();
    SweepTotals totals;
    totals.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    totals.jobs = jobs;
    totals.processes = world.active ? world.size : 1;
    out.finish(totals);

    int ok = 0, failed = 0, finished = 0;
    for (int i = 0; i < total; ++i) {
        if (!out.finished()[static_cast<std::size_t>(i)]) continue;
        ++finished;
        (out.results()[static_cast<std::size_t>(i)].status == PointStatus::ok ? ok : failed) += 1;
    }
    std::printf("points                     %d of %d finished: %d ok, %d failed\n", finished, total, ok, failed);
    std::printf("table                      %s/points.csv\n", directory.c_str());
    if (finished < total) {
        const int signal = g_signal != 0 ? g_signal : SIGINT;  // --stop-after: as SIGINT
        std::fprintf(stderr,
                     "stackbeam: sweep stopped (signal %d): %d of %d points finished, kept in %s; run the same command "
                     "again to resume (the finished points are not run again)\n",
                     signal, finished, total, directory.c_str());
        return 128 + signal;
    }
    if (!a.no_plot) {
        std::string note;
        const auto files = plot_sweep(directory, spec, points, out.results(), note);
        for (const auto& f : files) std::printf("figure                     %s\n", f.c_str());
        if (files.empty()) std::printf("figures                    none: %s\n", note.c_str());
    }
    std::printf("wall time                  %.3f s (%d %s)\n", totals.wall_s, world.active ? world.size : jobs,
                world.active ? "ranks" : "threads");
    if (failed > 0) {
        std::fprintf(stderr, "stackbeam: %d of %d points failed (status and message in %s/points.csv)\n", failed, total,
                     directory.c_str());
        return exit_solver;
    }
    return exit_ok;
}

}  // namespace stackbeam::cli
