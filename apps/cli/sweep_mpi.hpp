#pragma once
/// @file sweep_mpi.hpp
/// `mpirun -n N stackbeam sweep SPEC.toml`: the points spread over the ranks (built when
/// CMake finds MPI: STACKBEAM_WITH_MPI). Rank 0 owns the sweep directory and hands the
/// points out one at a time, on request (points differ in cost by orders of magnitude):
/// its main thread serves the other ranks' requests while a thread of its own runs
/// points too; every other rank asks for a point, runs it (run_point), writes its files
/// and sends its row back with the next request. MPI starts on a thread of its own while
/// every rank reads and checks the spec (the two take about the same time, and MPI_Init is
/// mostly waiting); that thread also finalizes MPI (MPI-3.1 12.4.3: the thread that
/// initialised it). MPI is called by one thread at a time (MPI_THREAD_SERIALIZED): the
/// process's main thread once MPI is up; rank 0's point-running thread never calls it.
/// The table is the one a serial run writes: each point's row is computed by the same
/// code, rows are put in point order at the end.
#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "stackbeam/study/sweep.hpp"
#include "stackbeam/study/sweep_output.hpp"

namespace stackbeam::cli {

struct MpiHost;  // the thread that initialises and finalizes MPI (sweep_mpi.cpp)

/// MPI_COMM_WORLD as this process sees it.
struct MpiWorld {
    bool active = false;  ///< started by mpirun: MPI initialised, or being initialised by `host`
    int rank = 0;         ///< from the launcher's variables; checked against MPI's once it is up
    int size = 1;
    std::shared_ptr<MpiHost> host;
};

/// Starts initialising MPI, on a thread of its own, when the process was started by
/// mpirun/mpiexec (OpenMPI's, or a PMI launcher's variables; rank and size are read from
/// them at once); a plain command never touches MPI. Throws if started by a launcher with
/// several ranks and this program was built without MPI.
MpiWorld mpi_start(int& argc, char**& argv);
/// Waits until MPI is initialised (before the first MPI call); throws if it could not be,
/// or if it gives another rank or size than the launcher's variables.
void mpi_ready(const MpiWorld& world);
/// MPI_Finalize on the thread that initialised MPI (when active).
void mpi_finish(const MpiWorld& world);
/// Aborts every rank (a rank's error the others cannot see).
[[noreturn]] void mpi_abort(const MpiWorld& world, int status);

/// Rank 0: runs `pending` (point indices) on its own thread and on the other ranks, calling
/// `record_local` (this rank's results, records attached) and `record_remote` (another rank's
/// row) from the calling thread or its worker, one at a time. Returns when every point ran
/// or `stop` was set and the ranks have been told.
void mpi_serve(const MpiWorld& world, const SweepPoints& points, const std::vector<int>& pending,
               const std::atomic<bool>& stop, const std::function<void(const PointResult&)>& record_local,
               const std::function<void(const std::string&)>& record_remote);

/// Any other rank: asks rank 0 for points until told none is left (or `stop`), runs them,
/// writes their files in `directory`, sends their rows back.
void mpi_work(const MpiWorld& world, const SweepPoints& points, const std::string& directory,
              bool keep_series, const std::atomic<bool>& stop);

}  // namespace stackbeam::cli
