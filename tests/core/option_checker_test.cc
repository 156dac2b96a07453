#include "evfs/core/option_checker.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace evfs {
namespace {

struct Nested {
  bool valid = true;
  bool IsValid(std::string* error) const {
    OptionChecker check;
    check.Check(valid, "nested is broken");
    return check.Passed(error);
  }
};

TEST(OptionChecker, PassedClearsTheErrorAndAcceptsNull) {
  OptionChecker check;
  check.Positive("a", 1.0).NonNegative("b", 0.0).InRange("c", 3, 1, 5).Valid(Nested());
  std::string error = "stale";
  EXPECT_TRUE(check.Passed(&error));
  EXPECT_EQ(error, "");
  EXPECT_TRUE(check.Passed(nullptr));
  EXPECT_TRUE(check.ok());
}

TEST(OptionChecker, KeepsTheFirstFailure) {
  OptionChecker check;
  check.Positive("a", 0.0).NonNegative("b", -1.0).Check(false, "third");
  std::string error;
  EXPECT_FALSE(check.Passed(&error));
  EXPECT_EQ(error, "a must be finite and > 0");
  EXPECT_FALSE(check.Passed(nullptr));
  EXPECT_FALSE(check.ok());
}

TEST(OptionChecker, EachRequirementSaysWhatIsExpected) {
  const auto reason = [](OptionChecker check) {
    std::string error;
    check.Passed(&error);
    return error;
  };
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(reason(OptionChecker().Positive("x", inf)), "x must be finite and > 0");
  EXPECT_EQ(reason(OptionChecker().NonNegative("x", std::nan(""))), "x must be finite and >= 0");
  EXPECT_EQ(reason(OptionChecker().InRange("n", 0, 1, 4)), "n must be in [1, 4], got 0");
  EXPECT_EQ(reason(OptionChecker().Require(false, "n", "odd")), "n must be odd");
  EXPECT_EQ(reason(OptionChecker().Check(false, "the whole reason")), "the whole reason");
  EXPECT_EQ(reason(OptionChecker().Check(false, "")), "invalid options");
  Nested broken;
  broken.valid = false;
  EXPECT_EQ(reason(OptionChecker().Valid(broken)), "nested is broken");
  EXPECT_EQ(reason(OptionChecker().Check(false, "first").Valid(broken)), "first");
}

}  // namespace
}  // namespace evfs
