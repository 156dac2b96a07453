#include "evfs/core/stop_condition.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <string>

namespace evfs {
namespace {

TEST(StopCondition, DefaultIsNeverReached) {
  const StopCondition never;
  EXPECT_FALSE(never.active());
  EXPECT_FALSE(never.Reached());
  EXPECT_TRUE(std::isinf(never.SecondsLeft()));
  EXPECT_EQ(std::string(never.Reason()), "");
}

TEST(StopCondition, DeadlinePassesAndHugeBudgetsSetNone) {
  const StopCondition now = StopCondition::After(0.0);
  EXPECT_TRUE(now.active());
  EXPECT_TRUE(now.TimedOut());
  EXPECT_EQ(now.SecondsLeft(), 0.0);
  EXPECT_NE(std::string(now.Reason()).find("--max_time_s"), std::string::npos);
  EXPECT_TRUE(StopCondition::After(-3.0).Reached());

  const StopCondition later = StopCondition::After(3600.0);
  EXPECT_FALSE(later.Reached());
  EXPECT_GT(later.SecondsLeft(), 3500.0);
  EXPECT_LE(later.SecondsLeft(), 3600.0);

  for (const double huge : {1e12, HUGE_VAL}) {
    const StopCondition none = StopCondition::After(huge);
    EXPECT_FALSE(none.active());
    EXPECT_FALSE(none.Reached());
  }
  EXPECT_FALSE(StopCondition::After(std::nan("")).active());
}

TEST(StopCondition, CopiesShareTheFlag) {
  std::atomic<bool> flag(false);
  StopCondition condition = StopCondition::After(3600.0);
  condition.WhenRaised(&flag);
  const StopCondition copy = condition;
  EXPECT_FALSE(copy.Reached());
  flag = true;
  EXPECT_TRUE(condition.Interrupted());
  EXPECT_TRUE(copy.Reached());
  EXPECT_EQ(std::string(copy.Reason()), "interrupted");
}

}  // namespace
}  // namespace evfs
