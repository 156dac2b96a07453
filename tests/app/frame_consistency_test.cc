#include "evfs/denoiser/frame_consistency.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/scene/scene.h"
#include "evfs/tests/scene/scene_test_scenes.h"

namespace evfs {
namespace {

// A scene of the synthetic recording, its "reconstruction" (the blend) and a "denoised" video
// that differs from it by a correction.
struct Case {
  explicit Case(Scene scene_in) : scene(std::move(scene_in)) {}

  Scene scene;
  Video before = InitializeLatentVideo(scene);
  Video denoised = before;

  // The correction at latent frame t: `pattern` times (1 + t).
  void Correct(const Image& pattern) {
    for (int t = 0; t < denoised.num_frames(); ++t)
      denoised.frame(t) = before.frame(t) - (1.0 + t) * pattern;
  }
  // The mean of `video` over frame k's exposure.
  Image ExposureMean(const Video& video, int k) const {
    const FrameObservation& frame = scene.frames[k];
    Image mean = Image::Zero(scene.height, scene.width);
    for (int t = frame.latent_first; t <= frame.latent_last; ++t) {
      mean += video.frame(t) / (frame.latent_last - frame.latent_first + 1);
    }
    return mean;
  }
};

const test::SyntheticRecording& Recording() {
  static const test::SyntheticRecording recording;
  return recording;
}

Case InterpolationCase() {
  return Case(MakeInterpolationScene(Recording().Sharp(0), Recording().Sharp(20),
                                     Recording().events, BinningOptions()));
}

Case DeblurCase() {
  return Case(MakeDeblurScene(Recording().Blurred(2, 17), Recording().events, BinningOptions()));
}

Image Checkerboard(int height, int width) {
  Image pattern = Image::Zero(height, width);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) pattern(y, x) = ((x + y) % 2 == 0) ? 0.01 : -0.02;
  return pattern;
}

TEST(FrameConsistency, SharpFramesKeepTheSolveAndTheFramesBetweenKeepTheCorrection) {
  Case c = InterpolationCase();
  c.Correct(Checkerboard(c.scene.height, c.scene.width));
  const Video full = c.denoised;
  const FrameConsistency consistency = KeepFramesConsistent(c.scene, c.before, &c.denoised);
  ASSERT_EQ(consistency.observations, 2);
  std::vector<bool> observed(c.before.num_frames(), false);
  for (const FrameObservation& frame : c.scene.frames) {
    ASSERT_EQ(frame.latent_first, frame.latent_last);  // a sharp frame: one latent frame
    observed[frame.latent_first] = true;
  }
  double kept = 0.0;
  for (int t = 0; t < c.before.num_frames(); ++t) {
    const Video& expected = observed[t] ? c.before : full;
    EXPECT_LT((c.denoised.frame(t) - expected.frame(t)).abs().maxCoeff(), 1e-15) << "frame " << t;
    kept += (c.before.frame(t) - c.denoised.frame(t)).square().sum();
  }
  EXPECT_GT(consistency.removed_energy, 0.0);
  EXPECT_NEAR(consistency.removed_energy + kept, consistency.correction_energy,
              1e-12 * consistency.correction_energy);
  EXPECT_GT(consistency.RemovedFraction(), 0.0);
  EXPECT_LT(consistency.RemovedFraction(), 1.0);
}

TEST(FrameConsistency, ABlurredFrameKeepsItsMeanAndTheNearestCorrectionIsKept) {
  Case c = DeblurCase();
  ASSERT_EQ(c.scene.frames.size(), 1u);
  const FrameObservation& frame = c.scene.frames.front();
  const int length = frame.latent_last - frame.latent_first + 1;
  ASSERT_GT(length, 2);
  c.Correct(Checkerboard(c.scene.height, c.scene.width));
  const Video full = c.denoised;
  KeepFramesConsistent(c.scene, c.before, &c.denoised);
  // The exposure mean is the solve's.
  EXPECT_LT((c.ExposureMean(c.denoised, 0) - c.ExposureMean(c.before, 0)).abs().maxCoeff(), 1e-15);
  // The correction (1 + t) p becomes (t - mean t) p over the exposure: its change within the
  // exposure stays, its mean goes (the nearest correction that keeps the frame).
  double mean_t = 0.0;
  for (int t = frame.latent_first; t <= frame.latent_last; ++t) mean_t += (1.0 + t) / length;
  const Image pattern = Checkerboard(c.scene.height, c.scene.width);
  for (int t = 0; t < c.before.num_frames(); ++t) {
    const bool inside = t >= frame.latent_first && t <= frame.latent_last;
    const Image expected =
        inside ? Image(c.before.frame(t) - (1.0 + t - mean_t) * pattern) : full.frame(t);
    EXPECT_LT((c.denoised.frame(t) - expected).abs().maxCoeff(), 1e-14) << "frame " << t;
  }
}

TEST(FrameConsistency, ACorrectionTheSameThroughAnExposureIsRemoved) {
  Case c = DeblurCase();
  Image offset = Image::Zero(c.scene.height, c.scene.width);
  offset.block(10, 10, 20, 20) = 0.04;
  for (int t = 0; t < c.before.num_frames(); ++t) c.denoised.frame(t) = c.before.frame(t) - offset;
  const FrameConsistency consistency = KeepFramesConsistent(c.scene, c.before, &c.denoised);
  const FrameObservation& frame = c.scene.frames.front();
  for (int t = frame.latent_first; t <= frame.latent_last; ++t) {
    EXPECT_LT((c.denoised.frame(t) - c.before.frame(t)).abs().maxCoeff(), 1e-15) << "frame " << t;
  }
  if (frame.latent_first == 0 && frame.latent_last == c.before.num_frames() - 1) {
    EXPECT_NEAR(consistency.RemovedFraction(), 1.0, 1e-12);
  }
}

TEST(FrameConsistency, PixelsTheDenoiserLeftKeepTheirBits) {
  for (Case c : {InterpolationCase(), DeblurCase()}) {
    Image pattern = Image::Zero(c.scene.height, c.scene.width);
    pattern(5, 7) = 0.3;
    c.Correct(pattern);
    KeepFramesConsistent(c.scene, c.before, &c.denoised);
    for (int t = 0; t < c.before.num_frames(); ++t) {
      Image difference = c.denoised.frame(t) - c.before.frame(t);
      difference(5, 7) = 0.0;
      EXPECT_TRUE((difference == 0.0).all()) << "frame " << t;
    }
  }
}

TEST(FrameConsistency, ExposuresSharingLatentFramesAreAllKept) {
  // Two blurred frames whose exposures overlap: alternating projections until both hold.
  Case c = DeblurCase();
  const int n = c.before.num_frames();
  ASSERT_GE(n, 6);
  c.scene.frames = {FrameObservation{c.before.frame(0), 0, n / 2 + 1, "a"},
                    FrameObservation{c.before.frame(0), n / 2 - 1, n - 1, "b"}};
  c.Correct(Checkerboard(c.scene.height, c.scene.width));
  const FrameConsistency consistency = KeepFramesConsistent(c.scene, c.before, &c.denoised);
  for (int k = 0; k < 2; ++k) {
    EXPECT_LT((c.ExposureMean(c.denoised, k) - c.ExposureMean(c.before, k)).abs().maxCoeff(), 1e-11)
        << "frame " << k;
  }
  EXPECT_GT(consistency.removed_energy, 0.0);
  EXPECT_LT(consistency.removed_energy, consistency.correction_energy);
}

TEST(FrameConsistency, AVideoTheDenoiserLeftAloneStaysAsItWas) {
  Case c = InterpolationCase();
  const FrameConsistency consistency = KeepFramesConsistent(c.scene, c.before, &c.denoised);
  EXPECT_EQ(consistency.correction_energy, 0.0);
  EXPECT_EQ(consistency.RemovedFraction(), 0.0);
  for (int t = 0; t < c.before.num_frames(); ++t) {
    EXPECT_TRUE((c.denoised.frame(t) == c.before.frame(t)).all());
  }
}

TEST(FrameConsistency, DenoisingTheFramesToDenoiseGivesTheReadFramesOfDenoisingAll) {
  // Sharp frames at both ends and a blurred one between them: a window of evfs video.
  const test::SyntheticRecording& recording = Recording();
  const TimedFrame first = recording.Sharp(0), last = recording.Sharp(20);
  Case c(MakeScene({first, recording.Blurred(6, 12), last}, recording.events,
                   first.exposure_begin_ns, last.exposure_end_ns, BinningOptions()));
  ASSERT_EQ(c.scene.frames.size(), 3u);
  const FrameObservation& blurred = c.scene.frames[1];
  ASSERT_GT(blurred.latent_last, blurred.latent_first + 1);
  const int n = c.before.num_frames();
  const int sharp_first = c.scene.frames[0].latent_first;
  const int sharp_last = c.scene.frames[2].latent_first;
  // A correction that differs from frame to frame.
  const Image pattern = Checkerboard(c.scene.height, c.scene.width);
  const auto correction = [&](int t) { return Image((1.0 + t) * pattern + 0.001 * t * t); };
  Video all = c.before;
  for (int t = 0; t < n; ++t) all.frame(t) = c.before.frame(t) - correction(t);
  KeepFramesConsistent(c.scene, c.before, &all);

  // Read: a frame before the blurred exposure, one inside it and both sharp frames.
  std::vector<uint8_t> read(n, 0);
  const int outside = (sharp_first + blurred.latent_first) / 2;
  ASSERT_NE(outside, sharp_first);
  const int inside = (blurred.latent_first + blurred.latent_last) / 2;
  for (const int t : {outside, inside, sharp_first, sharp_last}) read[t] = 1;
  const std::vector<uint8_t> to_denoise = FramesToDenoise(c.scene, read);
  ASSERT_EQ(static_cast<int>(to_denoise.size()), n);
  EXPECT_EQ(to_denoise[outside], 1);
  EXPECT_EQ(to_denoise[sharp_first], 0);  // its correction is taken out whole
  EXPECT_EQ(to_denoise[sharp_last], 0);
  for (int t = blurred.latent_first; t <= blurred.latent_last; ++t) {
    EXPECT_EQ(to_denoise[t], 1) << "frame " << t << " of the blurred exposure";
  }
  EXPECT_EQ(std::count(to_denoise.begin(), to_denoise.end(), 1),
            1 + blurred.latent_last - blurred.latent_first + 1);

  Video some = c.before;
  for (int t = 0; t < n; ++t) {
    if (to_denoise[t] != 0) some.frame(t) = c.before.frame(t) - correction(t);
  }
  KeepFramesConsistent(c.scene, c.before, &some);
  for (int t = 0; t < n; ++t) {
    if (read[t] == 0) continue;
    EXPECT_LT((some.frame(t) - all.frame(t)).abs().maxCoeff(), 1e-12) << "frame " << t;
  }
  EXPECT_THROW(FramesToDenoise(c.scene, std::vector<uint8_t>(n + 1, 0)), InvalidArgumentError);
}

TEST(FrameConsistency, VideosOffTheTimelineAreRejected) {
  Case c = InterpolationCase();
  Video shorter(c.before.height(), c.before.width(), 2);  // not the scene's timeline
  EXPECT_THROW(KeepFramesConsistent(c.scene, shorter, &shorter), InvalidArgumentError);
  Video narrower(c.before.height(), c.before.width() - 1, c.before.num_frames());
  EXPECT_THROW(KeepFramesConsistent(c.scene, c.before, &narrower), InvalidArgumentError);
}

}  // namespace
}  // namespace evfs
