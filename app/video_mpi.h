// `evfs video` across processes with Open MPI: `mpirun -np N evfs video ...`. Rank 0 checks
// --out, prepares the work folder and hands windows out one at a time as the other ranks ask
// (so slow windows do not stall the rest); the other ranks solve them and write their frames
// into the work folder, which all ranks must see (one machine, or a shared file system); rank 0
// then assembles timestamps, summary and video. Built when CMake finds MPI (EVFS_WITH_MPI).
#ifndef EVFS_APP_VIDEO_MPI_H_
#define EVFS_APP_VIDEO_MPI_H_

#include <memory>
#include <string>

#include "evfs/app/video_job.h"

namespace evfs {

/// True when this build has MPI and the process was started by mpirun/srun with 2 ranks or
/// more (Open MPI's OMPI_COMM_WORLD_SIZE, or PMI_SIZE).
bool LaunchedAsMpiJob();

/// One MPI job's video distribution: MPI_Init on construction, MPI_Finalize on destruction.
/// Throws InvalidArgumentError in a build without MPI.
class MpiVideoSession {
 public:
  MpiVideoSession();
  ~MpiVideoSession();
  MpiVideoSession(const MpiVideoSession&) = delete;
  MpiVideoSession& operator=(const MpiVideoSession&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  /// Rank 0's `text` on every rank.
  std::string Broadcast(const std::string& text) const;
  /// This rank's part: the coordinator on rank 0, a worker elsewhere.
  const VideoDistribution& distribution() const { return distribution_; }
  /// A worker tells rank 0 that all its windows are written.
  void WorkerFinished() const;
  /// A worker tells rank 0 that it failed (after printing why): rank 0 removes the work folder
  /// and ends every rank.
  void WorkerFailed() const;
  /// Ends every rank with `status` (an error on one rank must not leave the others waiting).
  [[noreturn]] void Abort(int status) const;

 private:
  int rank_ = 0;
  int size_ = 1;
  VideoDistribution distribution_;
  mutable bool got_last_ = false;  // a worker was told there is no window left
};

}  // namespace evfs

#endif  // EVFS_APP_VIDEO_MPI_H_
