#include "evfs/solver/problem_builder.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <unordered_map>
#include <utility>

#include "evfs/core/error.h"
#include "evfs/core/parallel.h"
#include "evfs/cost_functions/difference_residual.h"
#include "evfs/cost_functions/event_residual.h"
#include "evfs/cost_functions/frame_residual.h"
#include "evfs/cost_functions/prior_residual.h"
#include "evfs/cost_functions/spatial_tv_residual.h"
#include "evfs/cost_functions/weighted_l1_loss.h"
#include "evfs/solver/objective_terms.h"

namespace evfs {
namespace {

// Cost functions depend only on (family, observed value, shape), and observations take few
// distinct values (events are {-1, 0, 1} or small counts, frames 8- or 16-bit levels, spatial TV
// offsets multiples of kSpatialTvOffsetStep), so one cost function per key serves every residual
// block that shares it. The shape is the number of steps of an event frame, or the run lengths
// of a frame observation's segments.
class CostFunctionCache {
 public:
  enum class Family { kFrame, kEvent, kSpatialTv, kTemporalTv };

  explicit CostFunctionCache(std::vector<std::unique_ptr<ceres::CostFunction>>* owned)
      : owned_(owned) {}

  // The cost function of (family, value, shape), made by create() the first time it is asked
  // for. A lookup allocates nothing: a problem asks once per residual block.
  template <typename Create>
  ceres::CostFunction* Get(Family family, double value, const std::vector<int>& shape,
                           const Create& create) {
    return Find(family, value, 0.0, shape.data(), shape.size(), create);
  }
  // An event frame's: its value and number of steps.
  template <typename Create>
  ceres::CostFunction* GetSteps(Family family, double value, int steps, const Create& create) {
    return Find(family, value, 0.0, &steps, 1, create);
  }
  // A key of two values and no shape: the offsets of a spatial TV term.
  template <typename Create>
  ceres::CostFunction* GetPair(Family family, double value, double second_value,
                               const Create& create) {
    return Find(family, value, second_value, nullptr, 0, create);
  }

 private:
  struct Entry {
    Family family;
    double value;
    double second_value;
    std::vector<int> shape;
    ceres::CostFunction* cost;
  };

  template <typename Create>
  ceres::CostFunction* Find(Family family, double value, double second_value, const int* shape,
                            size_t shape_size, const Create& create) {
    // -0.0 and 0.0 compare equal, so they are one key: both hash as 0.0.
    value += 0.0;
    second_value += 0.0;
    const uint64_t hash = Hash(family, value, second_value, shape, shape_size);
    const auto [begin, end] = cache_.equal_range(hash);
    for (auto it = begin; it != end; ++it) {
      const Entry& entry = it->second;
      if (entry.family == family && entry.value == value && entry.second_value == second_value &&
          entry.shape.size() == shape_size &&
          std::equal(shape, shape + shape_size, entry.shape.begin())) {
        return entry.cost;
      }
    }
    owned_->emplace_back(create());
    cache_.emplace(hash, Entry{family, value, second_value,
                               std::vector<int>(shape, shape + shape_size), owned_->back().get()});
    return owned_->back().get();
  }

  static uint64_t Hash(Family family, double value, double second_value, const int* shape,
                       size_t shape_size) {
    // FNV-1a over the key's words.
    uint64_t hash = 14695981039346656037ull;
    const auto mix = [&hash](uint64_t word) {
      hash ^= word;
      hash *= 1099511628211ull;
    };
    uint64_t bits = 0;
    mix(static_cast<uint64_t>(family));
    std::memcpy(&bits, &value, sizeof(bits));
    mix(bits);
    std::memcpy(&bits, &second_value, sizeof(bits));
    mix(bits);
    for (size_t i = 0; i < shape_size; ++i) mix(static_cast<uint64_t>(shape[i]));
    return hash;
  }

