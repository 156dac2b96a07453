#include "evfs/core/metrics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "evfs/core/error.h"

namespace evfs {
namespace {

// Reference values come from scikit-image 0.19 (Debian 12's python3-skimage), an implementation
// independent of ours, computed on the same analytic images:
//   structural_similarity(u, v, gaussian_weights=True, sigma=1.5,
//                         use_sample_covariance=False, data_range=1.0)
//   peak_signal_noise_ratio(v, u, data_range=1.0)
// with h, w = 32, 40 and the formulas of the Make* helpers below.
constexpr double kSsimAB = 0.8661797715515431;
constexpr double kSsimAC = 0.920660276586037;
constexpr double kPsnrAB = 20.264147445124856;
constexpr double kPsnrAC = 26.00259230565133;
// Both implementations are double precision and sum the same terms in a different order.
constexpr double kReferenceTolerance = 1e-9;

constexpr int kHeight = 32;
constexpr int kWidth = 40;

template <typename F>
Image MakeImage(F f) {
  Image image(kHeight, kWidth);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x)
      image(y, x) = f(static_cast<double>(y), static_cast<double>(x));
  }
  return image;
}

Image MakeA() {
  return MakeImage([](double y, double x) { return 0.5 + 0.4 * std::sin(0.3 * x + 0.2 * y); });
}
Image MakeB() {
  return MakeImage([](double y, double x) {
    return 0.5 + 0.35 * std::sin(0.31 * x + 0.2 * y + 0.1) + 0.05 * std::cos(0.7 * y);
  });
}
Image MakeC() {
  return MakeImage([](double y, double x) {
    const double v =
        0.5 + 0.4 * std::sin(0.3 * x + 0.2 * y) + 0.1 * std::cos(1.3 * x) * std::sin(0.9 * y);
    return std::clamp(v, 0.0, 1.0);
  });
}

TEST(Metrics, SsimMatchesScikitImage) {
  EXPECT_NEAR(Ssim(MakeA(), MakeB()), kSsimAB, kReferenceTolerance);
  EXPECT_NEAR(Ssim(MakeA(), MakeC()), kSsimAC, kReferenceTolerance);
}

TEST(Metrics, SsimIsSymmetricAndOneForIdenticalImages) {
  EXPECT_NEAR(Ssim(MakeB(), MakeA()), kSsimAB, kReferenceTolerance);
  EXPECT_NEAR(Ssim(MakeA(), MakeA()), 1.0, kReferenceTolerance);
}

TEST(Metrics, PsnrMatchesScikitImage) {
  EXPECT_NEAR(Psnr(MakeA(), MakeB()), kPsnrAB, kReferenceTolerance);
  EXPECT_NEAR(Psnr(MakeA(), MakeC()), kPsnrAC, kReferenceTolerance);
}

TEST(Metrics, PsnrOfHandComputedError) {
  // Every pixel off by 0.1: MSE = 0.01, PSNR = 10 log10(100) = 20 dB exactly.
  const Image a = Image::Constant(4, 5, 0.3);
  const Image b = Image::Constant(4, 5, 0.4);
  EXPECT_NEAR(Psnr(a, b), 20.0, 1e-12);
  EXPECT_EQ(Psnr(a, a), std::numeric_limits<double>::infinity());
}

TEST(Metrics, RejectsMismatchedOrTinyImages) {
  EXPECT_THROW(Psnr(Image::Zero(4, 5), Image::Zero(5, 4)), InvalidArgumentError);
  EXPECT_THROW(Ssim(Image::Zero(10, 10), Image::Zero(10, 10)), InvalidArgumentError);
  EXPECT_THROW(Psnr(Image(0, 0), Image(0, 0)), InvalidArgumentError);
}

TEST(Metrics, LaplacianVarianceGrowsWithSharpness) {
  // A checkerboard is maximally sharp; its blurred (box-averaged) version is not.
  Image sharp(8, 8);
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x) sharp(y, x) = ((x + y) % 2) ? 1.0 : 0.0;
  }
  // Interior Laplacian of a checkerboard is ±4, so the variance is 16.
  EXPECT_NEAR(LaplacianVariance(sharp), 16.0, 1e-12);
  EXPECT_NEAR(LaplacianVariance(Image::Constant(8, 8, 0.5)), 0.0, 1e-15);
}

