#include "evfs/runtime/progress.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

namespace evfs {
namespace {

using Clock = std::chrono::steady_clock;

// Everything written to `file` so far.
std::string Contents(std::FILE* file) {
  std::fflush(file);
  std::rewind(file);
  std::string text;
  char buffer[4096];
  for (size_t n; (n = std::fread(buffer, 1, sizeof(buffer), file)) > 0;) text.append(buffer, n);
  return text;
}

SolverIteration MakeIteration(int index, double cost, double elapsed_s) {
  SolverIteration iteration;
  iteration.iteration = index;
  iteration.cost = cost;
  iteration.elapsed_s = elapsed_s;
  return iteration;
}

// Long enough for a 1 ms interval to pass many times over, even on a loaded machine.
constexpr auto kSeveralIntervals = std::chrono::milliseconds(100);

TEST(ProgressReporter, ACommandEndingWithinItsFirstIntervalPrintsNothing) {
  std::FILE* out = std::tmpfile();
  ProgressOptions options;
  options.prefix = "evfs test";
  options.interval_s = 60.0;
  options.out = out;
  const auto start = Clock::now();
  {
    ProgressReporter progress(options);
    progress.StartStage("read");
    progress.Iteration(MakeIteration(0, 1.0, 0.0));
  }
  // Stopping does not wait for the interval.
  EXPECT_LT(Clock::now() - start, std::chrono::seconds(10));
  EXPECT_EQ(Contents(out), "");
  std::fclose(out);
}

TEST(ProgressReporter, IntervalLinesSayTheStageTheIterationAndTheTime) {
  std::FILE* out = std::tmpfile();
  ProgressOptions options;
  options.prefix = "evfs test";
  options.interval_s = 0.001;
  options.out = out;
  {
    ProgressReporter progress(options);
    progress.StartStage("bin");
    std::this_thread::sleep_for(kSeveralIntervals);
    progress.Iteration(MakeIteration(3, 2.5, 0.1));
    std::this_thread::sleep_for(kSeveralIntervals);
  }
  const std::string text = Contents(out);
  // The reporter may print once before the stage is set: a later line names it.
  EXPECT_NE(("\n" + text).find("\nevfs test: bin, "), std::string::npos) << text;
  EXPECT_NE(text.find("\nevfs test: solve, iteration 3 (cost 2.500000e+00), "), std::string::npos)
      << text;
  EXPECT_NE(text.find(" s elapsed\n"), std::string::npos) << text;
  EXPECT_EQ(text.find("iter "), std::string::npos) << "no line per iteration asked for";
  std::fclose(out);
}

TEST(ProgressReporter, EveryIterationIsALineAtOnceWhenAskedFor) {
  std::FILE* out = std::tmpfile();
  ProgressOptions options;
  options.interval_s = 0.0;  // no interval lines
  options.every_iteration = true;
  options.out = out;
  {
    ProgressReporter progress(options);
    progress.Iteration(MakeIteration(0, 4.0, 0.0));
    progress.Iteration(MakeIteration(1, 2.5, 1.5));
    EXPECT_EQ(Contents(out),
              "iter    0  cost 4.000000e+00  0.00 s\n"
              "iter    1  cost 2.500000e+00  1.50 s\n");
  }
  std::fclose(out);
}

}  // namespace
}  // namespace evfs
