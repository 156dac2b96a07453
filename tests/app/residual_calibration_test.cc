#include "app/residual_calibration.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "scene/scene.h"
#include "tests/scene/scene_test_scenes.h"

namespace evfs {
namespace {

// An interpolation scene of the synthetic recording, its "reconstruction" (the blend) and a
// "denoised" video that differs from it by `correction` at every latent frame.
struct Case {
  test::SyntheticRecording recording;
  Scene scene = MakeInterpolationScene(recording.Sharp(0), recording.Sharp(20), recording.events,
                                       BinningOptions());
  Video before = InitializeLatentVideo(scene);
  Video denoised = before;

  void Correct(const Image& correction) {
    for (int t = 0; t < denoised.num_frames(); ++t)
      denoised.frame(t) = before.frame(t) - correction;
  }
  // The observation misfit of the first frame: mean of its exposure minus the frame.
  Image FirstFrameMisfit() const {
    const FrameObservation& frame = scene.frames.front();
    Image mean = Image::Zero(scene.height, scene.width);
    for (int t = frame.latent_first; t <= frame.latent_last; ++t) {
      mean += before.frame(t) / (frame.latent_last - frame.latent_first + 1);
    }
    return mean - frame.image;
  }
};

TEST(ResidualCalibration, ACorrectionTowardsTheObservationsKeepsItsSize) {
  Case c;
  // Disturb the reconstruction at the observed frames by a pattern the denoiser then removes.
  Image pattern = Image::Zero(c.scene.height, c.scene.width);
  for (int y = 0; y < pattern.rows(); y += 3) pattern.row(y) = 0.05;
  for (int t = 0; t < c.before.num_frames(); ++t) c.before.frame(t) += pattern;
  c.Correct(pattern);
  const ResidualCalibration calibration = CalibrateResidual(c.scene, c.before, c.denoised);
  EXPECT_EQ(calibration.observations, 2);
  EXPECT_GT(calibration.energy, 0.0);
  EXPECT_NEAR(calibration.scale, 1.0, 1e-9);  // it removes the disturbance exactly
}

TEST(ResidualCalibration, ACorrectionAgainstTheObservationsIsDropped) {
  Case c;
  // The reconstruction is off by e at the observed frames and the "denoiser" doubles the error
  // (the network "denoising" what the sensor saw): the least-squares scale is -1, clamped to 0.
  Image error = Image::Zero(c.scene.height, c.scene.width);
  for (int x = 0; x < error.cols(); x += 4) error.col(x) = 0.02;
  for (int t = 0; t < c.before.num_frames(); ++t) c.before.frame(t) += error;
  c.Correct(-error);
  const ResidualCalibration calibration = CalibrateResidual(c.scene, c.before, c.denoised);
  EXPECT_NEAR((c.FirstFrameMisfit() - error).abs().maxCoeff(), 0.0, 1e-12);
  EXPECT_LT(calibration.agreement, 0.0);
  EXPECT_DOUBLE_EQ(calibration.scale, 0.0);
  ScaleResidual(calibration.scale, c.before, &c.denoised);
  for (int t = 0; t < c.before.num_frames(); ++t) {
    EXPECT_TRUE((c.denoised.frame(t) == c.before.frame(t)).all()) << "frame " << t;
  }
}

TEST(ResidualCalibration, AHalfRightCorrectionIsHalved) {
  Case c;
  // The reconstruction is off by e at the observed frames; the denoiser removes 2e: the least
  // squares scale is 1/2, and the scaled correction removes e exactly.
  Image error = Image::Zero(c.scene.height, c.scene.width);
  error.block(10, 10, 20, 20) = 0.04;
  for (int t = 0; t < c.before.num_frames(); ++t) c.before.frame(t) += error;
  c.Correct(2.0 * error);
  const ResidualCalibration calibration = CalibrateResidual(c.scene, c.before, c.denoised);
  EXPECT_NEAR(calibration.scale, 0.5, 1e-9);
  ScaleResidual(calibration.scale, c.before, &c.denoised);
  const FrameObservation& first = c.scene.frames.front();
  EXPECT_LT((c.denoised.frame(first.latent_first) - first.image).abs().maxCoeff(), 1e-12);
}

TEST(ResidualCalibration, PixelsTheDenoiserLeftKeepTheirBits) {
  Case c;
  Image correction = Image::Zero(c.scene.height, c.scene.width);
  correction(5, 7) = 0.3;
  c.Correct(correction);
  ScaleResidual(0.37, c.before, &c.denoised);
  for (int t = 0; t < c.before.num_frames(); ++t) {
    const Image difference = c.denoised.frame(t) - c.before.frame(t);
    EXPECT_EQ((difference != 0.0).count(), 1) << "frame " << t;
    EXPECT_NEAR(difference(5, 7), -0.37 * 0.3, 1e-15);
  }
}

TEST(ResidualCalibration, VideosOffTheTimelineAreRejected) {
  Case c;
  const Video shorter(c.before.height(), c.before.width(), 2);  // not the scene's timeline
  EXPECT_THROW(CalibrateResidual(c.scene, shorter, shorter), InvalidArgumentError);
}

}  // namespace
}  // namespace evfs
