#include "evfs/baselines/scalar_search.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace evfs {
namespace {

// The search stops when its bracket is narrower than 1e-3 of its centre.
constexpr double kRelativeTolerance = 1e-3;

TEST(MinimizeOnLogInterval, FindsAnInteriorMinimum) {
  const auto f = [](double c) { return std::pow(std::log(c / 0.3), 2.0); };
  const ScalarMinimum minimum = MinimizeOnLogInterval(f, 0.01, 1.0);
  EXPECT_NEAR(minimum.argument, 0.3, 0.3 * kRelativeTolerance);
  EXPECT_DOUBLE_EQ(minimum.value, f(minimum.argument));
  EXPECT_GT(minimum.evaluations, 16);
}

TEST(MinimizeOnLogInterval, ReturnsTheBoundOfAMonotoneFunction) {
  const ScalarMinimum rising = MinimizeOnLogInterval([](double c) { return c; }, 0.05, 2.0);
  EXPECT_NEAR(rising.argument, 0.05, 0.05 * kRelativeTolerance);
  const ScalarMinimum falling = MinimizeOnLogInterval([](double c) { return -c; }, 0.05, 2.0);
  EXPECT_NEAR(falling.argument, 2.0, 2.0 * kRelativeTolerance);
}

TEST(MinimizeOnLogInterval, PicksTheDeeperOfTwoBasins) {
  // A shallow basin at 0.02 and a deeper, narrow one at 0.5: the grid finds the deeper one.
  const auto f = [](double c) {
    const double shallow = std::pow(std::log(c / 0.02), 2.0) - 1.0;
    const double deep = 10.0 * std::pow(std::log(c / 0.5), 2.0) - 2.0;
    return std::min(shallow, deep);
  };
  EXPECT_NEAR(MinimizeOnLogInterval(f, 0.01, 1.0).argument, 0.5, 0.5 * kRelativeTolerance);
}

}  // namespace
}  // namespace evfs
