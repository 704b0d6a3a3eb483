// `mpirun -n N stackbeam sweep`: rank 0 hands the points out, the others run them (sweep_mpi.hpp).
#include "sweep_mpi.hpp"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <exception>
#include <future>
#include <mutex>
#include <stdexcept>
#include <thread>

#ifdef STACKBEAM_WITH_MPI
#define OMPI_SKIP_MPICXX 1  // the C interface only
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#endif

namespace stackbeam::cli {

namespace {

/// The number of ranks a launcher says this process is one of (1 when not launched by one).
int launcher_size() {
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MPI_LOCALNRANKS"})
        if (const char* v = std::getenv(name)) return std::max(1, std::atoi(v));
    return 1;
}

#ifdef STACKBEAM_WITH_MPI
constexpr int tag_request = 1;  // rank -> 0: the row of its last point ("" the first time); wants a point
constexpr int tag_point = 2;    // 0 -> rank: the point's index (int), -1: none left
constexpr int tag_leave = 3;    // rank -> 0: stopped (a signal); the row of its last finished point, if any

void check(int rc, const char* what) {
    if (rc != MPI_SUCCESS) throw std::runtime_error(std::string("MPI: ") + what + " failed (code " + std::to_string(rc) + ")");
}
#endif

}  // namespace

#ifdef STACKBEAM_WITH_MPI
/// The thread that initialises MPI and, at the end, finalizes it (MPI-3.1 12.4.3: the thread
/// that initialised MPI finalizes it). Started at once so that MPI_Init (OpenMPI: about 0.2-0.35 s,
/// mostly waiting for the launcher and loading transports) overlaps the spec's reading.
struct MpiHost {
    std::thread thread;
    std::promise<void> finish;  // set by mpi_finish: finalize now
    std::shared_future<std::string> ready;  // "" once initialised, else what failed
};
#else
struct MpiHost {};
#endif

namespace {

/// This process's rank as a launcher states it (0 when not launched by one).
int launcher_rank() {
    for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"})
        if (const char* v = std::getenv(name)) return std::max(0, std::atoi(v));
    return 0;
}

}  // namespace

MpiWorld mpi_start(int& argc, char**& argv) {
    (void)argc;
    (void)argv;
    MpiWorld world;
    const int size = launcher_size();
#ifdef STACKBEAM_WITH_MPI
    if (size <= 1 && std::getenv("OMPI_COMM_WORLD_SIZE") == nullptr) return world;  // a plain command: no MPI at all
    auto host = std::make_shared<MpiHost>();
    std::promise<std::string> ready;
    host->ready = ready.get_future().share();
    std::future<void> finish = host->finish.get_future();
    host->thread = std::thread([ready = std::move(ready), finish = std::move(finish)]() mutable {
        int provided = 0;
        if (MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided) != MPI_SUCCESS) {
            ready.set_value("MPI: MPI_Init_thread failed");
            return;
        }
        ready.set_value(provided < MPI_THREAD_SERIALIZED
                            ? "MPI: the library does not provide MPI_THREAD_SERIALIZED (MPI is initialised on a "
                              "thread of its own and called from the main thread)"
                            : "");
        finish.wait();
        MPI_Finalize();
    });
    world.active = true;
    world.rank = launcher_rank();
    world.size = std::max(1, size);
    world.host = std::move(host);
#else
    if (size > 1)
        throw std::runtime_error("started by an MPI launcher with " + std::to_string(size) +
                                 " ranks, but this stackbeam was built without MPI (install libopenmpi-dev and "
                                 "rebuild; docs/sweep.md)");
#endif
    return world;
}

void mpi_ready(const MpiWorld& world) {
#ifdef STACKBEAM_WITH_MPI
    if (!world.active) return;
    const std::string& failure = world.host->ready.get();
    if (!failure.empty()) throw std::runtime_error(failure);
    int rank = 0, size = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    if (rank != world.rank || size != world.size)
        throw std::runtime_error("MPI: rank " + std::to_string(rank) + " of " + std::to_string(size) +
                                 ", but the launcher's variables said " + std::to_string(world.rank) + " of " +
                                 std::to_string(world.size));
#else
    (void)world;
#endif
}

void mpi_finish(const MpiWorld& world) {
#ifdef STACKBEAM_WITH_MPI
    if (!world.active) return;
    world.host->ready.wait();
    world.host->finish.set_value();
    world.host->thread.join();
#else
    (void)world;
#endif
}

