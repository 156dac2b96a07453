#include "evfs/benchmarks/cell_runner.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace evfs {
namespace {

namespace fs = std::filesystem;

std::string ResultPath() {
  fs::create_directories(EVFS_TEST_TMP_DIR);
  return std::string(EVFS_TEST_TMP_DIR) + "/cell_result.txt";
}

// A shell cell: `script` runs with the result path as $0.
CellRun RunShell(const std::string& script, const CellLimits& limits = CellLimits()) {
  return RunCellProcess({"/bin/sh", "-c", script, ResultPath()}, ResultPath(), limits);
}

TEST(RunCellProcess, ReturnsTheResultTheCellWroteAndRemovesTheFile) {
  const CellRun run = RunShell("printf 'psnr 25.5\\n' > \"$0\"");
  ASSERT_TRUE(run.has_result) << run.failure;
  EXPECT_EQ(run.result, "psnr 25.5\n");
  EXPECT_TRUE(run.failure.empty());
  EXPECT_FALSE(fs::exists(ResultPath()));
  EXPECT_GT(run.peak_memory_mb, 0.0);  // the shell's own resident set
  EXPECT_GE(run.cpu_s, 0.0);
  EXPECT_GT(run.wall_s, 0.0);
}

TEST(RunCellProcess, AnEarlierResultIsNotTakenForThisCells) {
  const CellRun first = RunShell("printf 'first' > \"$0\"");
  ASSERT_TRUE(first.has_result);
  const CellRun second = RunShell("exit 3");
  EXPECT_FALSE(second.has_result);
  EXPECT_EQ(second.failure, "exited with status 3 and no result");
}

TEST(RunCellProcess, AMissingExecutableIsExitStatus127) {
  const CellRun run = RunCellProcess({"/nonexistent/cell"}, ResultPath(), CellLimits());
  EXPECT_FALSE(run.has_result);
  EXPECT_EQ(run.failure, "exited with status 127 and no result");
}

TEST(RunCellProcess, StopsACellPastItsTimeout) {
  const CellRun run = RunShell("sleep 10", CellLimits{/*timeout_s=*/1, /*memory_mb=*/0});
  EXPECT_FALSE(run.has_result);
  EXPECT_EQ(run.failure, "timed out after 1 s");
  EXPECT_LT(run.wall_s, 9.0);
}

TEST(RunCellProcess, ASignalUnderAMemoryLimitMayBeTheLimit) {
  EXPECT_EQ(RunShell("kill -SEGV $$", CellLimits{/*timeout_s=*/60, /*memory_mb=*/1024}).failure,
            "killed by signal 11 (memory limit 1024 MB?)");
  EXPECT_EQ(RunShell("kill -SEGV $$").failure, "killed by signal 11");
}

TEST(RunCellProcess, TheMemoryLimitHoldsInTheCell) {
  // ulimit -v reports RLIMIT_AS in KiB.
  const CellRun run =
      RunShell("ulimit -v > \"$0\"", CellLimits{/*timeout_s=*/60, /*memory_mb=*/512});
  ASSERT_TRUE(run.has_result) << run.failure;
  EXPECT_EQ(run.result, "524288\n");
}

}  // namespace
}  // namespace evfs
