#include "solver/problem_builder.h"

#include <algorithm>
#include <functional>
#include <initializer_list>
#include <tuple>
#include <utility>

#include "core/error.h"
#include "core/parallel.h"
#include "cost_functions/difference_residual.h"
#include "cost_functions/event_residual.h"
#include "cost_functions/frame_residual.h"
#include "cost_functions/prior_residual.h"
#include "cost_functions/spatial_tv_residual.h"
#include "cost_functions/weighted_l1_loss.h"
#include "solver/objective_terms.h"

namespace evfs {
namespace {

// Cost functions depend only on (family, observed value, shape), and observations take few
// distinct values (events are {-1, 0, 1} or small counts, frames 8- or 16-bit levels), so one
// cost function per key serves every residual block that shares it. The shape is the number of
// steps of an event frame, or the run lengths of a frame observation's segments.
class CostFunctionCache {
 public:
  enum class Family { kFrame, kEvent, kSpatialTv, kTemporalTv };

  explicit CostFunctionCache(std::vector<std::unique_ptr<ceres::CostFunction>>* owned)
      : owned_(owned) {}

  ceres::CostFunction* Get(Family family, double value, const std::vector<int>& shape,
                           const std::function<ceres::CostFunction*()>& create) {
    Key key(family, value, shape);
    const auto it = cache_.find(key);
    if (it != cache_.end()) return it->second;
    owned_->emplace_back(create());
    cache_.emplace(std::move(key), owned_->back().get());
    return owned_->back().get();
  }

 private:
  using Key = std::tuple<Family, double, std::vector<int>>;
  std::vector<std::unique_ptr<ceres::CostFunction>>* owned_;
  std::map<Key, ceres::CostFunction*> cache_;
};

// One loss per term family and multiplicity: a residual standing for m identical terms (a spatial
// TV pair that keeps its segments over m latent frames) is weighted m times.
class LossCache {
 public:
  LossCache(std::vector<std::unique_ptr<ceres::LossFunction>>* owned, double smoothing_scale)
      : owned_(owned), smoothing_scale_(smoothing_scale) {}

  ceres::LossFunction* Get(double weight, int multiplicity) {
    const std::pair<double, int> key(weight, multiplicity);
    const auto it = cache_.find(key);
    if (it != cache_.end()) return it->second;
    owned_->emplace_back(CreateWeightedL1Loss(weight * multiplicity, smoothing_scale_));
    cache_.emplace(key, owned_->back().get());
    return owned_->back().get();
  }

