// The MP4 encoder plug-in (io/mp4_encoder_plugin.h): cv::VideoWriter behind a C interface.
#include "evfs/io/mp4_encoder_plugin.h"

#include <malloc.h>
#include <pthread.h>
#include <sched.h>
#include <stdlib.h>

#include <mutex>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

namespace {

struct Encoder {
  cv::VideoWriter writer;
  cv::Size size;
};

// Restricts the calling thread to one of the CPUs it may run on, for the lifetime of the object,
// then gives it back the CPUs it had.
//
// libx264, which encodes "avc1", picks its number of frame threads when the encoder is opened
// from the CPUs the opening thread may run on (1.5 per CPU, capped by the frame height), and
// writes different bytes for the same frames with a different number of threads (its options,
// "threads=3" against "threads=1", are even part of the stream). So the same frames gave
// different files from a plain run and from rank 0 of `mpirun`, which binds each rank to a core,
// and would from machines with other core counts. OpenCV 4.6 hands its FFmpeg writer no codec
// options (OPENCV_FFMPEG_WRITER_OPTIONS only selects hardware acceleration there), so the thread
// count cannot be asked for; seeing one CPU, x264 always chooses one thread. Threads that the
// encoder starts while the object lives keep the one CPU; with one x264 thread there are none.
class OneCpuWhileOpening {
 public:
  OneCpuWhileOpening() {
    if (pthread_getaffinity_np(pthread_self(), sizeof(allowed_), &allowed_) != 0) return;
    for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
      if (!CPU_ISSET(cpu, &allowed_)) continue;
      cpu_set_t one;
      CPU_ZERO(&one);
      CPU_SET(cpu, &one);
      restore_ = pthread_setaffinity_np(pthread_self(), sizeof(one), &one) == 0;
      return;
    }
  }
  ~OneCpuWhileOpening() {
    if (restore_) pthread_setaffinity_np(pthread_self(), sizeof(allowed_), &allowed_);
  }
  OneCpuWhileOpening(const OneCpuWhileOpening&) = delete;
  OneCpuWhileOpening& operator=(const OneCpuWhileOpening&) = delete;

 private:
  cpu_set_t allowed_;
  bool restore_ = false;
};

// While any encoder is open, glibc hands out every block filled with zeros.
//
// libx264 reads bytes of its frame buffers that it never wrote (frame widths such as 240 show
// it; 256 does not), so the stream depended on what earlier code of the process had left in
// the memory that malloc returned: a resumed `evfs video` run, whose heap had seen fewer
// solves, wrote another video.mp4 than an uninterrupted one from the same frames. A block
// fresh from the kernel is zeros, and glibc's perturbation (the setting behind
// MALLOC_PERTURB_) fills a recycled block with `byte ^ 0xff` when it is handed out, so 0xff
// makes both zeros. The setting is global to the process: other threads' allocations are
// zeroed too meanwhile, which costs time but changes nothing correct code can see. When the
// last encoder closes, the MALLOC_PERTURB_ of the environment (normally none) is restored.
class ZeroedAllocations {
 public:
  static void Acquire() {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (open_++ == 0) Perturb(0xff);
  }
  static void Release() {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (--open_ > 0) return;
    const char* user = getenv("MALLOC_PERTURB_");
    Perturb(user != nullptr ? atoi(user) & 0xff : 0);
  }

 private:
  static void Perturb(int byte) {
#ifdef M_PERTURB
    mallopt(M_PERTURB, byte);
#else
    static_cast<void>(byte);
#endif
  }
  static inline std::mutex mutex_;
  static inline int open_ = 0;
};

}  // namespace

extern "C" {

__attribute__((visibility("default"))) void* EvfsMp4Open(const char* path, const char* codec,
                                                         double fps, int width, int height) {
  ZeroedAllocations::Acquire();
  auto* encoder = new Encoder{cv::VideoWriter(), cv::Size(width, height)};
  const int fourcc = cv::VideoWriter::fourcc(codec[0], codec[1], codec[2], codec[3]);
  bool opened = false;
  {
    const OneCpuWhileOpening one_cpu;
    opened = encoder->writer.open(path, cv::CAP_FFMPEG, fourcc, fps, encoder->size, true);
  }
  if (!opened) {
    delete encoder;
    ZeroedAllocations::Release();
    return nullptr;
  }
  return encoder;
}

__attribute__((visibility("default"))) void EvfsMp4Write(void* encoder, const unsigned char* bgr) {
  auto* open = static_cast<Encoder*>(encoder);
  open->writer.write(cv::Mat(open->size, CV_8UC3, const_cast<unsigned char*>(bgr)));
}

__attribute__((visibility("default"))) void EvfsMp4Close(void* encoder) {
  auto* open = static_cast<Encoder*>(encoder);
  open->writer.release();
  delete open;
  ZeroedAllocations::Release();
}

}  // extern "C"
