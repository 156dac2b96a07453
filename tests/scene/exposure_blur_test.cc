#include "evfs/scene/exposure_blur.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>

#include "evfs/core/error.h"
#include "evfs/events/random.h"

namespace evfs {
namespace {

constexpr int64_t kMs = 1000000;
constexpr int kWidth = 64, kHeight = 48;
// Immerkær's estimate of white Gaussian noise on smooth content is within a few per cent of the
// true sigma over ~3000 pixels; 10 % leaves room for the ramp's curvature-free residue.
constexpr double kNoiseSigmaTolerance = 0.1;

// A horizontal ramp (no curvature: the estimator's mask cancels it) plus seeded Gaussian noise.
Image NoisyRamp(double sigma, uint64_t seed) {
  Random random(seed);
  Image image(kHeight, kWidth);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x)
      image(y, x) = 0.2 + 0.5 * x / kWidth + random.Normal(0.0, sigma);
  }
  return image;
}

TEST(ExposureBlur, NoiseSigmaReadsTheNoiseOfASmoothFrame) {
  for (const double sigma : {0.005, 0.02, 0.05}) {
    EXPECT_NEAR(NoiseSigma(NoisyRamp(sigma, 7)), sigma, kNoiseSigmaTolerance * sigma) << sigma;
  }
  EXPECT_NEAR(NoiseSigma(NoisyRamp(0.0, 7)), 0.0, 1e-12);
  EXPECT_EQ(NoiseSigma(Image::Constant(2, 5, 0.5)), 0.0);
}

// Half the frame clipped white: counted, it halves the estimate; left out, the estimate is the
// noise of the rest. A frame clipped everywhere has nothing left to read.
TEST(ExposureBlur, NoiseSigmaCanLeaveOutClippedPixels) {
  const double sigma = 0.02;
  Image image = NoisyRamp(sigma, 11);
  image.topRows(kHeight / 2).setConstant(1.0);
  EXPECT_LT(NoiseSigma(image), 0.6 * sigma);
  EXPECT_NEAR(NoiseSigma(image, /*leave_out_clipped=*/true), sigma, kNoiseSigmaTolerance * sigma);
  EXPECT_TRUE(IsClippedLevel(0.0) && IsClippedLevel(1.0) && !IsClippedLevel(1.0 / 255.0) &&
              !IsClippedLevel(254.0 / 255.0));
  EXPECT_EQ(NoiseSigma(Image::Constant(8, 8, 0.0), /*leave_out_clipped=*/true), 0.0);
}

// A still, noisy frame whose events are isolated background activity stays sharp.
TEST(ExposureBlur, StillFrameWithNoiseEventsIsSharp) {
  const Image frame = NoisyRamp(0.01, 3);
  Random random(11);
  EventStream events(kWidth, kHeight);
  for (int64_t t = 0; t < 20 * kMs; t += kMs / 10) {  // 200 events over 3072 pixels
    events.push_back(t, static_cast<uint16_t>(random.Uniform() * kWidth),
                     static_cast<uint16_t>(random.Uniform() * kHeight),
                     random.Uniform() < 0.5 ? 1 : -1);
  }
  const ExposureBlurEstimate estimate = ExposureBlur(frame, events, 0, 20 * kMs);
  EXPECT_FALSE(estimate.blurred) << estimate.description;
  // Most are alone within 2 ms: left out as background activity.
  EXPECT_LT(estimate.events, 50);
  // Counted, all of them would predict a blur above the noise (about 3 events per pixel and
  // second, a noisy sensor in the dark).
  ExposureBlurOptions every_event;
  every_event.support_window_ms = 0.0;
  const ExposureBlurEstimate unfiltered = ExposureBlur(frame, events, 0, 20 * kMs, every_event);
  EXPECT_EQ(unfiltered.events, 200);
  EXPECT_TRUE(unfiltered.blurred) << unfiltered.description;
}

// A bright bar moving 16 pixels during the exposure: every pixel it enters fires ON events and
// every pixel it leaves OFF events, spread over the exposure. The frame is blurred.
TEST(ExposureBlur, MovingEdgeBlursTheFrame) {
  Image frame = NoisyRamp(0.01, 5);
  EventStream events(kWidth, kHeight);
  constexpr int kStart = 20, kTravel = 16, kEventsPerCrossing = 4;
  for (int step = 0; step < kTravel; ++step) {
    const int64_t t = (step * 20 * kMs) / kTravel + kMs / 2;
    for (int k = 0; k < kEventsPerCrossing; ++k) {
      for (int y = 0; y < kHeight; ++y) {
        events.push_back(t + k, static_cast<uint16_t>(kStart + step), static_cast<uint16_t>(y), 1);
      }
    }
  }
  const ExposureBlurEstimate estimate = ExposureBlur(frame, events, 0, 20 * kMs);
  EXPECT_TRUE(estimate.blurred) << estimate.description;
  EXPECT_GT(estimate.predicted_blur_rms, 2.0 * estimate.noise_sigma);
  // The same events over an exposure that ends before they start predict no blur.
  EXPECT_EQ(ExposureBlur(frame, events, 0, kMs / 4).predicted_blur_rms, 0.0);
}

// A light blinking at a few pixels fires many events inside the exposure; they are the light's,
// not motion, and do not make a still frame blurred.
TEST(ExposureBlur, FlickeringPixelsDoNotCount) {
  const Image frame = NoisyRamp(0.01, 9);
  EventStream events(kWidth, kHeight);
  for (int period = 0; period < 20; ++period) {
    for (int polarity : {1, -1}) {
      const int64_t t = period * kMs + (polarity > 0 ? 0 : kMs / 2);
      for (int k = 0; k < 6; ++k) {
        for (int x = 10; x < 20; ++x) {
          events.push_back(t + k, static_cast<uint16_t>(x), 10, static_cast<int8_t>(polarity));
        }
      }
    }
  }
  ExposureBlurOptions options;
  EXPECT_FALSE(ExposureBlur(frame, events, 0, 20 * kMs, options).blurred);
  options.flicker_min_reversals = 0;
  EXPECT_TRUE(ExposureBlur(frame, events, 0, 20 * kMs, options).blurred);
}

TEST(ExposureBlur, RejectsBadInput) {
  const Image frame = NoisyRamp(0.01, 1);
  EXPECT_THROW(ExposureBlur(frame, EventStream(kWidth, kHeight), 5, 5), InvalidArgumentError);
  EXPECT_THROW(ExposureBlur(frame, EventStream(kWidth + 1, kHeight), 0, kMs), InvalidArgumentError);
  ExposureBlurOptions options;
  options.contrast_threshold = -1.0;
  EXPECT_THROW(ExposureBlur(frame, EventStream(kWidth, kHeight), 0, kMs, options),
               InvalidArgumentError);
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("contrast_threshold"), std::string::npos) << error;
}

}  // namespace
}  // namespace evfs
