// The run of `stackbeam simulate`: rows streamed to FILE.partial, progress, interruption.
#include "run.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iostream>

#include "stackbeam/errors.hpp"
#include "stackbeam/io/csv.hpp"

namespace stackbeam::cli {

namespace {

volatile std::sig_atomic_t g_stop_signal = 0;

extern "C" void on_stop_signal(int signal) { g_stop_signal = signal; }

/// A file written as FILE.partial and renamed to FILE when the whole run succeeded.
class PartialFile {
public:
    PartialFile(const std::string& path, const std::string& option) : path_(path), partial_(path + ".partial") {
        if (path_.empty()) return;
        errno = 0;
        stream_.open(partial_, std::ios::out | std::ios::trunc);
        if (!stream_)
            throw ArgumentError(option + ": cannot open '" + partial_ + "' for writing" +
                                (errno != 0 ? std::string(": ") + std::strerror(errno) : std::string()));
    }
    /// Throws (the system's reason) when a write failed (a full disk), after cutting the file
    /// back to its last whole row.
    void check() {
        if (!active() || stream_.good()) return;
        fail();
    }
    bool active() const { return !path_.empty(); }
    std::ofstream& stream() { return stream_; }
    const std::string& partial() const { return partial_; }
    /// Closes and renames; throws if writing failed.
    void commit() {
        if (!active()) return;
        close();
        if (std::rename(partial_.c_str(), path_.c_str()) != 0)
            throw std::runtime_error("cannot rename '" + partial_ + "' to '" + path_ + "': " + std::strerror(errno));
    }
    /// Closes and keeps FILE.partial (an interrupted or failed run); throws if writing failed.
    void close() {
        if (!active()) return;
        if (!stream_.is_open()) return;
        errno = 0;
        stream_.close();
        if (stream_.fail()) fail();
    }
    /// Flushes and closes after a failure elsewhere, keeping whole rows only.
    void keep_whole_rows() {
        if (!active() || !stream_.is_open()) return;
        stream_.close();
        trim();
    }
    /// Removes the partial file (bad input found before any result).
    void discard() {
        if (!active()) return;
        stream_.close();
        std::remove(partial_.c_str());
    }

private:
    [[noreturn]] void fail() {
        const std::string why = errno != 0 ? std::strerror(errno) : "the stream reported an error";
        if (stream_.is_open()) stream_.close();
        trim();
        throw std::runtime_error("writing '" + partial_ + "' failed: " + why + " (it keeps the whole rows written before)");
    }
    /// Cuts FILE.partial after its last line break: a row half written (a full disk, the
    /// buffer flushed in part) is removed, so the file ends on a whole row as documented.
    void trim() {
        const int fd = ::open(partial_.c_str(), O_RDWR | O_CLOEXEC);
        if (fd < 0) return;
        struct stat st {};
        off_t keep = 0;
        if (::fstat(fd, &st) == 0) {
            char buffer[4096];
            for (off_t end = st.st_size; end > 0 && keep == 0;) {
                const off_t begin = std::max<off_t>(0, end - static_cast<off_t>(sizeof buffer));
                const ssize_t n = ::pread(fd, buffer, static_cast<std::size_t>(end - begin), begin);
                if (n <= 0) break;
                for (ssize_t i = n; i-- > 0;)
                    if (buffer[i] == '\n') {
                        keep = begin + i + 1;
                        break;
                    }
                end = begin;
            }
            if (keep < st.st_size) (void)::ftruncate(fd, keep);
        }
        ::close(fd);
    }
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

}  // namespace

void install_interrupt_handlers() { install_stop_handlers(on_stop_signal); }

void install_stop_handlers(void (*handler)(int)) {
    struct sigaction action {};
    action.sa_handler = handler;
    sigemptyset(&action.sa_mask);
    action.sa_flags = 0;
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
}

namespace {

/// The run's rows to the files (--out, --pairs, --nodes), the progress line and, for --plot, the
/// stack at the extreme deflections: the library's RunSink.
class FileSink : public RunSink {
public:
    FileSink(const SimulateRequest& request, RunResult& result)
        : csv(request.out, "--out"), pairs_csv(request.pairs, "--pairs"), nodes_csv(request.nodes, "--nodes"),
          stresses_csv(request.stresses, "--stresses"),
          progress(!request.quiet, request.options.t_end_s), snapshots_(!request.plot.empty()),
          snapshot_stresses_(snapshots_ && request.stack_stress), result_(result) {
        result_.snapshots_by_seat_rotation = loads_the_seat(request.options.loading);
        write_csv_header(csv.stream());
        if (pairs_csv.active()) pairs_csv.stream() << "t,pair,interface,x,state,p_n,p_t,gap,slip\n";
        pairs_csv.stream().precision(17);
        if (nodes_csv.active()) nodes_csv.stream() << "t,leaf,x,w,theta\n";
        nodes_csv.stream().precision(17);
        // SI units: x [m], stresses [Pa] (tension positive), N and V [N], M [N m] (post/stresses.hpp's signs)
        if (stresses_csv.active())
            stresses_csv.stream() << "t,leaf,x,sigma_top,sigma_bottom,axial_force,bending_moment,shear_force\n";
        stresses_csv.stream().precision(17);
    }
    /// What the run hands over: pairs and nodes for their files or the stack figure.
    RunOutputs outputs() const {
        RunOutputs o;
        o.pairs = pairs_csv.active() || snapshots_;
        o.nodes = nodes_csv.active() || snapshots_;
        o.stresses = stresses_csv.active() || snapshot_stresses_;
        return o;
    }
    void on_record(const StepRecord& r) override {
        write_csv_row(csv.stream(), r);
        csv.check();  // a write error (a full disk) stops the run at once, with the system's reason
        pairs_csv.check();
        nodes_csv.check();
        stresses_csv.check();
        // --plot: a new max or min of w (of theta_R in a windup run) marks the record; its pairs and nodes
        // follow in on_pairs, on_nodes
        marked_.clear();
        if (snapshots_) {
            const double v = result_.snapshots_by_seat_rotation ? r.seat_rotation_rad : r.w_m;
            if (records_ == 0 || v > max_) marked_.push_back(&result_.stack_at_max);
            if (records_ == 0 || v < min_) marked_.push_back(&result_.stack_at_min);
            for (StackSnapshot* s : marked_) {
                s->t_s = r.t_s;
                s->w_m = r.w_m;
                s->seat_rotation_rad = r.seat_rotation_rad;
            }
            max_ = records_ == 0 ? v : std::max(max_, v);
            min_ = records_ == 0 ? v : std::min(min_, v);
        }
        ++records_;
        progress.update(r.t_s);
    }
    void on_pairs(double t, const std::vector<PairRecord>& prs) override {
        for (StackSnapshot* s : marked_) s->pairs = prs;
        if (!pairs_csv.active()) return;
        auto& o = pairs_csv.stream();
        for (const auto& p : prs)
            o << t << ',' << p.pair << ',' << p.interface_index << ',' << p.x_m << ',' << to_string(p.state) << ','
              << p.p_n_n << ',' << p.p_t_n << ',' << p.gap_m << ',' << p.slip_m << '\n';
    }
    void on_nodes(double t, const std::vector<LeafNodes>& leaves) override {
        for (StackSnapshot* s : marked_) s->nodes = leaves;
        if (!nodes_csv.active()) return;
        auto& o = nodes_csv.stream();
        for (const auto& leaf : leaves)
            for (std::size_t j = 0; j < leaf.x_m.size(); ++j)
                o << t << ',' << leaf.leaf << ',' << leaf.x_m[j] << ',' << leaf.w_m[j] << ',' << leaf.theta_rad[j] << '\n';
    }

