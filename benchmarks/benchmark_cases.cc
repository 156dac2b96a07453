#include "evfs/benchmarks/benchmark_cases.h"

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "evfs/core/error.h"
#include "evfs/core/metrics.h"
#include "evfs/events/simulator.h"
#include "evfs/io/frame_list.h"
#include "evfs/io/image_io.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;

TimedFrame SharpClipFrame(const SimulatedClip& clip, int t) {
  return TimedFrame{clip.frames.frame(t), clip.frames.timestamp_ns(t), clip.frames.timestamp_ns(t),
                    "frame " + std::to_string(t)};
}

}  // namespace

std::vector<std::string> SplitCommaList(const std::string& list) {
  std::vector<std::string> items;
  std::stringstream stream(list);
  for (std::string item; std::getline(stream, item, ',');) {
    if (!item.empty()) items.push_back(item);
  }
  return items;
}

SimulatedClip LoadSimulatedClip(const std::string& data_dir, const std::string& name, int crop_px) {
  const fs::path folder = fs::path(data_dir) / name;
  const std::string list_path = (folder / "images.txt").string();
  const std::vector<FrameInfo> list = ReadFrameList(list_path);
  if (static_cast<int>(list.size()) < kClipFrames) {
    throw InputError(InputError::Kind::kEmptyWindow, list_path, 0,
                     "at least " + std::to_string(kClipFrames) + " frames, found " +
                         std::to_string(list.size()));
  }
  SimulatedClip clip;
  for (int i = 0; i < kClipFrames; ++i) {
    Image frame = ReadGreyImage((folder / list[i].path).string());
    if (crop_px > 0) {
      const int height = std::min<int>(crop_px, frame.rows());
      const int width = std::min<int>(crop_px, frame.cols());
      frame = Image(
          frame.block((frame.rows() - height) / 2, (frame.cols() - width) / 2, height, width));
    }
    clip.frames.AppendFrame(frame, list[i].t_ns);
  }
  clip.events = SimulateEvents(clip.frames, SimulatorOptions());
  return clip;
}

Scene MakeClipInterpolationScene(const SimulatedClip& clip, const BinningOptions& binning) {
  return MakeInterpolationScene(SharpClipFrame(clip, kClipFirstFrame),
                                SharpClipFrame(clip, kClipLastFrame), clip.events, binning);
}

TimedFrame ClipBlurredFrame(const SimulatedClip& clip) {
  TimedFrame blurred{Image::Zero(clip.frames.height(), clip.frames.width()),
                     clip.frames.timestamp_ns(0), clip.frames.timestamp_ns(kClipFrames - 1),
                     "mean of frames 0-" + std::to_string(kClipFrames - 1)};
  for (int t = 0; t < kClipFrames; ++t) blurred.image += clip.frames.frame(t);
  blurred.image /= kClipFrames;
  return blurred;
}

Scene MakeClipDeblurScene(const SimulatedClip& clip, const BinningOptions& binning) {
  return MakeDeblurScene(ClipBlurredFrame(clip), clip.events, binning);
}

double ScoreClipDeblur(const Video& latent, const SimulatedClip& clip, ImageMetric metric) {
  double score = 0.0;
  for (int t = 0; t < kClipFrames; ++t) {
    const int index = latent.NearestFrame(clip.frames.timestamp_ns(t));
    score += metric(latent.frame(index), clip.frames.frame(t)) / kClipFrames;
  }
  return score;
}

DeblurWithoutTruthScore ScoreDeblurWithoutTruth(const Video& latent, const Image& blurred) {
  Image mean = Image::Zero(latent.height(), latent.width());
  DeblurWithoutTruthScore score;
  for (int t = 0; t < latent.num_frames(); ++t) {
    mean += latent.frame(t);
    score.latent_sharpness += LaplacianVariance(latent.frame(t)) / latent.num_frames();
  }
  mean /= latent.num_frames();
  score.mean_vs_input_psnr = Psnr(mean, blurred);
  score.input_sharpness = LaplacianVariance(blurred);
  return score;
}

}  // namespace evfs
