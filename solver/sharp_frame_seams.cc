#include "evfs/solver/sharp_frame_seams.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "evfs/core/error.h"

namespace evfs {

SharpFrameSeams MeetSharpFrames(const Scene& scene, Video* latent) {
  const int frames = latent->num_frames();
  if (frames != scene.num_latent_frames() || latent->height() != scene.height ||
      latent->width() != scene.width) {
    throw InvalidArgumentError("the video is not on the scene's latent timeline");
  }
  std::vector<double> times(frames);
  for (int t = 0; t < frames; ++t) times[t] = static_cast<double>(latent->timestamp_ns(t));

  SharpFrameSeams seams;
  double sum_squares = 0.0;
  for (size_t j = 0; j < scene.frames.size(); ++j) {
    const FrameObservation& frame = scene.frames[j];
    if (frame.latent_first != frame.latent_last) continue;  // blurred: observes a mean
    const int k = frame.latent_first;
    // Where the correction ends on each side: half-way to the nearest other observation, or
    // the window's end.
    double before = -std::numeric_limits<double>::infinity();
    double after = std::numeric_limits<double>::infinity();
    bool shared = false;
    for (size_t i = 0; i < scene.frames.size(); ++i) {
      if (i == j) continue;
      const FrameObservation& other = scene.frames[i];
      if (other.latent_first <= k && k <= other.latent_last) shared = true;
      if (other.latent_last < k) before = std::max(before, times[other.latent_last]);
      if (other.latent_first > k) after = std::min(after, times[other.latent_first]);
    }
    if (shared) continue;
    const double at = times[k];
    const double begin = std::isfinite(before) ? 0.5 * (before + at) : times.front();
    const double end = std::isfinite(after) ? 0.5 * (at + after) : times.back();

    const Image offset = frame.image - latent->frame(k);
    sum_squares += offset.square().sum();
    ++seams.frames_met;
    for (int t = 0; t < frames; ++t) {
      double weight = 0.0;
      if (t < k && times[t] > begin) {
        weight = (times[t] - begin) / (at - begin);
      } else if (t > k && times[t] < end) {
        weight = (end - times[t]) / (end - at);
      }
      if (t == k) {
        latent->frame(t) = frame.image;
      } else if (weight > 0.0) {
        latent->frame(t) += weight * offset;
      }
    }
  }
  if (seams.frames_met > 0) {
    seams.offset_rms = std::sqrt(
        sum_squares / (static_cast<double>(seams.frames_met) * scene.height * scene.width));
  }
  return seams;
}

}  // namespace evfs