    /// Stepper::stresses() gives whole leaves (the half model mirrored): one row per node.
    void on_stresses(double t, const Stresses& stresses) override {
        if (snapshot_stresses_)
            for (StackSnapshot* s : marked_) s->stresses = stresses.leaves;
        if (!stresses_csv.active()) return;
        auto& o = stresses_csv.stream();
        for (const LeafStresses& l : stresses.leaves)
            for (std::size_t j = 0; j < l.x_m.size(); ++j)
                o << t << ',' << l.leaf << ',' << l.x_m[j] << ',' << l.top_stress_pa[j] << ',' << l.bottom_stress_pa[j] << ','
                  << l.axial_force_n[j] << ',' << l.bending_moment_n_m[j] << ',' << l.shear_force_n[j] << '\n';
    }

    PartialFile csv, pairs_csv, nodes_csv, stresses_csv;
    Progress progress;

private:
    bool snapshots_;
    bool snapshot_stresses_;  // --stack-color stress: the snapshots keep the stresses too
    RunResult& result_;
    std::vector<StackSnapshot*> marked_;  // the snapshots the current record replaces
    long records_ = 0;
    double min_ = 0.0, max_ = 0.0;  ///< the extremes of w [m] (theta_R [rad] in a windup run) so far
};

}  // namespace

RunResult run(const SimulateRequest& request, const System& system) {
    RunResult result;
    FileSink sink(request, result);
    RunRequest run;
    run.options = request.options;
    run.setup = request.setup;
    run.outputs = sink.outputs();
    run.sink = &sink;
    // SIGINT / SIGTERM: checked before each record is written and within long steps (mode cvode:
    // the event driver polls it inside its step loop), so the run stops promptly
    run.stop = [] { return g_stop_signal != 0; };
    try {
        result.summary = run_scenario(system, run);
        sink.progress.finish();
    } catch (const InputError&) {
        // bad input found when the run starts (e.g. an option the mode cannot use): no rows to keep
        sink.progress.finish();
        sink.csv.discard();
        sink.pairs_csv.discard();
        sink.nodes_csv.discard();
        sink.stresses_csv.discard();
        throw;
    } catch (...) {
        sink.progress.finish();
        sink.csv.keep_whole_rows();
        sink.pairs_csv.keep_whole_rows();
        sink.nodes_csv.keep_whole_rows();
        sink.stresses_csv.keep_whole_rows();
        std::cerr << "stackbeam: note: " << request.out << " was not written; the rows up to the failure are in "
                  << sink.csv.partial() << "\n";
        throw;
    }
    if (result.summary.interrupted) {
        // the whole records so far are kept in the partial files
        result.signal = g_stop_signal;
        sink.csv.close();
        sink.pairs_csv.close();
        sink.nodes_csv.close();
        sink.stresses_csv.close();
        result.files.csv_file = sink.csv.partial();
        if (sink.pairs_csv.active()) result.files.pairs_file = sink.pairs_csv.partial();
        if (sink.nodes_csv.active()) result.files.nodes_file = sink.nodes_csv.partial();
        if (sink.stresses_csv.active()) result.files.stresses_file = sink.stresses_csv.partial();
        std::cerr << "stackbeam: interrupted by signal " << result.signal << " at t = " << result.summary.t_reached_s
                  << " s; the rows up to it are in " << sink.csv.partial() << "\n";
        return result;
    }
    if (!request.events.empty()) {
        PartialFile ev(request.events, "--events");
        write_events_csv(ev.stream(), result.summary.report.events);
        ev.commit();
        result.files.events_file = request.events;
    }
    sink.csv.commit();
    sink.pairs_csv.commit();
    sink.nodes_csv.commit();
    sink.stresses_csv.commit();
    result.files.csv_file = request.out;
    result.files.pairs_file = request.pairs;
    result.files.nodes_file = request.nodes;
    result.files.stresses_file = request.stresses;
    return result;
}

}  // namespace stackbeam::cli
