#include "evfs/scene/event_model.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace evfs {
namespace {

// Closed-form values computed with the same libm calls.
constexpr double kNominalTolerance = 1e-15;

EventModelParams LogParams() {
  EventModelParams params;
  params.model = EventModel::kLog;
  params.log_offset = 0.1;
  return params;
}

TEST(EventModel, DefaultsAreThePaperLinearModel) {
  const EventModelParams params;
  EXPECT_EQ(params.model, EventModel::kLinear);
  EXPECT_EQ(params.alpha, 5.0);
  EXPECT_EQ(params.log_offset, 0.1);
  std::string error;
  EXPECT_TRUE(params.IsValid(&error)) << error;
}

TEST(EventModel, NominalIntensityTransform) {
  EXPECT_EQ(IntensityTransform(0.3, EventModelParams()), 0.3);
  EXPECT_NEAR(IntensityTransform(0.3, LogParams()), std::log(0.4), kNominalTolerance);
}

TEST(EventModel, NominalPredictedEvent) {
  EXPECT_NEAR(PredictedEvent(0.2, 0.3, EventModelParams()), std::tanh(0.5), kNominalTolerance);
  EXPECT_NEAR(PredictedEvent(0.2, 0.3, LogParams()),
              std::tanh(5.0 * (std::log(0.4) - std::log(0.3))), kNominalTolerance);
}

TEST(EventModel, LogGuardClampsNegativeIntensities) {
  using Jet = ceres::Jet<double, 1>;
  const Jet transformed = IntensityTransform(Jet(-0.5, 0), LogParams());
  EXPECT_NEAR(transformed.a, std::log(0.1), kNominalTolerance);
  EXPECT_EQ(transformed.v[0], 0.0);
  EXPECT_EQ(IntensityTransformDerivative(-0.5, LogParams()), 0.0);
}

TEST(EventModel, LogGuardKeepsTheSlopeAtZero) {
  // Regression: the clamp took x = 0 itself to the flat side, so a bounded solve starting from
  // a black frame had no event gradient at all and stopped after 0 iterations
  // (tests/stress, black_start_prediction_log).
  using Jet = ceres::Jet<double, 1>;
  const Jet transformed = IntensityTransform(Jet(0.0, 0), LogParams());
  EXPECT_NEAR(transformed.a, std::log(0.1), kNominalTolerance);
  EXPECT_NEAR(transformed.v[0], 1.0 / 0.1, kNominalTolerance);
  EXPECT_NEAR(IntensityTransformDerivative(0.0, LogParams()), 1.0 / 0.1, kNominalTolerance);
}

TEST(EventModel, DerivativeMatchesAutoDiff) {
  using Jet = ceres::Jet<double, 1>;
  for (const EventModelParams& params : {EventModelParams(), LogParams()}) {
    for (const double intensity : {-0.2, 0.0, 0.05, 0.5, 1.0}) {
      SCOPED_TRACE(intensity);
      EXPECT_NEAR(IntensityTransform(Jet(intensity, 0), params).v[0],
                  IntensityTransformDerivative(intensity, params), kNominalTolerance);
    }
  }
}

TEST(EventModel, IsValidRejectsNonPositiveAlphaAndOffset) {
  std::string error;
  EventModelParams params;
  params.alpha = 0.0;
  EXPECT_FALSE(params.IsValid(&error));
  EXPECT_NE(error.find("alpha"), std::string::npos);
  params = LogParams();
  params.log_offset = -0.1;
  EXPECT_FALSE(params.IsValid(&error));
  EXPECT_NE(error.find("offset"), std::string::npos);
  params.model = EventModel::kLinear;  // The offset is unused by the linear model.
  EXPECT_TRUE(params.IsValid(nullptr));
}

}  // namespace
}  // namespace evfs