void mpi_abort(const MpiWorld& world, int status) {
#ifdef STACKBEAM_WITH_MPI
    if (world.active && world.host->ready.get().empty()) MPI_Abort(MPI_COMM_WORLD, status);
#else
    (void)world;
#endif
    std::exit(status);
}

#ifdef STACKBEAM_WITH_MPI
void mpi_serve(const MpiWorld& world, const SweepPoints& points, const std::vector<int>& pending,
               const std::atomic<bool>& stop, const std::function<void(const PointResult&)>& record_local,
               const std::function<void(const std::string&)>& record_remote) {
    std::atomic<std::size_t> cursor{0};
    auto next = [&]() -> int {
        if (stop.load()) return -1;
        const std::size_t k = cursor.fetch_add(1);
        return k < pending.size() ? pending[k] : -1;
    };
    std::mutex record;
    std::exception_ptr local_error;
    std::atomic<bool> abandon{false};  // the stop flag, or an error on this rank
    std::thread local([&] {
        try {
            for (int i; (i = next()) >= 0 && !abandon.load();) {
                try {
                    run_point(points.point(i), &abandon, [&](const PointResult& r) {
                        std::lock_guard<std::mutex> lock(record);
                        record_local(r);
                    });
                } catch (const SweepStopped&) {
                    return;
                }
            }
        } catch (...) {
            local_error = std::current_exception();
        }
    });
    int ranks_left = world.size - 1;
    try {
        mpi_ready(world);  // this rank's points have started meanwhile
        while (ranks_left > 0) {
            if (stop.load()) abandon = true;
            int flag = 0;
            MPI_Status status;
            check(MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status), "MPI_Iprobe");
            if (!flag) {
                std::this_thread::sleep_for(std::chrono::microseconds(500));  // a request waits 0.25 ms on average
                continue;
            }
            int length = 0;
            MPI_Get_count(&status, MPI_CHAR, &length);
            std::string row(static_cast<std::size_t>(length), '\0');
            check(MPI_Recv(&row[0], length, MPI_CHAR, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE),
                  "MPI_Recv");
            // the rank's next point first: recording the row (the journal's fsync, ~5 ms) would keep it waiting
            if (status.MPI_TAG == tag_leave) {
                --ranks_left;
            } else {
                const int index = next();
                check(MPI_Send(&index, 1, MPI_INT, status.MPI_SOURCE, tag_point, MPI_COMM_WORLD), "MPI_Send");
                if (index < 0) --ranks_left;
            }
            if (!row.empty()) {
                std::lock_guard<std::mutex> lock(record);
                record_remote(row);
            }
        }
    } catch (...) {
        abandon = true;
        local.join();
        throw;
    }
    if (stop.load()) abandon = true;
    local.join();
    if (local_error) std::rethrow_exception(local_error);
}

void mpi_work(const MpiWorld& world, const SweepPoints& points, const std::string& directory,
              bool keep_series, const std::atomic<bool>& stop) {
    mpi_ready(world);
    std::string row;  // the last finished point's row, not sent yet
    for (;;) {
        if (stop.load()) {
            check(MPI_Send(row.data(), static_cast<int>(row.size()), MPI_CHAR, 0, tag_leave, MPI_COMM_WORLD), "MPI_Send");
            return;
        }
        check(MPI_Send(row.data(), static_cast<int>(row.size()), MPI_CHAR, 0, tag_request, MPI_COMM_WORLD), "MPI_Send");
        row.clear();
        int index = -1;
        // waits by polling with short sleeps: OpenMPI's blocking receive spins, and the spinning rank
        // would hold the core rank 0's serving thread needs to answer (about 2 ms per request here)
        MPI_Request request;
        check(MPI_Irecv(&index, 1, MPI_INT, 0, tag_point, MPI_COMM_WORLD, &request), "MPI_Irecv");
        for (int done = 0;;) {
            check(MPI_Test(&request, &done, MPI_STATUS_IGNORE), "MPI_Test");
            if (done) break;
            std::this_thread::sleep_for(std::chrono::microseconds(100));
        }
        if (index < 0) return;
        const SweepPoint point = points.point(index);
        try {
            const PointResult r = run_point(point, &stop, [&](const PointResult& with_records) {
                write_point_files(directory, point, with_records, keep_series, points.spec().source);
            });
            row = format_point_row(point, r);
        } catch (const SweepStopped&) {
            row.clear();
        }
    }
}
#endif

}  // namespace stackbeam::cli