 private:
  std::vector<std::unique_ptr<ceres::LossFunction>>* owned_;
  const double smoothing_scale_;
  std::map<std::pair<double, int>, ceres::LossFunction*> cache_;
};

}  // namespace

ProblemStatistics& ProblemStatistics::operator+=(const ProblemStatistics& part) {
  parameter_blocks += part.parameter_blocks;
  variable_parameter_blocks += part.variable_parameter_blocks;
  frame_residuals += part.frame_residuals;
  event_residuals += part.event_residuals;
  spatial_tv_residuals += part.spatial_tv_residuals;
  temporal_tv_residuals += part.temporal_tv_residuals;
  prior_residuals += part.prior_residuals;
  distinct_cost_functions += part.distinct_cost_functions;
  active_pixels += part.active_pixels;
  skipped_pixels += part.skipped_pixels;
  parts += part.parts;
  return *this;
}

// What every part of a scene shares: which pixels are solved for, how their time series are
// cut into segments, and which terms the objective has. The mask is on the heap: `terms`
// refers to it.
struct ProblemBuilder::Prepared {
  std::shared_ptr<const ActivityMask> mask;
  std::shared_ptr<const LatentLayout> layout;
  std::shared_ptr<const ObjectiveTerms> terms;
};

ProblemBuilder::ProblemBuilder(const Scene& scene, const ReconstructionOptions& options)
    : scene_(scene), options_(options) {}

ProblemBuilder::Prepared ProblemBuilder::Prepare(Video* latent) const {
  if (latent->num_frames() != scene_.num_latent_frames() || latent->height() != scene_.height ||
      latent->width() != scene_.width) {
    throw InvalidArgumentError("the latent video does not match the scene's size");
  }
  Prepared prepared;
  prepared.mask = std::make_shared<ActivityMask>(scene_.events, options_.activity_radius_px);
  auto layout =
      std::make_shared<LatentLayout>(scene_, *prepared.mask, *latent, options_.merge_quiet_steps);
  layout->ProjectOnto(latent);
  prepared.layout = std::move(layout);
  prepared.terms = std::make_shared<ObjectiveTerms>(scene_, options_.objective, *prepared.mask);
  return prepared;
}

std::unique_ptr<BuiltProblem> ProblemBuilder::Build(Video* latent) const {
  const Prepared prepared = Prepare(latent);
  std::vector<int64_t> pixels;
  for (int64_t p = 0; p < prepared.mask->num_pixels(); ++p) {
    if (prepared.mask->in_problem(p)) pixels.push_back(p);
  }
  std::unique_ptr<BuiltProblem> built = BuildPart(prepared, pixels, latent);
  built->statistics_.skipped_pixels = prepared.mask->num_pixels() - prepared.mask->num_active();
  return built;
}

std::vector<std::unique_ptr<BuiltProblem>> ProblemBuilder::BuildParts(Video* latent,
                                                                      int build_workers) const {
  const Prepared prepared = Prepare(latent);
  const std::vector<std::vector<int64_t>> parts =
      prepared.mask->IndependentParts(options_.min_part_pixels);
  std::vector<std::unique_ptr<BuiltProblem>> built(parts.size());
  ParallelForEach(static_cast<int>(parts.size()), build_workers,
                  [&](int i) { built[i] = BuildPart(prepared, parts[i], latent); });
  return built;
}

std::unique_ptr<BuiltProblem> ProblemBuilder::BuildPart(const Prepared& prepared,
                                                        const std::vector<int64_t>& pixels,
                                                        Video* latent) const {
  const ObjectiveOptions& objective = options_.objective;
  const ActivityMask& mask = *prepared.mask;
  const LatentLayout& layout = *prepared.layout;
  const ObjectiveTerms& terms = *prepared.terms;
  const int num_latent = scene_.num_latent_frames();
  const int width = scene_.width;

  auto built = std::make_unique<BuiltProblem>();
  built->layout_ = prepared.layout;
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
  LossCache losses(&built->losses_, objective.smoothing_scale);

  // The segments of pixel p are consecutive in the layout, from its first frame's.
  const auto for_each_segment = [&](int64_t p, const auto& visit) {
    for (int64_t s = layout.segment_at(0, p);
         s < layout.num_segments() && layout.segment(s).pixel == p; ++s) {
      visit(s);
    }
  };
  for (const int64_t p : pixels) {
    statistics.active_pixels += mask.active(p);
    for_each_segment(p, [&](int64_t s) {
      double* value = layout.value(s, latent);
      problem.AddParameterBlock(value, 1);
      ++statistics.parameter_blocks;
      if (layout.segment(s).constant) {
        problem.SetParameterBlockConstant(value);
        return;
      }
      ++statistics.variable_parameter_blocks;
      if (options_.bound_intensities) {
        problem.SetParameterLowerBound(value, 0, 0.0);
        problem.SetParameterUpperBound(value, 0, 1.0);
      }
    });
  }

  // Each family's loss is its normalised weight (ObjectiveTerms) times the smoothed |r|.
  const auto block = [&](int t, int64_t p) {
    return layout.value(layout.segment_at(t, p), latent);
  };
  using Family = CostFunctionCache::Family;
  std::vector<double*> blocks;
  std::vector<int> shape;

  if (terms.has(TermFamily::kFrame)) {
    ceres::LossFunction* loss = losses.Get(terms.weight(TermFamily::kFrame), 1);
    for (const FrameObservation& frame : scene_.frames) {
      for (const int64_t p : pixels) {
        if (!mask.active(p)) continue;
        // The exposure's voxels, one block per run of a segment.
        blocks.clear();
        shape.clear();
        for (int t = frame.latent_first; t <= frame.latent_last; ++t) {
          const int64_t s = layout.segment_at(t, p);
          if (!blocks.empty() && layout.value(s, latent) == blocks.back()) {
            ++shape.back();
          } else {
            blocks.push_back(layout.value(s, latent));
            shape.push_back(1);
          }
        }
        const double value = frame.image.data()[p];
        ceres::CostFunction* cost = cache.Get(Family::kFrame, value, shape,
                                              [&] { return FrameResidual::Create(value, shape); });
        problem.AddResidualBlock(cost, loss, blocks);
        ++statistics.frame_residuals;
      }
    }
  }

  if (terms.has(TermFamily::kEvent)) {
    ceres::LossFunction* loss = losses.Get(terms.weight(TermFamily::kEvent), 1);
    for (int k = 0; k < scene_.events.num_frames(); ++k) {
      const EventFrameSpan& span = scene_.events.span(k);
      const int steps = span.latent_last - span.latent_first;
      const float* values = scene_.events.frame_data(k);
      for (const int64_t p : pixels) {
        if (!mask.active(p)) continue;
        // Over merged steps H does not change and the model predicts 0: a step contributes
        // only where a segment starts. The layout starts one at every step of a frame that
        // fired, so a frame is either all new segments or (quiet, value 0) none, residual 0.
        int new_segments = 0;
        for (int t = span.latent_first + 1; t <= span.latent_last; ++t) {
          new_segments += layout.segment_at(t, p) != layout.segment_at(t - 1, p);
        }
        if (new_segments == 0) continue;
        CHECK_EQ(new_segments, steps) << "an event frame's span is partly merged";
        const double value = values[p];
        ceres::CostFunction* cost = cache.Get(Family::kEvent, value, {steps}, [&] {
          return EventResidual::Create(value, steps, objective.event_model);
        });
        if (steps == 1) {
          problem.AddResidualBlock(cost, loss, block(span.latent_first, p),
                                   block(span.latent_last, p));
        } else {
          blocks.resize(steps + 1);
          for (int i = 0; i <= steps; ++i) blocks[i] = block(span.latent_first + i, p);
          problem.AddResidualBlock(cost, loss, blocks);
        }
        ++statistics.event_residuals;
      }
    }
  }

  if (terms.has(TermFamily::kSpatialTv)) {
    const double weight = terms.weight(TermFamily::kSpatialTv);
    // Anisotropic TV is two difference residuals; the other forms one three-point residual.
    const bool anisotropic = objective.spatial_tv == SpatialTv::kAnisotropic;
    ceres::CostFunction* spatial_cost = cache.Get(Family::kSpatialTv, 0.0, {}, [&] {
      if (anisotropic) return DifferenceResidual::Create();
      return objective.spatial_tv == SpatialTv::kIsotropic ? IsotropicTvResidual::Create()
                                                           : PaperTvResidual::Create();
    });
    // One residual per run of latent frames over which the pixels it touches keep their
    // segments: the run's m identical terms, weighted m times.
    const auto add_runs = [&](std::initializer_list<int64_t> touched) {
      int run_first = 0;
      for (int t = 1; t <= num_latent; ++t) {
        bool same = t < num_latent;
        for (const int64_t q : touched) {
          same = same && layout.segment_at(t, q) == layout.segment_at(t - 1, q);
        }
        if (same) continue;
        blocks.clear();
        for (const int64_t q : touched) blocks.push_back(block(run_first, q));
        problem.AddResidualBlock(spatial_cost, losses.Get(weight, t - run_first), blocks);
        ++statistics.spatial_tv_residuals;
        run_first = t;
      }
    };
    // A term touches an active pixel (ObjectiveTerms), so the others it touches are in the
    // problem (within one pixel of an active one) and in the same part; it is built by the part
    // of its top-left pixel.
    for (const int64_t p : pixels) {
      const SpatialTvTermsAt owned = terms.spatial_tv_terms_at(p);
      if (anisotropic) {
        if (owned.right) add_runs({p, p + 1});
        if (owned.below) add_runs({p, p + width});
      } else if (owned.right) {
        add_runs({p, p + 1, p + width});
      }
    }
  }

  if (terms.has(TermFamily::kTemporalTv)) {
    // Σ_t |H_{t+1}(p) - H_t(p)| is the sum over the pixel's segment boundaries.
    ceres::LossFunction* loss = losses.Get(terms.weight(TermFamily::kTemporalTv), 1);
    ceres::CostFunction* difference =
        cache.Get(Family::kTemporalTv, 0.0, {}, [] { return DifferenceResidual::Create(); });
    for (const int64_t p : pixels) {
      for_each_segment(p, [&](int64_t s) {
        if (layout.segment(s).constant || s + 1 >= layout.num_segments() ||
            layout.segment(s + 1).pixel != p) {
          return;
        }
        problem.AddResidualBlock(difference, loss, layout.value(s, latent),
                                 layout.value(s + 1, latent));
        ++statistics.temporal_tv_residuals;
      });
    }
  }
  if (terms.has(TermFamily::kPrior)) {
    // One squared residual per unknown, towards the mean of its voxels' targets: its cost
    // differs from the sum over the voxels by a constant (cost_functions/prior_residual.h).
    // Targets are continuous, so each residual has its own cost function.
    const double weight = terms.weight(TermFamily::kPrior);
    const Video& target = *objective.prior_target;
    for (const int64_t p : pixels) {
      if (!mask.active(p)) continue;
      for_each_segment(p, [&](int64_t s) {
        const LatentLayout::Segment& segment = layout.segment(s);
        if (segment.constant) return;
        double sum = 0.0;
        for (int t = segment.first; t <= segment.last; ++t) sum += target.frame_data(t)[p];
        const int length = segment.length();
        built->cost_functions_.emplace_back(PriorResidual::Create(sum / length, weight * length));
        problem.AddResidualBlock(built->cost_functions_.back().get(), nullptr,
                                 layout.value(s, latent));
        ++statistics.prior_residuals;
      });
    }
  }
  statistics.distinct_cost_functions = static_cast<int64_t>(built->cost_functions_.size());
  return built;
}

}  // namespace evfs
