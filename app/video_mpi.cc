#include "evfs/app/video_mpi.h"

#include <cstdlib>

#include "evfs/core/error.h"

#ifdef EVFS_WITH_MPI
#include <mpi.h>
#endif

namespace evfs {

#ifdef EVFS_WITH_MPI
namespace {

// Messages between rank 0 and the workers; each carries one int.
constexpr int kTagRequest = 1;   // worker → 0: give me a window (the previous one is written)
constexpr int kTagAssign = 2;    // 0 → worker: a window index, or -1: none left
constexpr int kTagFinished = 3;  // worker → 0: every window of mine is written

}  // namespace

bool LaunchedAsMpiJob() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"}) {
    const char* value = std::getenv(name);
    if (value != nullptr && std::atoi(value) > 1) return true;
  }
  return false;
}

MpiVideoSession::MpiVideoSession() {
  int provided = 0;
  // The worker's --jobs threads ask for windows one at a time (VideoDistribution::next).
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  distribution_.coordinator = rank_ == 0;
  if (rank_ == 0) {
    distribution_.serve = [this](const std::vector<int>& pending) {
      size_t next = 0;
      int told_none = 0;
      while (told_none < size_ - 1) {
        int failed = 0;
        MPI_Status status;
        MPI_Recv(&failed, 1, MPI_INT, MPI_ANY_SOURCE, kTagRequest, MPI_COMM_WORLD, &status);
        if (failed != 0) {
          // The worker said why; unwinding here removes the work folder before every rank ends.
          throw InvalidArgumentError("rank " + std::to_string(status.MPI_SOURCE) +
                                     " stopped with an error; no output was written");
        }
        int index = -1;
        if (next < pending.size()) {
          index = pending[next++];
        } else {
          ++told_none;
        }
        MPI_Send(&index, 1, MPI_INT, status.MPI_SOURCE, kTagAssign, MPI_COMM_WORLD);
      }
      for (int worker = 1; worker < size_; ++worker) {
        int ignored = 0;
        MPI_Recv(&ignored, 1, MPI_INT, MPI_ANY_SOURCE, kTagFinished, MPI_COMM_WORLD,
                 MPI_STATUS_IGNORE);
      }
    };
  } else {
    distribution_.next = [this]() {
      if (got_last_) return -1;  // the worker's other threads stop without asking again
      int request = 0, index = -1;
      MPI_Send(&request, 1, MPI_INT, 0, kTagRequest, MPI_COMM_WORLD);
      MPI_Recv(&index, 1, MPI_INT, 0, kTagAssign, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      got_last_ = index < 0;
      return index;
    };
  }
}

MpiVideoSession::~MpiVideoSession() { MPI_Finalize(); }

std::string MpiVideoSession::Broadcast(const std::string& text) const {
  int length = static_cast<int>(text.size());
  MPI_Bcast(&length, 1, MPI_INT, 0, MPI_COMM_WORLD);
  std::string received = rank_ == 0 ? text : std::string(length, '\0');
  MPI_Bcast(received.data(), length, MPI_CHAR, 0, MPI_COMM_WORLD);
  return received;
}

void MpiVideoSession::WorkerFinished() const {
  int done = 0;
  MPI_Send(&done, 1, MPI_INT, 0, kTagFinished, MPI_COMM_WORLD);
}

void MpiVideoSession::WorkerFailed() const {
  int failed = 1;
  MPI_Send(&failed, 1, MPI_INT, 0, kTagRequest, MPI_COMM_WORLD);
}

void MpiVideoSession::Abort(int status) const {
  MPI_Abort(MPI_COMM_WORLD, status);
  std::_Exit(status);
}

#else  // !EVFS_WITH_MPI

bool LaunchedAsMpiJob() { return false; }

MpiVideoSession::MpiVideoSession() {
  throw InvalidArgumentError("this evfs was built without MPI (EVFS_WITH_MPI)");
}

MpiVideoSession::~MpiVideoSession() = default;

std::string MpiVideoSession::Broadcast(const std::string& text) const { return text; }

void MpiVideoSession::WorkerFinished() const {}

void MpiVideoSession::WorkerFailed() const {}

void MpiVideoSession::Abort(int status) const { std::_Exit(status); }

#endif  // EVFS_WITH_MPI

}  // namespace evfs
