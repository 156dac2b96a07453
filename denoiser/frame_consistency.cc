#include "evfs/denoiser/frame_consistency.h"

#include <algorithm>
#include <string>

#include "evfs/core/error.h"

namespace evfs {
namespace {

double CorrectionEnergy(const Video& before, const Video& denoised) {
  double energy = 0.0;
  for (int t = 0; t < before.num_frames(); ++t) {
    energy += (before.frame(t) - denoised.frame(t)).square().sum();
  }
  return energy;
}

}  // namespace

FrameConsistency KeepFramesConsistent(const Scene& scene, const Video& before, Video* denoised) {
  if (before.num_frames() != scene.num_latent_frames() ||
      denoised->num_frames() != before.num_frames() || before.height() != scene.height ||
      before.width() != scene.width || denoised->height() != before.height() ||
      denoised->width() != before.width()) {
    throw InvalidArgumentError(
        "the videos to keep consistent are not on the scene's latent timeline");
  }
  FrameConsistency consistency;
  consistency.observations = static_cast<int>(scene.frames.size());
  consistency.correction_energy = CorrectionEnergy(before, *denoised);
  if (consistency.correction_energy == 0.0) return consistency;
  // One pass projects onto each exposure in turn; exposures that share no latent frame are
  // orthogonal, so the first pass is the projection and the second finds nothing left. Shared
  // latent frames need more passes (alternating projections onto the frames' constraints
  // converge to the projection onto all of them).
  constexpr int kMaxPasses = 1000;
  constexpr double kTolerance = 1e-12;
  for (int pass = 0; pass < kMaxPasses; ++pass) {
    double largest = 0.0;
    for (const FrameObservation& frame : scene.frames) {
      const int length = frame.latent_last - frame.latent_first + 1;
      Image mean = Image::Zero(scene.height, scene.width);
      for (int t = frame.latent_first; t <= frame.latent_last; ++t) {
        mean += (before.frame(t) - denoised->frame(t)) / length;
      }
      largest = std::max(largest, mean.abs().maxCoeff());
      // Where the denoiser changed nothing the mean is 0 and the pixel keeps its bits.
      for (int t = frame.latent_first; t <= frame.latent_last; ++t) denoised->frame(t) += mean;
    }
    if (largest <= kTolerance) break;
  }
  consistency.removed_energy =
      std::max(0.0, consistency.correction_energy - CorrectionEnergy(before, *denoised));
  return consistency;
}

std::vector<uint8_t> FramesToDenoise(const Scene& scene, std::vector<uint8_t> read) {
  const int n = scene.num_latent_frames();
  if (static_cast<int>(read.size()) != n) {
    throw InvalidArgumentError("frames to denoise: " + std::to_string(read.size()) + " flags for " +
                               std::to_string(n) + " latent frames");
  }
  for (uint8_t& flag : read) flag = flag != 0 ? 1 : 0;
  // How many exposures hold each latent frame.
  std::vector<int> holders(n, 0);
  for (const FrameObservation& frame : scene.frames) {
    for (int t = frame.latent_first; t <= frame.latent_last; ++t) ++holders[t];
  }
  // Grow the flags over whole exposures until none grows (exposures sharing latent frames
  // chain).
  const auto is_set = [](uint8_t flag) { return flag != 0; };
  for (bool grew = true; grew;) {
    grew = false;
    for (const FrameObservation& frame : scene.frames) {
      if (frame.latent_first == frame.latent_last) continue;
      const auto first = read.begin() + frame.latent_first;
      const auto last = read.begin() + frame.latent_last + 1;
      if (std::none_of(first, last, is_set) || std::all_of(first, last, is_set)) continue;
      std::fill(first, last, 1);
      grew = true;
    }
  }
  for (const FrameObservation& frame : scene.frames) {
    if (frame.latent_first == frame.latent_last && holders[frame.latent_first] == 1) {
      read[frame.latent_first] = 0;
    }
  }
  return read;
}

}  // namespace evfs
