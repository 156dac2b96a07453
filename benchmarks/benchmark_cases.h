// The reconstruction cases the whole-pipeline benchmarks share: the 240 fps ground-truth clips
// with events simulated by SimulateEvents' defaults (interpolation of frame 2 from frames 0 and
// 4; deblurring the mean of frames 0–7), and the scores of a deblur without a sharp truth.
#ifndef EVFS_BENCHMARKS_BENCHMARK_CASES_H_
#define EVFS_BENCHMARKS_BENCHMARK_CASES_H_

#include <string>
#include <vector>

#include "evfs/core/event_stream.h"
#include "evfs/core/video.h"
#include "evfs/scene/scene.h"

namespace evfs {

/// The non-empty items of a comma-separated list ("a,b,,c" → a, b, c).
std::vector<std::string> SplitCommaList(const std::string& list);

/// The first frames of a ground-truth clip and the events SimulateEvents (default options)
/// makes of them.
struct SimulatedClip {
  Video frames;
  EventStream events;
};

/// Frames the clip cases use: 0–7 (the deblur's exposure; the interpolation uses 0, 2 and 4).
constexpr int kClipFrames = 8;
/// The interpolation case: frame kClipTruthFrame from frames kClipFirstFrame and kClipLastFrame.
constexpr int kClipFirstFrame = 0;
constexpr int kClipTruthFrame = 2;
constexpr int kClipLastFrame = 4;

/// Reads the first kClipFrames frames of `data_dir`/`name` (images.txt), keeps their central
/// crop_px × crop_px pixels when crop_px > 0 (all of a side shorter than that), and simulates
/// their events. Throws InputError for a missing or malformed clip.
SimulatedClip LoadSimulatedClip(const std::string& data_dir, const std::string& name,
                                int crop_px = 0);

/// Interpolation of frame kClipTruthFrame from the sharp frames kClipFirstFrame and
/// kClipLastFrame with the events between them.
Scene MakeClipInterpolationScene(const SimulatedClip& clip, const BinningOptions& binning);

/// The clip's blurred frame: the mean of frames 0 … kClipFrames − 1, exposed from the first
/// frame's timestamp to the last one's.
TimedFrame ClipBlurredFrame(const SimulatedClip& clip);

/// Deblurring of ClipBlurredFrame with the events of its exposure.
Scene MakeClipDeblurScene(const SimulatedClip& clip, const BinningOptions& binning);

/// An image quality metric of core/metrics.h (Psnr, Ssim): (estimate, reference) → score.
using ImageMetric = double (*)(const Image& estimate, const Image& reference);

/// The clip deblur's score: the mean over frames 0 … kClipFrames − 1 of `metric` of the latent
/// frame nearest each frame's timestamp against that frame.
double ScoreClipDeblur(const Video& latent, const SimulatedClip& clip, ImageMetric metric);

/// A deblur without a sharp truth (eslnet_cups_blur): the mean of the latent frames must
/// reproduce the blurred input, and the latent frames must be sharper than it.
struct DeblurWithoutTruthScore {
  /// PSNR (dB) of the mean of the latent frames against the blurred input.
  double mean_vs_input_psnr = 0.0;
  /// Variance of the Laplacian (LaplacianVariance), mean over the latent frames.
  double latent_sharpness = 0.0;
  /// Variance of the Laplacian of the blurred input.
  double input_sharpness = 0.0;
};
DeblurWithoutTruthScore ScoreDeblurWithoutTruth(const Video& latent, const Image& blurred);

}  // namespace evfs

#endif  // EVFS_BENCHMARKS_BENCHMARK_CASES_H_
