#include "solver/problem_builder.h"

#include <algorithm>
#include <functional>
#include <tuple>

#include "core/error.h"
#include "solver/activity_mask.h"
#include "cost_functions/difference_residual.h"
#include "cost_functions/event_residual.h"
#include "cost_functions/frame_residual.h"
#include "cost_functions/spatial_tv_residual.h"
#include "cost_functions/weighted_l1_loss.h"

namespace evfs {
namespace {

// Cost functions depend only on (family, observed value, span length), and observations take
// few distinct values (events are {-1, 0, 1} or small counts, frames 8- or 16-bit levels), so one
// cost function per key serves every residual block that shares it.
class CostFunctionCache {
 public:
  enum class Family { kFrame, kEvent, kSpatialTv, kTemporalTv };

  explicit CostFunctionCache(std::vector<std::unique_ptr<ceres::CostFunction>>* owned)
      : owned_(owned) {}

  ceres::CostFunction* Get(Family family, double value, int span,
                           const std::function<ceres::CostFunction*()>& create) {
    const Key key(family, value, span);
    const auto it = cache_.find(key);
    if (it != cache_.end()) return it->second;
    owned_->emplace_back(create());
    cache_.emplace(key, owned_->back().get());
    return owned_->back().get();
  }

 private:
  using Key = std::tuple<Family, double, int>;
  std::vector<std::unique_ptr<ceres::CostFunction>>* owned_;
  std::map<Key, ceres::CostFunction*> cache_;
};

}  // namespace

ProblemBuilder::ProblemBuilder(const Scene& scene, const ReconstructionOptions& options)
    : scene_(scene), options_(options) {}

std::unique_ptr<BuiltProblem> ProblemBuilder::Build(Video* latent) const {
  const int num_latent = scene_.num_latent_frames();
  const int height = scene_.height, width = scene_.width;
  if (latent->num_frames() != num_latent || latent->height() != height ||
      latent->width() != width) {
    throw InvalidArgumentError("the latent video does not match the scene's size");
  }
  const ObjectiveOptions& objective = options_.objective;
  const int64_t pixels = latent->pixels_per_frame();

  auto built = std::make_unique<BuiltProblem>();
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  // The builder only adds blocks, never removes them, and passes well-formed blocks:
  // skipping Ceres' bookkeeping for removal and its checks halves construction time.
  problem_options.enable_fast_removal = false;
  problem_options.disable_all_safety_checks = true;
  built->problem_ = std::make_unique<ceres::Problem>(problem_options);
  ceres::Problem& problem = *built->problem_;
  ProblemStatistics& statistics = built->statistics_;
  CostFunctionCache cache(&built->cost_functions_);

  const ActivityMask mask(scene_.events, options_.activity_radius_px);
  for (int64_t p = 0; p < pixels; ++p) {
    if (!mask.in_problem(p)) continue;
    for (int t = 0; t < num_latent; ++t) {
      double* voxel = latent->frame_data(t) + p;
      problem.AddParameterBlock(voxel, 1);
      if (!mask.active(p)) {
        problem.SetParameterBlockConstant(voxel);
      } else if (options_.bound_intensities) {
        problem.SetParameterLowerBound(voxel, 0, 0.0);
        problem.SetParameterUpperBound(voxel, 0, 1.0);
      }
      ++statistics.parameter_blocks;
    }
  }
  statistics.active_pixels = mask.num_active();
  statistics.skipped_pixels = pixels - mask.num_active();

  // Each family's loss is weight / (h·w) times the smoothed |r| (ObjectiveOptions).
  const auto make_loss = [&](double weight) {
    built->losses_.emplace_back(
        CreateWeightedL1Loss(weight / static_cast<double>(pixels), objective.smoothing_scale));
    return built->losses_.back().get();
  };
  const auto voxel = [&](int t, int64_t p) { return latent->frame_data(t) + p; };
  using Family = CostFunctionCache::Family;

  if (objective.frame_weight > 0.0) {
    ceres::LossFunction* loss = make_loss(objective.frame_weight);
    std::vector<double*> blocks;
    for (const FrameObservation& frame : scene_.frames) {
      const int span = frame.latent_last - frame.latent_first + 1;
      blocks.resize(span);
      for (int64_t p = 0; p < pixels; ++p) {
        if (!mask.active(p)) continue;
        const double value = frame.image.data()[p];
        ceres::CostFunction* cost = cache.Get(Family::kFrame, value, span, [&] {
          return FrameResidual::Create(value, span);
        });
        for (int i = 0; i < span; ++i) blocks[i] = voxel(frame.latent_first + i, p);
        problem.AddResidualBlock(cost, loss, blocks);
        ++statistics.frame_residuals;
      }
    }
  }

  if (objective.event_weight > 0.0) {
    ceres::LossFunction* loss = make_loss(objective.event_weight);
    std::vector<double*> blocks;
    for (int k = 0; k < scene_.events.num_frames(); ++k) {
      const EventFrameSpan& span = scene_.events.span(k);
      const int steps = span.latent_last - span.latent_first;
      const float* values = scene_.events.frame_data(k);
      blocks.resize(steps + 1);
      for (int64_t p = 0; p < pixels; ++p) {
        if (!mask.active(p)) continue;
        const double value = values[p];
        ceres::CostFunction* cost = cache.Get(Family::kEvent, value, steps, [&] {
          return EventResidual::Create(value, steps, objective.event_model);
        });
        if (steps == 1) {
          problem.AddResidualBlock(cost, loss, voxel(span.latent_first, p),
                                   voxel(span.latent_last, p));
        } else {
          for (int i = 0; i <= steps; ++i) blocks[i] = voxel(span.latent_first + i, p);
          problem.AddResidualBlock(cost, loss, blocks);
        }
        ++statistics.event_residuals;
      }
    }
  }

  if (objective.spatial_tv_weight > 0.0) {
    // A mean over latent frames: summed, smoothing a run of m frames would save m times the
    // TV while paying for only two temporal transitions, so finer binning would blur more.
    ceres::LossFunction* loss = make_loss(objective.spatial_tv_weight / num_latent);
    // Anisotropic TV is two difference residuals; the other forms one three-point residual.
    const bool anisotropic = objective.spatial_tv == SpatialTv::kAnisotropic;
    ceres::CostFunction* spatial_cost = cache.Get(Family::kSpatialTv, 0.0, 0, [&] {
      if (anisotropic) return DifferenceResidual::Create();
      return objective.spatial_tv == SpatialTv::kIsotropic ? IsotropicTvResidual::Create()
                                                           : PaperTvResidual::Create();
    });
    for (int t = 0; t < num_latent; ++t) {
      for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
          const int64_t p = static_cast<int64_t>(y) * width + x;
          // A term is built when any pixel it touches is active; the others are then ring
          // pixels, held constant.
          const bool has_right = x + 1 < width, has_below = y + 1 < height;
          const bool here = mask.active(p);
          const bool right = has_right && mask.active(p + 1);
          const bool below = has_below && mask.active(p + width);
          if (anisotropic) {
            if (has_right && (here || right)) {
              problem.AddResidualBlock(spatial_cost, loss, voxel(t, p), voxel(t, p + 1));
              ++statistics.spatial_tv_residuals;
            }
            if (has_below && (here || below)) {
              problem.AddResidualBlock(spatial_cost, loss, voxel(t, p), voxel(t, p + width));
              ++statistics.spatial_tv_residuals;
            }
          } else if (has_right && has_below && (here || right || below)) {
            problem.AddResidualBlock(spatial_cost, loss, voxel(t, p), voxel(t, p + 1),
                                     voxel(t, p + width));
            ++statistics.spatial_tv_residuals;
          }
        }
      }
    }
  }

  if (objective.temporal_tv_weight > 0.0 && num_latent > 1) {
    ceres::LossFunction* loss = make_loss(objective.temporal_tv_weight);
    ceres::CostFunction* difference =
        cache.Get(Family::kTemporalTv, 0.0, 0, [] { return DifferenceResidual::Create(); });
    for (int t = 0; t + 1 < num_latent; ++t) {
      for (int64_t p = 0; p < pixels; ++p) {
        if (!mask.active(p)) continue;
        problem.AddResidualBlock(difference, loss, voxel(t, p), voxel(t + 1, p));
        ++statistics.temporal_tv_residuals;
      }
    }
  }
  statistics.distinct_cost_functions = static_cast<int64_t>(built->cost_functions_.size());
  return built;
}

Video InitializeLatentVideo(const Scene& scene) {
  const std::vector<int64_t>& latent_ns = scene.latent_timestamps_ns();
  // Each observation sits at the centre of its exposure on the latent timeline.
  Video anchors;
  std::vector<const FrameObservation*> sorted;
  for (const FrameObservation& frame : scene.frames) sorted.push_back(&frame);
  std::stable_sort(sorted.begin(), sorted.end(), [&](const auto* a, const auto* b) {
    return a->latent_first + a->latent_last < b->latent_first + b->latent_last;
  });
  for (const FrameObservation* frame : sorted) {
    const int64_t centre_ns = (latent_ns[frame->latent_first] + latent_ns[frame->latent_last]) / 2;
    if (!anchors.empty() && anchors.timestamp_ns(anchors.num_frames() - 1) == centre_ns) continue;
    anchors.AppendFrame(frame->image, centre_ns);
  }
  Video latent(scene.height, scene.width, static_cast<int>(latent_ns.size()));
  for (int t = 0; t < latent.num_frames(); ++t) {
    latent.set_timestamp_ns(t, latent_ns[t]);
    latent.frame(t) = anchors.InterpolateAt(latent_ns[t]);
  }
  return latent;
}

}  // namespace evfs
