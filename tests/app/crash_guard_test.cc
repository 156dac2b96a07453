#include "evfs/runtime/crash_guard.h"

#include <glog/logging.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>

#include "evfs/core/error.h"
#include "evfs/io/hdf5_io.h"
#include "evfs/runtime/signal_cleanup.h"
#include "evfs/tests/test_data.h"

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

TEST(RunInChildProcess, ACrashInsideLibhdf5IsTheFilesFault) {
  // SIGILL: AddressSanitizer leaves it alone by default (handle_sigill=0), unlike SIGSEGV.
  ::testing::internal::CaptureStderr();
  const int status = RunInChildProcess(
      [] {
        const ScopedInputLibraryRead reading(kLibhdf5);
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

// Reading an HDF5 file does not make every crash the file's: evfs' own code, or another
// thread while one is inside libhdf5, crashes through a bug of evfs'.
TEST(RunInChildProcess, ACrashOutsideLibhdf5IsAnInternalErrorEvenReadingHdf5) {
  const auto crash_of = [](const std::function<int()>& body) {
    ::testing::internal::CaptureStderr();
    const int status = RunInChildProcess(body, "evfs test", "file.h5");
    EXPECT_EQ(status, 3);
    return ::testing::internal::GetCapturedStderr();
  };
  const std::string expected =
      "evfs test: internal error: crashed (Illegal instruction) outside libhdf5; please report "
      "it\n";
  EXPECT_EQ(crash_of([] {
              { const ScopedInputLibraryRead reading(kLibhdf5); }
              std::raise(SIGILL);
              return 0;
            }),
            expected);
  EXPECT_EQ(crash_of([] {
              const ScopedInputLibraryRead reading(kLibhdf5);
              std::thread([] { std::raise(SIGILL); }).join();
              return 0;
            }),
            expected);
}

// The runtime names whichever input library a reader marked: it knows none of them.
TEST(RunInChildProcess, ACrashInsideAnyInputLibraryIsTheFilesFaultInItsWords) {
  static const InputLibrary kDecoder = {"libdecoder", "some truncated test files"};
  ::testing::internal::CaptureStderr();
  int status = RunInChildProcess(
      [] {
        const ScopedInputLibraryRead reading(kDecoder);
        std::raise(SIGILL);
        return 0;
      },
      "evfs test", "file.bin");
  EXPECT_EQ(status, 2);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(),
            "evfs test: file.bin: crashed (Illegal instruction) reading it; libdecoder does so on "
            "some truncated test files\n");
  // Without a file to blame, the same crash is evfs' own.
  ::testing::internal::CaptureStderr();
  status = RunInChildProcess(
      [] {
        const ScopedInputLibraryRead reading(kDecoder);
        std::raise(SIGILL);
        return 0;
      },
      "evfs test", "");
  EXPECT_EQ(status, 3);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(),
            "evfs test: internal error: crashed (Illegal instruction); please report it\n");
}

// The two files the HDF5 fuzzer found on which libhdf5 1.10 itself dies of a segmentation
// fault (tests/examples/data): the crash happens inside libhdf5's ScopedInputLibraryRead, so it
// is the file's.
// Whether libhdf5 crashes on one of them depends on the process around it (the attribute file
// crashed it while OpenCV's imgcodecs, and through it GDAL, were linked in); where it reads the
// file instead, evfs must refuse the file cleanly. At least one file must crash, or the test
// would prove nothing.
TEST(RunInChildProcess, Libhdf5CrashingOnACorruptFileIsTheFilesFault) {
  constexpr int kRefused = 3;
  int crashed = 0;
  for (const char* name : {"fuzz_libhdf5_segv_cache_read.h5", "fuzz_libhdf5_segv_attribute.h5"}) {
    const std::string h5 = std::string(EVFS_TEST_SOURCE_DIR) + "/../examples/data/" + name;
    ::testing::internal::CaptureStderr();
    const int status = RunInChildProcess(
        [&h5] {
          try {
            const Hdf5DataSource source(h5);
            source.Summarize();
          } catch (const InputError&) {
            return kRefused;
          }
          return 0;
        },
        "evfs test", h5);
    const std::string errors = ::testing::internal::GetCapturedStderr();
    if (status == kRefused) continue;
    ++crashed;
    EXPECT_EQ(errors, "evfs test: " + h5 +
                          ": crashed (Segmentation fault) reading it; libhdf5 does so on some "
                          "corrupt HDF5 files\n");
  }
  EXPECT_GE(crashed, 1) << "libhdf5 read both files: the crash attribution was not exercised";
}

void UseInternalErrorReporting() {
  if (!google::IsGoogleLoggingInitialized()) google::InitGoogleLogging("crash_guard_test");
  InstallInternalErrorReporting("evfs test");
}

// A failed CHECK is a bug of evfs': one line naming the check, status 3, never the file's fault,
// and the unfinished output removed like on any other exit.
TEST(InternalErrorReporting, AFailedCheckIsOneLineNamingTheCheck) {
  UseInternalErrorReporting();
  const std::filesystem::path scratch = evfs::test::ScratchDir("crash_guard_check");
  const std::filesystem::path unfinished = scratch / ".out.evfs-tmp-1";
  ::testing::internal::CaptureStderr();
  const int status = RunInChildProcess(
      [&unfinished] {
        ScopedCleanupPath cleanup(unfinished.string());
        std::filesystem::create_directories(unfinished);
        const int frames = static_cast<int>(unfinished.string().size());
        CHECK_EQ(frames, -1) << "a frame count\nover two lines";
        return 0;
      },
      "evfs test", "file.h5");
  const std::string errors = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(status, 3);
  EXPECT_EQ(std::count(errors.begin(), errors.end(), '\n'), 1) << errors;
  EXPECT_EQ(errors.rfind("evfs test: internal error: crash_guard_test.cc:", 0), 0u) << errors;
  EXPECT_NE(errors.find(": Check failed: frames == -1 ("), std::string::npos) << errors;
  EXPECT_NE(errors.find("a frame count over two lines; please report it\n"), std::string::npos)
      << errors;
  EXPECT_EQ(errors.find("crashed"), std::string::npos) << errors;
  EXPECT_FALSE(std::filesystem::exists(unfinished));
}

TEST(InternalErrorReporting, OtherLogMessagesStillReachStderr) {
  UseInternalErrorReporting();
  ::testing::internal::CaptureStderr();
  LOG(WARNING) << "a warning from a library";
  const std::string errors = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(errors.rfind("W", 0), 0u) << errors;
  EXPECT_NE(errors.find("crash_guard_test.cc:"), std::string::npos) << errors;
  EXPECT_NE(errors.find("] a warning from a library\n"), std::string::npos) << errors;
}

TEST(RunInChildProcess, ACrashOutsideAnHdf5ReadIsAnInternalErrorAndLeavesNothing) {
  const std::filesystem::path scratch = evfs::test::ScratchDir("crash_guard_cleanup");
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
