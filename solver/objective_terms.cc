#include "evfs/solver/objective_terms.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "evfs/core/error.h"

namespace evfs {

ObjectiveTerms::ObjectiveTerms(const Scene& scene, const ObjectiveOptions& objective,
                               const ActivityMask& mask)
    : mask_(mask), height_(scene.height), width_(scene.width), spatial_tv_(objective.spatial_tv) {
  const int64_t pixels = static_cast<int64_t>(height_) * width_;
  if (mask.num_pixels() != pixels) {
    throw InvalidArgumentError("objective terms: the activity mask does not match the scene");
  }
  const int num_latent = scene.num_latent_frames();
  const double per_pixel = 1.0 / static_cast<double>(pixels);
  const auto family_weight = [](double weight) { return weight > 0.0 ? weight : 0.0; };
  weights_[static_cast<int>(TermFamily::kFrame)] =
      family_weight(objective.frame_weight) * per_pixel;
  weights_[static_cast<int>(TermFamily::kEvent)] =
      family_weight(objective.event_weight) * per_pixel;
  weights_[static_cast<int>(TermFamily::kSpatialTv)] =
      family_weight(objective.spatial_tv_weight) * per_pixel / num_latent;
  weights_[static_cast<int>(TermFamily::kTemporalTv)] =
      num_latent > 1 ? family_weight(objective.temporal_tv_weight) * per_pixel : 0.0;
  weights_[static_cast<int>(TermFamily::kPrior)] =
      family_weight(objective.prior_weight) * per_pixel / num_latent;
  if (has(TermFamily::kPrior)) {
    const Video* target = objective.prior_target.get();
    if (target == nullptr || target->num_frames() != num_latent || target->height() != height_ ||
        target->width() != width_) {
      throw InvalidArgumentError(
          "objective terms: the prior's target video does not match the scene's latent size");
    }
  }

  const int64_t active = mask.num_active();
  if (has(TermFamily::kFrame)) {
    counts_[static_cast<int>(TermFamily::kFrame)] =
        static_cast<int64_t>(scene.frames.size()) * active;
  }
  if (has(TermFamily::kEvent)) {
    counts_[static_cast<int>(TermFamily::kEvent)] =
        static_cast<int64_t>(scene.events.num_frames()) * active;
  }
  if (has(TermFamily::kSpatialTv)) {
    int64_t per_frame = 0;
    for (int64_t p = 0; p < pixels; ++p) {
      const SpatialTvTermsAt terms = spatial_tv_terms_at(p);
      per_frame += terms.right + terms.below;
    }
    counts_[static_cast<int>(TermFamily::kSpatialTv)] = per_frame * num_latent;
  }
  if (has(TermFamily::kSpatialTv) && objective.shared_structure_tv) {
    ComputeSharedStructureOffsets(scene);
  }
  if (has(TermFamily::kTemporalTv)) {
    counts_[static_cast<int>(TermFamily::kTemporalTv)] = (num_latent - 1) * active;
    const int min_reversals = objective.log_temporal_tv_reversals;
    if (min_reversals > 0 && objective.event_model.model == EventModel::kLog) {
      std::vector<uint8_t> in_g(static_cast<size_t>(pixels), 0);
      bool any = false;
      for (int64_t p = 0; p < pixels; ++p) {
        in_g[p] = PolarityReversals(scene.events, p) >= min_reversals;
        any = any || in_g[p];
      }
      if (any) temporal_tv_in_g_ = std::move(in_g);
    }
  }
  if (has(TermFamily::kPrior)) {
    counts_[static_cast<int>(TermFamily::kPrior)] = static_cast<int64_t>(num_latent) * active;
  }
}

void ObjectiveTerms::ComputeSharedStructureOffsets(const Scene& scene) {
  const FrameObservation* first = nullptr;
  const FrameObservation* last = nullptr;
  for (const FrameObservation& frame : scene.frames) {
    if (frame.latent_first != frame.latent_last) continue;  // blurred: no structure in place
    if (first == nullptr || frame.latent_first < first->latent_first) first = &frame;
    if (last == nullptr || frame.latent_first > last->latent_first) last = &frame;
  }
  if (first == nullptr || first->latent_first == last->latent_first) return;
  // The smaller of two differences of the same sign, else 0: what both frames show in place.
  // Rounded to kSpatialTvOffsetStep: the Ceres problem holds one cost function per distinct
  // offset, and 16-bit frames would otherwise give one per pixel.
  const auto minmod = [](double a, double b) {
    double shared = 0.0;
    if (a > 0.0 && b > 0.0) shared = std::min(a, b);
    if (a < 0.0 && b < 0.0) shared = std::max(a, b);
    return std::round(shared / kSpatialTvOffsetStep) * kSpatialTvOffsetStep;
  };
  const double* f = first->image.data();
  const double* l = last->image.data();
  const int64_t pixels = static_cast<int64_t>(height_) * width_;
  tv_offset_right_.assign(pixels, 0.0);
  tv_offset_below_.assign(pixels, 0.0);
  // Whether the frames share structure at all: the correlation of their differences over the
  // image. Where it is not positive their differences agree in sign by chance only.
  double cross = 0.0, first_energy = 0.0, last_energy = 0.0;
  const auto difference = [&](int64_t p, int64_t q, double* offset) {
    const double a = f[q] - f[p], b = l[q] - l[p];
    cross += a * b;
    first_energy += a * a;
    last_energy += b * b;
    *offset = minmod(a, b);
  };
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      const int64_t p = static_cast<int64_t>(y) * width_ + x;
      if (x + 1 < width_) difference(p, p + 1, &tv_offset_right_[p]);
      if (y + 1 < height_) difference(p, p + width_, &tv_offset_below_[p]);
    }
  }
  const double energy = std::sqrt(first_energy * last_energy);
  shared_structure_correlation_ = energy > 0.0 ? cross / energy : 0.0;
  if (!(shared_structure_correlation_ > 0.0)) {
    tv_offset_right_.clear();
    tv_offset_below_.clear();
  }
}

SpatialTvTermsAt ObjectiveTerms::spatial_tv_terms_at(int64_t p) const {
  SpatialTvTermsAt terms;
  if (!has(TermFamily::kSpatialTv)) return terms;
  const int y = static_cast<int>(p / width_), x = static_cast<int>(p % width_);
  const bool has_right = x + 1 < width_, has_below = y + 1 < height_;
  const bool here = mask_.active(p);
  const bool right = has_right && mask_.active(p + 1);
  const bool below = has_below && mask_.active(p + width_);
  if (spatial_tv_ == SpatialTv::kAnisotropic) {
    terms.right = has_right && (here || right);
    terms.below = has_below && (here || below);
  } else {
    terms.right = has_right && has_below && (here || right || below);
  }
  return terms;
}

}  // namespace evfs
