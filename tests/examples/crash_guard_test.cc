#include "examples/crash_guard.h"

#include <gtest/gtest.h>

#include "io/signal_cleanup.h"
#include "tests/test_data.h"

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <string>

namespace evfs {
namespace {

TEST(RunInChildProcess, PassesOnTheExitStatusAndTheOutput) {
  ::testing::internal::CaptureStdout();
  const int status = RunInChildProcess(
      [] {
        std::printf("from the child\n");
        return 7;
      },
      "evfs test", "file.h5");
  EXPECT_EQ(status, 7);
  EXPECT_EQ(::testing::internal::GetCapturedStdout(), "from the child\n");
}

TEST(RunInChildProcess, ACrashInTheChildIsOneLineAndStatus2) {
  // SIGILL: AddressSanitizer leaves it alone by default (handle_sigill=0), unlike SIGSEGV.
  ::testing::internal::CaptureStderr();
  const int status = RunInChildProcess(
      [] {
        std::raise(SIGILL);
        return 0;
      },
      "evfs test", "file.h5");
  const std::string errors = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(status, 2);
  EXPECT_EQ(errors,
            "evfs test: file.h5: crashed (Illegal instruction) reading it; libhdf5 does so on "
            "some corrupt HDF5 files\n");
}

TEST(RunInChildProcess, ACrashOutsideAnHdf5ReadIsAnInternalErrorAndLeavesNothing) {
  const std::filesystem::path scratch = evfs::testing::ScratchDir("crash_guard_cleanup");
  const std::filesystem::path unfinished = scratch / ".out.evfs-tmp-1";
  ::testing::internal::CaptureStderr();
  const int status = RunInChildProcess(
      [&unfinished] {
        ScopedCleanupPath cleanup(unfinished.string());
        std::filesystem::create_directories(unfinished / "frames");
        std::raise(SIGILL);
        return 0;
      },
      "evfs test", "");
  const std::string errors = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(status, 3);
  EXPECT_EQ(errors,
            "evfs test: internal error: crashed (Illegal instruction); the unfinished output was "
            "removed; please report it\n");
  EXPECT_FALSE(std::filesystem::exists(unfinished));
}

TEST(RunInChildProcess, TheParentIsUntouchedByTheChild) {
  int value = 1;
  EXPECT_EQ(RunInChildProcess(
                [&value] {
                  value = 2;
                  return 0;
                },
                "evfs test", "file.h5"),
            0);
  EXPECT_EQ(value, 1);
}

}  // namespace
}  // namespace evfs
