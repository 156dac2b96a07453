#include "evfs/baselines/event_double_integral.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "evfs/baselines/baseline.h"
#include "evfs/core/error.h"
#include "evfs/tests/baselines/baseline_test_scenes.h"

namespace evfs {
namespace {

// The mean of the latent frames is B times a mean divided by itself: rounding only.
constexpr double kRoundingTolerance = 1e-12;
// EDI with the criterion's threshold scores 36.97 dB at the middle of the 48×40 blurred scene,
// the blurred frame 32.69 dB (printed below when this was set); the bar is well below the gain.
constexpr double kMinGainOverBlurredDb = 2.5;
// The truth-tuned search and the criterion's search stop within 1e-3 of their optimum: the
// tuned PSNR may fall short of the criterion's by that much of the curve's slope.
constexpr double kSearchToleranceDb = 1e-3;

TEST(EventDoubleIntegral, MeanOfTheLatentFramesOverTheExposureIsTheBlurredFrame) {
  const test::SyntheticRecording recording;
  const Scene scene = test::DeblurScene(recording);
  const FrameObservation& blurred = scene.frames[0];
  BaselineOptions options;
  options.clamp_to_unit_range = false;
  for (double threshold : {0.05, 0.2, 0.6}) {
    const Video latent = EventDoubleIntegral(scene, options, threshold);
    ASSERT_EQ(latent.num_frames(), scene.num_latent_frames());
    EXPECT_EQ(latent.timestamps_ns(), scene.latent_timestamps_ns());
    Image mean = Image::Zero(scene.height, scene.width);
    for (int t = blurred.latent_first; t <= blurred.latent_last; ++t) mean += latent.frame(t);
    mean /= blurred.latent_last - blurred.latent_first + 1;
    EXPECT_LT(test::MaxAbsDifference(mean, blurred.image), kRoundingTolerance) << threshold;
  }
}

TEST(EventDoubleIntegral, SharpensASimulatedBlur) {
  const test::SyntheticRecording recording;
  const Scene scene = test::DeblurScene(recording);
  const BaselineResult edi = RunBaseline(BaselineMethod::kEdi, scene, BaselineOptions());
  const double blurred = Psnr(scene.frames[0].image, recording.rendered.frame(10));
  const double deblurred = test::PsnrAt(edi.video, recording, 10);
  std::printf("deblur of frames 0..20, at frame 10: blurred %.2f dB, edi %.2f dB (c = %.3f)\n",
              blurred, deblurred, edi.parameters[0].value);
  EXPECT_GE(deblurred, blurred + kMinGainOverBlurredDb);
}

TEST(EventDoubleIntegral, TheCriterionsThresholdMinimisesTheEnergy) {
  const test::SyntheticRecording recording;
  const Scene scene = test::DeblurScene(recording);
  const BaselineOptions options;
  const EdiThreshold chosen = ChooseEdiThreshold(scene, options);
  EXPECT_GE(chosen.contrast_threshold, options.threshold_search_min);
  EXPECT_LE(chosen.contrast_threshold, options.threshold_search_max);
  for (double threshold :
       {options.threshold_search_min, 0.05, 0.1, 0.2, 0.4, options.threshold_search_max}) {
    EXPECT_LE(chosen.sharpness.energy, EdiSharpnessEnergy(scene, options, threshold).energy)
        << threshold;
  }
  // The sharpness is judged at the latent frame nearest the middle of the exposure.
  const std::vector<int64_t>& latent_ns = scene.latent_timestamps_ns();
  const int64_t middle_ns = (latent_ns.front() + latent_ns.back()) / 2;
  const int reference = chosen.sharpness.reference_latent_frame;
  for (int t = 0; t < static_cast<int>(latent_ns.size()); ++t) {
    EXPECT_LE(std::llabs(latent_ns[reference] - middle_ns), std::llabs(latent_ns[t] - middle_ns));
  }
}

TEST(EventDoubleIntegral, TheThresholdTunedOnTheTruthScoresAtLeastTheCriterions) {
  const test::SyntheticRecording recording;
  const Scene scene = test::DeblurScene(recording);
  const BaselineResult criterion = RunBaseline(BaselineMethod::kEdi, scene, BaselineOptions());
  const int latent = criterion.video.NearestFrame(recording.rendered.timestamp_ns(10));
  const BaselineResult tuned = TuneContrastThresholdOnTruth(
      BaselineMethod::kEdi, scene, BaselineOptions(), recording.rendered.frame(10), latent);
  EXPECT_NE(tuned.threshold_source.find("truth"), std::string::npos);
  EXPECT_GE(test::PsnrAt(tuned.video, recording, 10),
            test::PsnrAt(criterion.video, recording, 10) - kSearchToleranceDb);
}

TEST(EventDoubleIntegral, RejectsScenesWithoutExactlyOneBlurredFrame) {
  const test::SyntheticRecording recording;
  EXPECT_THROW(EventDoubleIntegral(test::PredictionScene(recording), BaselineOptions(), 0.2),
               InvalidArgumentError);
  EXPECT_THROW(EventDoubleIntegral(test::InterpolationScene(recording), BaselineOptions(), 0.2),
               InvalidArgumentError);
}

}  // namespace
}  // namespace evfs