  std::vector<std::unique_ptr<ceres::CostFunction>>* owned_;
  std::unordered_multimap<uint64_t, Entry> cache_;
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
  log_temporal_tv_pixels += part.log_temporal_tv_pixels;
  prior_residuals += part.prior_residuals;
  distinct_cost_functions += part.distinct_cost_functions;
  active_pixels += part.active_pixels;
  skipped_pixels += part.skipped_pixels;
  parts += part.parts;
  shared_structure_correlation = part.shared_structure_correlation;
  shared_structure_applied = part.shared_structure_applied;
  return *this;
}

ProblemBuilder::ProblemBuilder(const Scene& scene, const ReconstructionOptions& options)
    : scene_(scene), options_(options) {}

ProblemPlan ProblemBuilder::Prepare(Video* latent) const {
  if (latent->num_frames() != scene_.num_latent_frames() || latent->height() != scene_.height ||
      latent->width() != scene_.width) {
    throw InvalidArgumentError("the latent video does not match the scene's size");
  }
  ProblemPlan prepared;
  prepared.mask_ = std::make_shared<ActivityMask>(scene_.events, options_.activity_radius_px);
  auto layout =
      std::make_shared<LatentLayout>(scene_, *prepared.mask_, *latent, options_.merge_quiet_steps,
                                     options_.unfired_pixel_changes, options_.ring_tolerance);
  layout->ProjectOnto(latent);
  prepared.layout_ = std::move(layout);
  prepared.terms_ = std::make_shared<ObjectiveTerms>(scene_, options_.objective, *prepared.mask_);
  return prepared;
}

std::unique_ptr<BuiltProblem> ProblemBuilder::Build(Video* latent) const {
  const ProblemPlan prepared = Prepare(latent);
  ProblemUnit unit;
  for (int64_t p = 0; p < prepared.mask_->num_pixels(); ++p) {
    if (prepared.mask_->in_problem(p)) unit.pixels.push_back(p);
  }
  std::unique_ptr<BuiltProblem> built = BuildUnit(prepared, unit, latent);
  built->statistics_.skipped_pixels = prepared.mask_->num_pixels() - prepared.mask_->num_active();
  return built;
}

std::vector<std::unique_ptr<BuiltProblem>> ProblemBuilder::BuildParts(Video* latent,
                                                                      int build_workers) const {
  const ProblemPlan prepared = Prepare(latent);
  std::vector<ProblemUnit> parts;
  for (std::vector<int64_t>& pixels : prepared.mask_->IndependentParts(options_.min_part_pixels)) {
    parts.emplace_back().pixels = std::move(pixels);
  }
  std::vector<std::unique_ptr<BuiltProblem>> built(parts.size());
  ParallelForEach(static_cast<int>(parts.size()), build_workers,
                  [&](int i) { built[i] = BuildUnit(prepared, parts[i], latent); });
  return built;
}

int64_t ProblemBuilder::EstimatedBytes(const ProblemPlan& prepared, int64_t p) const {
  // A problem holds about 300 bytes per parameter block and 330 per residual block
  // (ceres::Problem, its Program, the Jacobian and the CGNR workspace), fitted to the peak
  // memory of solves from 1.4 M to 2.2 M parameter blocks (BENCHMARKS.md, "Memory bounded
  // before allocation"). A pixel with s segments has up to s event and temporal TV residuals
  // and about 3s spatial TV runs with its neighbours; an active one has a residual per frame.
  constexpr int64_t kBytesPerParameterBlock = 300;
  constexpr int64_t kBytesPerResidualBlock = 330;
  const LatentLayout& layout = *prepared.layout_;
  int64_t segments = 0;
  for (int64_t s = layout.segment_at(0, p);
       s >= 0 && s < layout.num_segments() && layout.segment(s).pixel == p; ++s) {
    ++segments;
  }
  const int64_t frames = prepared.mask_->active(p) ? static_cast<int64_t>(scene_.frames.size()) : 0;
  return kBytesPerParameterBlock * segments + kBytesPerResidualBlock * (frames + 5 * segments);
}

std::vector<ProblemUnit> ProblemBuilder::Bands(const ProblemPlan& prepared,
                                               const std::vector<int64_t>& part,
                                               int64_t max_bytes) const {
  // Bands are solved top to bottom, each with the row above it held at the band before's
  // answer and the row below at the initialisation. A band solves this many rows beyond its
  // own below it, where that initial boundary pulls, and the next band solves them again with
  // the band before's answer above. Measured in BENCHMARKS.md ("Memory bounded before
  // allocation").
  constexpr int kMarginRows = 8;
  const int64_t width = scene_.width;
  const int first_row = static_cast<int>(part.front() / width);
  const int last_row = static_cast<int>(part.back() / width);
  // bytes_before[r - first_row]: the estimate of the part's pixels in rows first_row .. r - 1.
  std::vector<int64_t> bytes_before(last_row - first_row + 2, 0);
  for (const int64_t p : part) {
    bytes_before[p / width - first_row + 1] += EstimatedBytes(prepared, p);
  }
  for (size_t r = 1; r < bytes_before.size(); ++r) bytes_before[r] += bytes_before[r - 1];
  const auto rows_bytes = [&](int begin, int end) {  // rows [begin, end), clamped to the part
    begin = std::max(begin, first_row);
    end = std::min(end, last_row + 1);
    return bytes_before[end - first_row] - bytes_before[begin - first_row];
  };
  const auto pixels_of_rows = [&](int begin, int end) {  // the part's pixels in rows [begin, end)
    const auto from = std::lower_bound(part.begin(), part.end(), int64_t{begin} * width);
    const auto to = std::lower_bound(part.begin(), part.end(), int64_t{end} * width);
    return std::vector<int64_t>(from, to);
  };
  std::vector<ProblemUnit> bands;
  for (int core_begin = first_row; core_begin <= last_row;) {
    int core_end = core_begin + 1;  // at least one row, whatever the budget
    while (core_end <= last_row &&
           rows_bytes(core_begin, core_end + 1 + kMarginRows) <= max_bytes) {
      ++core_end;
    }
    ProblemUnit& band = bands.emplace_back();
    band.band = true;
    band.row_begin = core_begin;
    band.row_end = std::min(last_row + 1, core_end + kMarginRows);
    band.estimated_bytes = rows_bytes(band.row_begin, band.row_end);
    // The rows next to the band, held constant, come with it.
    band.pixels = pixels_of_rows(band.row_begin - 1, band.row_end + 1);
    core_begin = core_end;
  }
  return bands;
}

ProblemPlan ProblemBuilder::Plan(Video* latent, int64_t max_bytes) const {
  ProblemPlan plan = Prepare(latent);
  const ActivityMask& mask = *plan.mask_;
  std::vector<ProblemUnit> units;
  if (options_.split_independent_parts) {
    for (std::vector<int64_t>& pixels : mask.IndependentParts(options_.min_part_pixels)) {
      units.emplace_back().pixels = std::move(pixels);
    }
  } else {
    ProblemUnit& whole = units.emplace_back();
    for (int64_t p = 0; p < mask.num_pixels(); ++p) {
      if (mask.in_problem(p)) whole.pixels.push_back(p);
    }
    if (whole.pixels.empty()) units.clear();
  }
  for (ProblemUnit& unit : units) {
    for (const int64_t p : unit.pixels) unit.estimated_bytes += EstimatedBytes(plan, p);
    plan.estimated_bytes_ += unit.estimated_bytes;
  }
  if (max_bytes < 0 || plan.estimated_bytes_ <= max_bytes) {
    plan.batches_.push_back(std::move(units));
    return plan;
  }
  // Parts come largest first: those too large alone become bands, the others fill batches.
  int64_t batch_bytes = 0;
  bool packing = false;  // the last batch takes more parts
  for (ProblemUnit& unit : units) {
    if (unit.estimated_bytes > max_bytes) {
      for (ProblemUnit& band : Bands(plan, unit.pixels, max_bytes)) {
        plan.batches_.push_back({std::move(band)});
      }
      packing = false;
      continue;
    }
    if (!packing || batch_bytes + unit.estimated_bytes > max_bytes) {
      plan.batches_.emplace_back();
      batch_bytes = 0;
      packing = true;
    }
    batch_bytes += unit.estimated_bytes;
    plan.batches_.back().push_back(std::move(unit));
  }
  return plan;
}

std::unique_ptr<BuiltProblem> ProblemBuilder::BuildUnit(const ProblemPlan& prepared,
                                                        const ProblemUnit& unit,
                                                        Video* latent) const {
  const ObjectiveOptions& objective = options_.objective;
  const ActivityMask& mask = *prepared.mask_;
  const LatentLayout& layout = *prepared.layout_;
  const ObjectiveTerms& terms = *prepared.terms_;
  const std::vector<int64_t>& pixels = unit.pixels;
  const int num_latent = scene_.num_latent_frames();
  const int width = scene_.width;

  // A band solves its own rows; the rows next to it are held constant.
  const auto inside = [&](int64_t p) {
    const int64_t row = p / width;
    return !unit.band || (row >= unit.row_begin && row < unit.row_end);
  };
  // Terms of the pixels it solves: active ones, inside the unit.
  const auto solved = [&](int64_t p) { return mask.active(p) && inside(p); };

  auto built = std::make_unique<BuiltProblem>();
  built->layout_ = prepared.layout_;
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
  // Each pixel's temporal chain, for Ceres' SUBSET preconditioner only.
  const bool collect_temporal = options_.solver.preconditioner_type == ceres::SUBSET;
  const auto temporal = [&](ceres::ResidualBlockId id) {
    if (collect_temporal) built->temporal_residuals_.insert(id);
  };
  LossCache losses(&built->losses_, objective.smoothing_scale);

  // The segments of pixel p are consecutive in the layout, from its first frame's.
  const auto for_each_segment = [&](int64_t p, const auto& visit) {
    for (int64_t s = layout.segment_at(0, p);
         s < layout.num_segments() && layout.segment(s).pixel == p; ++s) {
      visit(s);
    }
  };
  for (const int64_t p : pixels) {
    statistics.active_pixels += solved(p);
    for_each_segment(p, [&](int64_t s) {
      double* value = layout.value(s, latent);
      problem.AddParameterBlock(value, 1);
      ++statistics.parameter_blocks;
      if (layout.segment(s).constant || !inside(p)) {
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
        if (!solved(p)) continue;
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
        temporal(problem.AddResidualBlock(cost, loss, blocks));
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
        if (!solved(p)) continue;
        // Over merged steps H does not change and the model predicts 0: a step contributes
        // only where a segment starts. The layout starts one at every step of a frame that
        // fired, so a frame is either all new segments or (quiet, value 0) none, residual 0.
        int new_segments = 0;
        for (int t = span.latent_first + 1; t <= span.latent_last; ++t) {
          new_segments += layout.segment_at(t, p) != layout.segment_at(t - 1, p);
        }
        if (new_segments == 0) continue;
        CHECK_EQ(new_segments, steps) << "an event frame's span is partly merged";
        // An unfired pixel's change has no event residual (LatentLayout).
        if (layout.segment(layout.segment_at(span.latent_last, p)).unfired_change) continue;
        const double value = values[p];
        ceres::CostFunction* cost = cache.GetSteps(Family::kEvent, value, steps, [&] {
          return EventResidual::Create(value, steps, objective.event_model);
        });
        if (steps == 1) {
          temporal(problem.AddResidualBlock(cost, loss, block(span.latent_first, p),
                                            block(span.latent_last, p)));
        } else {
          blocks.resize(steps + 1);
          for (int i = 0; i <= steps; ++i) blocks[i] = block(span.latent_first + i, p);
          temporal(problem.AddResidualBlock(cost, loss, blocks));
        }
        ++statistics.event_residuals;
      }
    }
  }

  if (terms.has(TermFamily::kSpatialTv)) {
    const double weight = terms.weight(TermFamily::kSpatialTv);
    // Anisotropic TV is two difference residuals; the other forms one three-point residual.
    // Each is measured from the pixel's offsets (0 for plain TV).
    const bool anisotropic = objective.spatial_tv == SpatialTv::kAnisotropic;
    // A difference's cost from its offset o_x (anisotropic), or a three-point term's from its
    // (o_x, o_y).
    const auto spatial_cost = [&](double offset_x, double offset_y) {
      return cache.GetPair(Family::kSpatialTv, offset_x, offset_y, [&]() -> ceres::CostFunction* {
        if (anisotropic) return DifferenceResidual::Create(offset_x);
        return objective.spatial_tv == SpatialTv::kIsotropic
                   ? IsotropicTvResidual::Create(offset_x, offset_y)
                   : PaperTvResidual::Create(offset_x, offset_y);
      });
    };
    ceres::CostFunction* const plain_cost = spatial_cost(0.0, 0.0);
    const bool offsets = terms.has_spatial_tv_offsets();
    // One residual per run of latent frames over which the pixels it touches keep their
    // segments: the run's m identical terms, weighted m times.
    const auto add_runs = [&](ceres::CostFunction* cost, std::initializer_list<int64_t> touched) {
      int run_first = 0;
      for (int t = 1; t <= num_latent; ++t) {
        bool same = t < num_latent;
        for (const int64_t q : touched) {
          same = same && layout.segment_at(t, q) == layout.segment_at(t - 1, q);
        }
        if (same) continue;
        blocks.clear();
        for (const int64_t q : touched) blocks.push_back(block(run_first, q));
        problem.AddResidualBlock(cost, losses.Get(weight, t - run_first), blocks);
        ++statistics.spatial_tv_residuals;
        run_first = t;
      }
    };
    // A term touches an active pixel (ObjectiveTerms), so the others it touches are in the
    // problem (within one pixel of an active one) and in the same part; it is built by the part
    // of its top-left pixel.
    // A band builds only the terms that touch its own rows.
    for (const int64_t p : pixels) {
      const SpatialTvTermsAt owned = terms.spatial_tv_terms_at(p);
      const SpatialTvOffset offset = terms.spatial_tv_offset_at(p);
      const bool here = inside(p), below = inside(p + width);
      if (anisotropic) {
        if (owned.right && here) {
          add_runs(offsets ? spatial_cost(offset.right, 0.0) : plain_cost, {p, p + 1});
        }
        if (owned.below && (here || below)) {
          add_runs(offsets ? spatial_cost(offset.below, 0.0) : plain_cost, {p, p + width});
        }
      } else if (owned.right && (here || below)) {
        add_runs(offsets ? spatial_cost(offset.right, offset.below) : plain_cost,
                 {p, p + 1, p + width});
      }
    }
  }

  if (terms.has(TermFamily::kTemporalTv)) {
    // Σ_t |H_{t+1}(p) - H_t(p)| is the sum over the pixel's segment boundaries.
    ceres::LossFunction* loss = losses.Get(terms.weight(TermFamily::kTemporalTv), 1);
    ceres::CostFunction* linear =
        cache.GetPair(Family::kTemporalTv, 0.0, 0.0, [] { return DifferenceResidual::Create(); });
    for (const int64_t p : pixels) {
      if (!inside(p)) continue;
      ceres::CostFunction* difference = linear;
      if (terms.temporal_tv_in_g_at(p)) {
        difference = cache.GetPair(Family::kTemporalTv, 1.0, 0.0, [&] {
          return TransformedDifferenceResidual::Create(objective.event_model);
        });
        ++statistics.log_temporal_tv_pixels;
      }
      for_each_segment(p, [&](int64_t s) {
        if (layout.segment(s).constant || s + 1 >= layout.num_segments() ||
            layout.segment(s + 1).pixel != p) {
          return;
        }
        temporal(problem.AddResidualBlock(difference, loss, layout.value(s, latent),
                                          layout.value(s + 1, latent)));
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
      if (!solved(p)) continue;
      for_each_segment(p, [&](int64_t s) {
        const LatentLayout::Segment& segment = layout.segment(s);
        if (segment.constant) return;
        double sum = 0.0;
        for (int t = segment.first; t <= segment.last; ++t) sum += target.frame_data(t)[p];
        const int length = segment.length();
        built->cost_functions_.emplace_back(PriorResidual::Create(sum / length, weight * length));
        temporal(problem.AddResidualBlock(built->cost_functions_.back().get(), nullptr,
                                          layout.value(s, latent)));
        ++statistics.prior_residuals;
      });
    }
  }
  statistics.distinct_cost_functions = static_cast<int64_t>(built->cost_functions_.size());
  statistics.shared_structure_correlation = terms.shared_structure_correlation();
  statistics.shared_structure_applied = terms.has_spatial_tv_offsets();
  return built;
}

}  // namespace evfs
