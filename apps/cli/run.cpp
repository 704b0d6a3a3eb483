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

/// Thrown from the per-record callback when a stop was asked for.
struct Interrupted {};

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

void RunStats::add(const StepRecord& r) {
    if (records == 0) {
        first = r;
        w_min_m = w_max_m = r.w_m;
        force_min_n = force_max_n = r.spring_force_n;
    }
    last = r;
    ++records;
    contact_iterations += r.contact_iterations;
    max_contact_iterations = std::max(max_contact_iterations, r.contact_iterations);
    max_abs_balance_j = std::max(max_abs_balance_j, std::abs(r.energy_balance_error_j));
    w_min_m = std::min(w_min_m, r.w_m);
    w_max_m = std::max(w_max_m, r.w_m);
    force_min_n = std::min(force_min_n, r.spring_force_n);
    force_max_n = std::max(force_max_n, r.spring_force_n);
}

void install_interrupt_handlers() { install_stop_handlers(on_stop_signal); }

void install_stop_handlers(void (*handler)(int)) {
    struct sigaction action {};
    action.sa_handler = handler;
    sigemptyset(&action.sa_mask);
    action.sa_flags = 0;
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
}

RunResult run(const RunRequest& request, const System& system) {
    const auto t0 = std::chrono::steady_clock::now();
    // SIGINT / SIGTERM reach the library's stop check too, so a long step between two outputs
    // (mode cvode: the event driver polls it inside its step loop) stops promptly
    SimulationOptions options = request.options;
    options.stop_requested = [] { return g_stop_signal != 0; };
    PartialFile csv(request.out, "--out");
    PartialFile pairs_csv(request.pairs, "--pairs");
    PartialFile nodes_csv(request.nodes, "--nodes");
    write_csv_header(csv.stream());
    if (pairs_csv.active()) pairs_csv.stream() << "t,pair,interface,x,state,p_n,p_t,gap,slip\n";
    pairs_csv.stream().precision(17);
    if (nodes_csv.active()) nodes_csv.stream() << "t,leaf,x,w,theta\n";
    nodes_csv.stream().precision(17);
    // --plot: the stack at the extreme deflections, kept as the run finds them (a new max or min of w
    // marks the record in on_step; its pairs and nodes follow in on_pairs, on_nodes)
    const bool snapshots = !request.plot.empty();
    std::vector<StackSnapshot*> marked;  // the snapshots the current record replaces

    RunResult result;
    Progress progress(!request.quiet, options.t_end_s);
    PairObserver on_pairs;
    if (pairs_csv.active() || snapshots)
        on_pairs = [&](double t, const std::vector<PairRecord>& prs) {
            for (StackSnapshot* s : marked) s->pairs = prs;
            if (!pairs_csv.active()) return;
            auto& o = pairs_csv.stream();
            for (const auto& p : prs)
                o << t << ',' << p.pair << ',' << p.interface_index << ',' << p.x_m << ',' << to_string(p.state) << ','
                  << p.p_n_n << ',' << p.p_t_n << ',' << p.gap_m << ',' << p.slip_m << '\n';
        };
    NodeObserver on_nodes;
    if (nodes_csv.active() || snapshots)
        on_nodes = [&](double t, const std::vector<LeafNodes>& leaves) {
            for (StackSnapshot* s : marked) s->nodes = leaves;
            if (!nodes_csv.active()) return;
            auto& o = nodes_csv.stream();
            for (const auto& leaf : leaves)
                for (std::size_t j = 0; j < leaf.x_m.size(); ++j)
                    o << t << ',' << leaf.leaf << ',' << leaf.x_m[j] << ',' << leaf.w_m[j] << ',' << leaf.theta_rad[j] << '\n';
        };
    // A record's pairs follow it (simulate calls on_pairs after on_step): stopping before
    // a record is written leaves the CSV and the pairs at the same last whole record.
    auto on_step = [&](const StepRecord& r) {
        if (g_stop_signal != 0) throw Interrupted{};
        write_csv_row(csv.stream(), r);
        csv.check();  // a write error (a full disk) stops the run at once, with the system's reason
        pairs_csv.check();
        nodes_csv.check();
        marked.clear();
        if (snapshots) {
            if (result.stats.records == 0 || r.w_m > result.stats.w_max_m) marked.push_back(&result.stack_at_w_max);
            if (result.stats.records == 0 || r.w_m < result.stats.w_min_m) marked.push_back(&result.stack_at_w_min);
            for (StackSnapshot* s : marked) {
                s->t_s = r.t_s;
                s->w_m = r.w_m;
            }
        }
        result.stats.add(r);
        progress.update(r.t_s);
    };
    // A stop (the signal seen between records, or by the library's stop check within a step): the
    // whole records so far are kept in the partial files.
    auto stopped = [&]() -> RunResult {
        progress.finish();
        result.signal = g_stop_signal;
        csv.close();
        pairs_csv.close();
        nodes_csv.close();
        result.csv_file = csv.partial();
        if (pairs_csv.active()) result.pairs_file = pairs_csv.partial();
        if (nodes_csv.active()) result.nodes_file = nodes_csv.partial();
        result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        std::cerr << "stackbeam: interrupted by signal " << result.signal << " at t = " << result.stats.last.t_s
                  << " s; the rows up to it are in " << csv.partial() << "\n";
        return result;
    };
    try {
        result.records = simulate(system, options, on_step, &result.report, on_pairs, on_nodes);
        progress.finish();
    } catch (const Interrupted&) {
        return stopped();
    } catch (const RunStopped&) {  // the library's stop check saw the signal within a step
        return stopped();
    } catch (const InputError&) {
        // bad input found when the run starts (e.g. an option the mode cannot use): no rows to keep
        progress.finish();
        csv.discard();
        pairs_csv.discard();
        nodes_csv.discard();
        throw;
    } catch (...) {
        progress.finish();
        csv.keep_whole_rows();
        pairs_csv.keep_whole_rows();
        nodes_csv.keep_whole_rows();
        std::cerr << "stackbeam: note: " << request.out << " was not written; the rows up to the failure are in "
                  << csv.partial() << "\n";
        throw;
    }
    if (!request.events.empty()) {
        PartialFile ev(request.events, "--events");
        write_events_csv(ev.stream(), result.report.events);
        ev.commit();
        result.events_file = request.events;
    }
    csv.commit();
    pairs_csv.commit();
    nodes_csv.commit();
    result.csv_file = request.out;
    result.pairs_file = request.pairs;
    result.nodes_file = request.nodes;
    result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return result;
}

}  // namespace stackbeam::cli
