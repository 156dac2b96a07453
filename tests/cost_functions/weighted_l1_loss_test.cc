#include "evfs/cost_functions/weighted_l1_loss.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

namespace evfs {
namespace {

// Ceres evaluates 2 a^2 (sqrt(1 + s / a^2) - 1), we evaluate sqrt(a^2 + r^2) - a: the same value
// through different roundings, each cancelling to a relative error of ~1e-16 * (a / cost).
constexpr double kLossIdentityTolerance = 1e-12;
// Closed-form values of SmoothedAbs.
constexpr double kNominalTolerance = 1e-15;

// Ceres' cost of a scalar residual r under `loss`: 1/2 rho(r^2).
double LossCost(const ceres::LossFunction& loss, double r) {
  double rho[3];
  loss.Evaluate(r * r, rho);
  return 0.5 * rho[0];
}

TEST(SmoothedAbs, Nominal) {
  EXPECT_EQ(SmoothedAbs(0.0, 0.01), 0.0);
  EXPECT_NEAR(SmoothedAbs(3.0, 4.0), 1.0, kNominalTolerance);   // sqrt(16 + 9) - 4
  EXPECT_NEAR(SmoothedAbs(-3.0, 4.0), 1.0, kNominalTolerance);  // even in r
}

TEST(SmoothedAbs, DerivativeTendsToSignForLargeResiduals) {
  using Jet = ceres::Jet<double, 1>;
  constexpr double kScale = 1e-3;
  EXPECT_NEAR(SmoothedAbs(Jet(1.0, 0), kScale).v[0], 1.0, kScale);
  EXPECT_NEAR(SmoothedAbs(Jet(-1.0, 0), kScale).v[0], -1.0, kScale);
  EXPECT_EQ(SmoothedAbs(Jet(0.0, 0), kScale).v[0], 0.0);
}

TEST(WeightedL1Loss, CostIsWeightTimesSmoothedAbs) {
  for (const double weight : {0.1, 1.0, 3.5}) {
    for (const double scale : {1e-3, 0.01, 0.5}) {
      const std::unique_ptr<ceres::LossFunction> loss(CreateWeightedL1Loss(weight, scale));
      for (const double r : {-2.0, -0.3, -0.01, 0.001, 0.02, 0.4, 1.5}) {
        SCOPED_TRACE(::testing::Message()
                     << "weight " << weight << ", scale " << scale << ", r " << r);
        const double expected = weight * SmoothedAbs(r, scale);
        EXPECT_NEAR(LossCost(*loss, r), expected, kLossIdentityTolerance * expected);
      }
    }
  }
}

TEST(WeightedL1Loss, LimitsAreWeightedAbsAndQuadratic) {
  constexpr double kWeight = 0.4;
  constexpr double kScale = 1e-4;
  const std::unique_ptr<ceres::LossFunction> loss(CreateWeightedL1Loss(kWeight, kScale));
  // |r| >> a: w |r| - w a up to O(a^2 / |r|).
  EXPECT_NEAR(LossCost(*loss, 0.5), kWeight * 0.5, kWeight * kScale);
  // |r| << a: w r^2 / (2 a) up to a relative O(r^2 / a^2).
  const double small_r = 1e-7;
  EXPECT_NEAR(LossCost(*loss, small_r), kWeight * small_r * small_r / (2.0 * kScale),
              1e-5 * kWeight * small_r * small_r / (2.0 * kScale));
}

TEST(WeightedL1LossDeathTest, RejectsNonPositiveWeightOrScale) {
  EXPECT_DEATH(CreateWeightedL1Loss(0.0, 0.01), "weight");
  EXPECT_DEATH(CreateWeightedL1Loss(1.0, -0.01), "smoothing_scale");
}

}  // namespace
}  // namespace evfs