// A step from 0.2 to 0.7 across the line through (32, 32) at `angle` to the vertical, blurred by a
// Gaussian of σ `sigma` px (exact: the step's profile is an error function).
Image BlurredStep(double sigma, double angle = 0.0) {
  Image image(64, 64);
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      const double d = (x - 32.0) * std::cos(angle) + (y - 32.0) * std::sin(angle);
      image(y, x) = 0.2 + 0.25 * (1.0 + std::erf(d / (std::sqrt(2.0) * sigma)));
    }
  }
  return image;
}

// The 10–90 % rise of BlurredStep(sigma)'s pixels joined by straight lines, as EdgeWidth samples
// them (bilinear): a little wider than the continuous step's 2 × 1.2816 σ.
double SampledRise(double sigma) {
  const auto level = [sigma](int x) {
    return 0.5 * (1.0 + std::erf((x - 32.0) / (std::sqrt(2.0) * sigma)));
  };
  const auto crossing = [&](double fraction) {
    int x = 0;
    while (level(x + 1) < fraction) ++x;
    return x + (fraction - level(x)) / (level(x + 1) - level(x));
  };
  return crossing(0.9) - crossing(0.1);
}

TEST(Metrics, EdgeWidthOfABlurredStepIsItsTenToNinetyRise) {
  for (const double sigma : {1.0, 1.5, 2.0}) {
    const Image step = BlurredStep(sigma);
    const EdgeWidthScore score = EdgeWidth(step, step);
    EXPECT_GT(score.edges, 0);
    // The profile is sampled every 0.1 px.
    EXPECT_NEAR(score.mean_px, SampledRise(sigma), 0.1) << "sigma " << sigma;
    EXPECT_NEAR(score.mean_px, 2.563 * sigma, 0.35) << "sigma " << sigma;
  }
  const Image diagonal = BlurredStep(1.5, 0.5);
  EXPECT_NEAR(EdgeWidth(diagonal, diagonal).mean_px, SampledRise(1.5), 0.2);
}

TEST(Metrics, EdgeWidthSeesBlurNotIsolatedNoisyPixels) {
  const Image sharp = BlurredStep(1.0), soft = BlurredStep(1.5);
  Image speckled = sharp;
  for (int y = 1; y < 63; y += 4) {
    for (int x = 2; x < 63; x += 5) {
      if (std::abs(x - 32) > 8) speckled(y, x) += ((x + y) % 3 ? 0.3 : -0.15);
    }
  }
  EXPECT_GT(LaplacianVariance(speckled), 10.0 * LaplacianVariance(sharp));
  // The same edges, located on the clean step.
  const double width = EdgeWidth(sharp, sharp).mean_px;
  EXPECT_NEAR(EdgeWidth(speckled, sharp).mean_px, width, 0.05);
  EXPECT_GT(EdgeWidth(soft, sharp).mean_px, width + 1.0);
}

TEST(Metrics, EdgeWidthWithoutEdgesOrOnBadSizes) {
  const Image flat = Image::Constant(32, 32, 0.5);
  const EdgeWidthScore none = EdgeWidth(flat, flat);
  EXPECT_EQ(none.edges, 0);
  EXPECT_TRUE(std::isnan(none.mean_px));
  // An edge too faint in the measured image is left out.
  const Image step = BlurredStep(1.0);
  EXPECT_EQ(EdgeWidth(Image::Constant(64, 64, 0.5) + 0.01 * step, step).edges, 0);
  EXPECT_THROW(EdgeWidth(Image::Zero(17, 40), Image::Zero(17, 40)), InvalidArgumentError);
  EXPECT_THROW(EdgeWidth(step, Image::Zero(64, 63)), InvalidArgumentError);
}

}  // namespace
}  // namespace evfs
