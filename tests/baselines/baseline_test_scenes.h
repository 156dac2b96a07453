// Scenes for the baseline tests: the solver tests' synthetic recording, cut into the three cases.
#ifndef EVFS_TESTS_BASELINES_BASELINE_TEST_SCENES_H_
#define EVFS_TESTS_BASELINES_BASELINE_TEST_SCENES_H_

#include "evfs/core/metrics.h"
#include "evfs/core/video.h"
#include "evfs/scene/scene.h"
#include "evfs/tests/scene/scene_test_scenes.h"

namespace evfs {
namespace test {

/// Rendered frames 0 and 20 with the events between them.
inline Scene InterpolationScene(const SyntheticRecording& recording) {
  return MakeInterpolationScene(recording.Sharp(0), recording.Sharp(20), recording.events,
                                BinningOptions());
}

/// Rendered frame 0 and the events up to frame 10.
inline Scene PredictionScene(const SyntheticRecording& recording) {
  return MakePredictionScene(recording.Sharp(0), recording.rendered.timestamp_ns(10),
                             recording.events, BinningOptions());
}

/// The mean of rendered frames 0..20 over their times, with the events inside.
inline Scene DeblurScene(const SyntheticRecording& recording) {
  return MakeDeblurScene(recording.Blurred(0, 20), recording.events, BinningOptions());
}

/// PSNR of the latent frame nearest rendered frame `truth` against it.
inline double PsnrAt(const Video& video, const SyntheticRecording& recording, int truth) {
  const int index = video.NearestFrame(recording.rendered.timestamp_ns(truth));
  return Psnr(video.frame(index), recording.rendered.frame(truth));
}

/// Largest absolute difference between two images of one size.
inline double MaxAbsDifference(const Image& a, const Image& b) { return (a - b).abs().maxCoeff(); }

}  // namespace test
}  // namespace evfs

#endif  // EVFS_TESTS_BASELINES_BASELINE_TEST_SCENES_H_
