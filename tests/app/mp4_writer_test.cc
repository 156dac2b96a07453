// Mp4Writer (io/video_writer.h): the same frames make the same file, whichever CPUs the writing
// thread may use and whatever the process did before, so that `evfs video` from one process,
// from rank 0 of `mpirun` (bound to a core) and after --resume writes the same video.mp4.
#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "evfs/core/video.h"
#include "evfs/io/video_writer.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;

std::string ReadBytes(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << file.rdbuf();
  return bytes.str();
}

// The CPUs the calling thread may run on.
cpu_set_t ThreadCpus() {
  cpu_set_t cpus;
  CPU_ZERO(&cpus);
  EXPECT_EQ(pthread_getaffinity_np(pthread_self(), sizeof(cpus), &cpus), 0);
  return cpus;
}

// Writes 24 frames of a moving pattern, large enough for x264 to use several threads when it
// may, into `path` at 240 fps and returns the codec.
std::string WriteMovingPattern(const fs::path& path) {
  constexpr int kWidth = 240, kHeight = 180;
  Mp4Writer writer(path.string(), 240.0, kWidth, kHeight);
  Image frame(kHeight, kWidth);
  for (int n = 0; n < 24; ++n) {
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        frame(y, x) = 0.5 + 0.25 * std::sin(0.11 * (x + 3 * n)) * std::cos(0.07 * (y - 2 * n)) +
                      0.2 * (((x / 8 + y / 8 + n) % 5) == 0);
      }
    }
    writer.WriteGrey(frame);
  }
  writer.Close();
  return writer.codec();
}

TEST(Mp4Writer, TheSameFramesMakeTheSameBytesOnAnyNumberOfCpus) {
  const cpu_set_t all = ThreadCpus();
  if (CPU_COUNT(&all) < 2) {
    GTEST_SKIP() << "this process may use one CPU only: the writes cannot see different counts";
  }
  const fs::path scratch = test::ScratchDir("mp4_writer_cpus");

  // On a thread that may use every CPU of the process; the writer leaves its CPUs as they were.
  std::string codec_all;
  std::thread([&] {
    codec_all = WriteMovingPattern(scratch / "all_cpus.mp4");
    const cpu_set_t after = ThreadCpus();
    EXPECT_TRUE(CPU_EQUAL(&all, &after));
  }).join();

  // On a thread bound to one CPU, as rank 0 of `mpirun` is.
  std::string codec_one;
  std::thread([&] {
    cpu_set_t one;
    CPU_ZERO(&one);
    for (int cpu = CPU_SETSIZE - 1; cpu >= 0; --cpu) {
      if (CPU_ISSET(cpu, &all)) {
        CPU_SET(cpu, &one);
        break;
      }
    }
    ASSERT_EQ(pthread_setaffinity_np(pthread_self(), sizeof(one), &one), 0);
    codec_one = WriteMovingPattern(scratch / "one_cpu.mp4");
  }).join();

  EXPECT_EQ(codec_all, codec_one);
  const std::string bytes_all = ReadBytes(scratch / "all_cpus.mp4");
  EXPECT_GT(bytes_all.size(), 0u);
  EXPECT_TRUE(bytes_all == ReadBytes(scratch / "one_cpu.mp4"))
      << "video.mp4 depends on the CPUs of the writing thread (" << codec_all << ")";

  fs::remove_all(scratch);
}

// Leaves `byte` in the memory that the next large allocations of the process will get: one big
// block freed first makes glibc serve later blocks of that size from the heap instead of fresh
// (zeroed) pages, then heap blocks are filled and freed.
void LeaveInFreedMemory(unsigned char byte) {
  void* volatile big = malloc(size_t{4} << 20);  // volatile: the pair is not optimised away
  free(big);
  std::vector<std::vector<unsigned char>> blocks;
  for (int i = 0; i < 16; ++i) blocks.emplace_back(size_t{400} << 10, byte);
}

TEST(Mp4Writer, TheSameFramesMakeTheSameBytesWhateverTheHeapHeld) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer replaces glibc's malloc, whose zeroing (M_PERTURB) the "
                  "writer relies on";
#endif
  const fs::path scratch = test::ScratchDir("mp4_writer_heap");
  // libx264 read bytes of its frame buffers that it never wrote, so the file depended on what
  // the process had done before (a resumed `evfs video` run against an uninterrupted one).
  const std::string codec = WriteMovingPattern(scratch / "first.mp4");
  LeaveInFreedMemory(0xa5);
  WriteMovingPattern(scratch / "after_a5.mp4");
  LeaveInFreedMemory(0x3c);
  WriteMovingPattern(scratch / "after_3c.mp4");
  const std::string first = ReadBytes(scratch / "first.mp4");
  EXPECT_TRUE(first == ReadBytes(scratch / "after_a5.mp4")) << codec;
  EXPECT_TRUE(first == ReadBytes(scratch / "after_3c.mp4")) << codec;
  fs::remove_all(scratch);
}

}  // namespace
}  // namespace evfs
