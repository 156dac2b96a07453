#include "examples/crash_guard.h"

#include <gtest/gtest.h>

#include <csignal>
#include <cstdio>
#include <string>

namespace evfs {
namespace {

TEST(RunInChildProcess, PassesOnTheExitStatusAndTheOutput) {
  testing::internal::CaptureStdout();
  const int status = RunInChildProcess(
      [] {
        std::printf("from the child\n");
        return 7;
      },
      "evfs test", "file.h5");
  EXPECT_EQ(status, 7);
  EXPECT_EQ(testing::internal::GetCapturedStdout(), "from the child\n");
}

TEST(RunInChildProcess, ACrashInTheChildIsOneLineAndStatus2) {
  // SIGILL: AddressSanitizer leaves it alone by default (handle_sigill=0), unlike SIGSEGV.
  testing::internal::CaptureStderr();
  const int status = RunInChildProcess(
      [] {
        std::raise(SIGILL);
        return 0;
      },
      "evfs test", "file.h5");
  const std::string errors = testing::internal::GetCapturedStderr();
  EXPECT_EQ(status, 2);
  EXPECT_EQ(errors,
            "evfs test: file.h5: crashed (Illegal instruction) reading it; libhdf5 does so on "
            "some corrupt HDF5 files\n");
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
