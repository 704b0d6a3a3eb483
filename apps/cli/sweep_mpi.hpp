#pragma once
/// @file sweep_mpi.hpp
/// `mpirun -n N stackbeam sweep SPEC.toml`: the points spread over the ranks (built when
/// CMake finds MPI: STACKBEAM_WITH_MPI). Rank 0 owns the sweep directory and hands the
/// points out one at a time, on request (points differ in cost by orders of magnitude):
/// its main thread serves the other ranks' requests while a thread of its own runs
/// points too; every other rank asks for a point, runs it (run_point), writes its files
/// and sends its row back with the next request. Only rank 0's main thread calls MPI
/// (MPI_THREAD_FUNNELED). The table is the one a serial run writes: each point's row is
/// computed by the same code, rows are put in point order at the end.
#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "stackbeam/study/sweep.hpp"
#include "stackbeam/study/sweep_output.hpp"

namespace stackbeam::cli {

/// MPI_COMM_WORLD as this process sees it.
struct MpiWorld {
    bool active = false;  ///< MPI initialised (started by mpirun with more than one rank)
    int rank = 0;
    int size = 1;
};

/// Initialises MPI when the process was started by mpirun/mpiexec (OpenMPI's, or a PMI
/// launcher's variables); a plain command never touches MPI. Throws if started by a
/// launcher with several ranks and this program was built without MPI.
MpiWorld mpi_start(int& argc, char**& argv);
/// MPI_Finalize (when active).
void mpi_finish(const MpiWorld& world);
/// Aborts every rank (a rank's error the others cannot see).
[[noreturn]] void mpi_abort(const MpiWorld& world, int status);

/// Rank 0: runs `pending` (point indices) on its own thread and on the other ranks, calling
/// `record_local` (this rank's results, records attached) and `record_remote` (another rank's
/// row) from the calling thread or its worker, one at a time. Returns when every point ran
/// or `stop` was set and the ranks have been told.
void mpi_serve(const MpiWorld& world, const std::vector<SweepPoint>& points, const std::vector<int>& pending,
               const std::atomic<bool>& stop, const std::function<void(const PointResult&)>& record_local,
               const std::function<void(const std::string&)>& record_remote);

/// Any other rank: asks rank 0 for points until told none is left (or `stop`), runs them,
/// writes their files in `directory`, sends their rows back.
void mpi_work(const MpiWorld& world, const std::vector<SweepPoint>& points, const std::string& directory,
              bool keep_series, const std::atomic<bool>& stop);

}  // namespace stackbeam::cli
