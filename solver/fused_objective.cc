#include "evfs/solver/fused_objective.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "evfs/core/error.h"
#include "evfs/core/option_checker.h"
#include "evfs/cost_functions/difference_residual.h"
#include "evfs/cost_functions/weighted_l1_loss.h"
#include "evfs/scene/event_model.h"
#include "evfs/solver/objective_terms.h"

namespace evfs {
namespace {

// tanh(z) = 1 − 2 / (e^{2z} + 1), to within 4e-16 of std::tanh (absolute, which is what the
// event residual needs) at less than half its cost: glibc's tanh goes through expm1, and the
// event term takes one tanh per active pixel and latent step, the largest share of an
// evaluation. e^{2z} overflowing to +inf gives 1, underflowing to 0 gives −1.
inline double TanhFromExp(double exp_2z) { return 1.0 - 2.0 / (exp_2z + 1.0); }

// ρ and its derivative. Scalar(r) returns ρ(r) and sets *slope = ρ'(r); Norm(s) returns ρ of a
// residual vector with squared norm s and sets *scale so that its gradient is scale · r.
template <L1Penalty kPenalty>
struct Penalty;

template <>
struct Penalty<L1Penalty::kSmoothed> {
  static double Scalar(double r, double eps, double* slope) {
    *slope = r / std::sqrt(eps * eps + r * r);
    return SmoothedAbs(r, eps);
  }
  static double Norm(double squared_norm, double eps, double* scale) {
    const double root = std::sqrt(eps * eps + squared_norm);
    *scale = 1.0 / root;
    return root - eps;
  }
};

template <>
struct Penalty<L1Penalty::kTrueL1> {
  static double Scalar(double r, double /*eps*/, double* slope) {
    *slope = r > 0.0 ? 1.0 : (r < 0.0 ? -1.0 : 0.0);
    return std::fabs(r);
  }
  static double Norm(double squared_norm, double /*eps*/, double* scale) {
    const double norm = std::sqrt(squared_norm);
    *scale = norm > 0.0 ? 1.0 / norm : 0.0;
    return norm;
  }
};

// Spatial TV terms owned by the pixels [begin, end) of one row of one latent frame: adds their
// cost to cost[x] and writes the coefficients of their gradient, ∂/∂H(x+1, y) into
// coef_right[x] and ∂/∂H(x, y+1) into coef_below[x] (∂/∂H(x, y) is minus their sum). right[x]
// and below[x] are the neighbours of center[x]; where a term does not exist its mask is 0. Each
// difference is measured from its offset (offset_right[x], offset_below[x]; ObjectiveTerms),
// read only when kOffsets (plain TV passes null).
template <L1Penalty kPenalty, bool kOffsets>
void SpatialTerms(SpatialTv form, const double* center, const double* right, const double* below,
                  const double* mask_right, const double* mask_below, const double* offset_right,
                  const double* offset_below, double weight, double eps, int begin, int end,
                  double* __restrict coef_right, double* __restrict coef_below,
                  double* __restrict cost) {
  using P = Penalty<kPenalty>;
  const auto offset_x = [&](int x) { return kOffsets ? offset_right[x] : 0.0; };
  const auto offset_y = [&](int x) { return kOffsets ? offset_below[x] : 0.0; };
  switch (form) {
    case SpatialTv::kAnisotropic:
      for (int x = begin; x < end; ++x) {
        double slope_x, slope_y;
        const double value_x = P::Scalar(right[x] - center[x] - offset_x(x), eps, &slope_x);
        const double value_y = P::Scalar(below[x] - center[x] - offset_y(x), eps, &slope_y);
        const double weight_x = weight * mask_right[x], weight_y = weight * mask_below[x];
        cost[x] += weight_x * value_x + weight_y * value_y;
        coef_right[x] = weight_x * slope_x;
        coef_below[x] = weight_y * slope_y;
      }
      break;
    case SpatialTv::kPaper:
      for (int x = begin; x < end; ++x) {
        double slope;
        const double value =
            P::Scalar((right[x] - center[x]) + (below[x] - center[x]) - offset_x(x) - offset_y(x),
                      eps, &slope);
        const double weight_here = weight * mask_right[x];
        cost[x] += weight_here * value;
        coef_right[x] = coef_below[x] = weight_here * slope;
      }
      break;
    case SpatialTv::kIsotropic:
      for (int x = begin; x < end; ++x) {
        const double dx = right[x] - center[x] - offset_x(x);
        const double dy = below[x] - center[x] - offset_y(x);
        double scale;
        const double value = P::Norm(dx * dx + dy * dy, eps, &scale);
        const double weight_here = weight * mask_right[x];
        cost[x] += weight_here * value;
        coef_right[x] = weight_here * scale * dx;
        coef_below[x] = weight_here * scale * dy;
      }
      break;
  }
}

}  // namespace

const char* L1PenaltyName(L1Penalty penalty) {
  return penalty == L1Penalty::kTrueL1 ? "true_l1" : "smoothed";
}

bool FusedObjectiveOptions::IsValid(std::string* error) const {
  return OptionChecker().InRange("num_threads", num_threads, 1, 1 << 16).Passed(error);
}

// Layout of an evaluation. The rows of the image are split into bands of about equal work, a few
// per thread. A band's rows are walked in order and, for each row, every latent frame: the
// spatial TV terms the row owns (kept as gradient coefficients for this row and the next), then
// for each run of active pixels the frame, event and temporal terms (they only involve the
// pixel's own time series), then the spatial TV gradient gathered from the coefficients of this
// row and the one above. So a band writes only its own rows of the gradient, and the one row of
// spatial terms above it is recomputed (without its cost) instead of shared. The gradient of a row
// is complete once the row is done: it is copied out or handed to a StepFunction there.
struct FusedObjective::Impl {
  struct FrameTerm {
    int first = 0;  // latent frames of the exposure
    int last = 0;
    const double* image = nullptr;  // F_j, row-major
  };
  struct EventTerm {
    int first = 0;                  // latent frame a_k
    int steps = 1;                  // b_k − a_k
    const float* values = nullptr;  // E_k
  };
  struct Row {
    int run_begin = 0;  // active runs of the row: runs[run_begin, run_end)
    int run_end = 0;
    // Columns whose spatial TV coefficients are computed: every term the row owns, and every
    // coefficient the gradient gathering of this row and the next one reads.
    int coef_begin = 0;
    int coef_end = 0;
  };
  struct Band {
    int row_begin = 0;
    int row_end = 0;
  };
  // Per-band buffers, reused by every evaluation.
  struct Scratch {
    std::vector<double> cost;                 // w: cost of the band's terms per column
    std::vector<double> discard;              // w: cost of the row above the band, dropped
    std::vector<double> gradient;             // N·w: the current row's gradient per frame
    std::vector<double> coef_right;           // N·(w+1): column x at x + 1; column −1 stays 0
    std::vector<double> coef_below;           // N·w: this row's
    std::vector<double> coef_below_previous;  // N·w: the row above's
    std::vector<double> transformed;          // N·w: g(H) of the row (log model)
    std::vector<double> transform_slope;      // N·w: g'(H) of the row (log model)
    std::vector<double> row_sum;              // w: sums over a term's frames, then its slope
    std::vector<double> step_slope;           // steps·w: e^{2z}, then α (1 − u²), per step
  };
  // Where an evaluation's gradient goes: into `gradient` (full size) and/or to `step`, which
  // writes the next iterate into `next`.
  struct Output {
    double* gradient = nullptr;
    const FusedObjective::StepFunction* step = nullptr;
    double* next = nullptr;
  };
  using BandFunction = double (Impl::*)(int, const double*, const Output&) const;

  Impl(const Scene& scene, const ObjectiveOptions& objective, const ActivityMask& mask,
       const FusedObjectiveOptions& options);

  double Evaluate(const double* latent, const Output& output) const;

  template <L1Penalty kPenalty, EventModel kModel>
  double EvaluateBand(int band, const double* latent, const Output& output) const;
  template <L1Penalty kPenalty>
  void SpatialRow(int y, const double* latent, double* coef_below, double* cost,
                  Scratch* scratch) const;
  template <L1Penalty kPenalty, EventModel kModel>
  void TimeSeriesTerms(int y, int begin, int end, const double* latent, Scratch* scratch) const;
  template <typename P>
  void TemporalTermsInG(int64_t row_start, int begin, int end, const double* latent,
                        Scratch* scratch) const;

  FusedObjectiveOptions options;
  int height = 0, width = 0, num_latent = 0;
  int64_t pixels = 0;
  // Normalised weight of each family's terms (ObjectiveTerms); 0 leaves the family out.
  double frame_weight = 0.0, event_weight = 0.0, spatial_weight = 0.0, temporal_weight = 0.0;
  double eps = 0.0;
  EventModelParams event_model;
  // ObjectiveTerms::temporal_tv_in_g: 1 where the pixel's temporal TV is measured in g.
  std::vector<uint8_t> temporal_in_g;
  SpatialTv spatial_tv = SpatialTv::kAnisotropic;
  std::vector<FrameTerm> frame_terms;
  std::vector<EventTerm> event_terms;
  int max_steps = 1;
  int64_t num_active = 0;
  std::vector<PixelRun> runs;
  std::vector<Row> rows;
  // 1 where a spatial TV term exists: the horizontal one (or the only one, for the paper and
  // isotropic forms) and the vertical one of anisotropic TV.
  std::vector<double> mask_right, mask_below;
  // What each difference is measured from (ObjectiveTerms::spatial_tv_offset_at); empty for
  // plain TV.
  std::vector<double> offset_right, offset_below;
  std::vector<Band> bands;
  BandFunction evaluate_band = nullptr;
  mutable std::vector<Scratch> scratch;
  mutable std::vector<double> band_costs;
};

FusedObjective::Impl::Impl(const Scene& scene, const ObjectiveOptions& objective,
                           const ActivityMask& mask, const FusedObjectiveOptions& options)
    : options(options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgumentError("fused objective: " + error);
  if (!objective.IsValid(&error)) throw InvalidArgumentError("objective: " + error);
  if (objective.prior_weight > 0.0) {
    throw InvalidArgumentError(
        "fused objective: the quadratic prior (plug & play) is built only by the Ceres problem "
        "(ceres_lm)");
  }
  if (!objective.event_model.IsValid(&error)) {
    throw InvalidArgumentError(error + " (derive alpha with EstimateEventModel first)");
  }
  height = scene.height;
  width = scene.width;
  num_latent = scene.num_latent_frames();
  pixels = static_cast<int64_t>(height) * width;
  if (mask.num_pixels() != pixels || scene.events.height() != height ||
      scene.events.width() != width) {
    throw InvalidArgumentError("fused objective: mask or event frames of another size");
  }
  eps = objective.smoothing_scale;
  event_model = objective.event_model;
  spatial_tv = objective.spatial_tv;
  const ObjectiveTerms terms(scene, objective, mask);
  frame_weight = terms.weight(TermFamily::kFrame);
  event_weight = terms.weight(TermFamily::kEvent);
  spatial_weight = terms.weight(TermFamily::kSpatialTv);
  temporal_weight = terms.weight(TermFamily::kTemporalTv);
  temporal_in_g = terms.temporal_tv_in_g();

  if (frame_weight > 0.0) {
    for (const FrameObservation& frame : scene.frames) {
      if (frame.image.rows() != height || frame.image.cols() != width) {
        throw InvalidArgumentError(frame.label + ": frame size differs from the scene's");
      }
      frame_terms.push_back({frame.latent_first, frame.latent_last, frame.image.data()});
    }
  }
  if (event_weight > 0.0) {
    for (int k = 0; k < scene.events.num_frames(); ++k) {
      const EventFrameSpan& span = scene.events.span(k);
      const int steps = span.latent_last - span.latent_first;
      event_terms.push_back({span.latent_first, steps, scene.events.frame_data(k)});
      max_steps = std::max(max_steps, steps);
    }
  }

  // Active runs, row by row.
  rows.resize(height);
  for (int y = 0; y < height; ++y) {
    rows[y].run_begin = static_cast<int>(runs.size());
    const int64_t row_start = static_cast<int64_t>(y) * width;
    for (int x = 0; x < width;) {
      if (!mask.active(row_start + x)) {
        ++x;
        continue;
      }
      PixelRun run;
      run.begin = row_start + x;
      run.offset = num_active;
      while (x < width && mask.active(row_start + x)) ++x;
      run.end = row_start + x;
      num_active += run.end - run.begin;
      runs.push_back(run);
    }
    rows[y].run_end = static_cast<int>(runs.size());
  }

  if (spatial_weight > 0.0) {
    mask_right.assign(pixels, 0.0);
    mask_below.assign(pixels, 0.0);
    if (terms.has_spatial_tv_offsets()) {
      offset_right.assign(pixels, 0.0);
      offset_below.assign(pixels, 0.0);
    }
    const bool anisotropic = spatial_tv == SpatialTv::kAnisotropic;
    for (int y = 0; y < height; ++y) {
      Row& row = rows[y];
      int first = width, last = -1;  // hull of the columns the row needs
      const auto need = [&](int x) {
        first = std::min(first, x);
        last = std::max(last, x);
      };
      for (int x = 0; x < width; ++x) {
        const int64_t p = static_cast<int64_t>(y) * width + x;
        const SpatialTvTermsAt owned = terms.spatial_tv_terms_at(p);
        mask_right[p] = owned.right;
        mask_below[p] = anisotropic ? owned.below : owned.right;
        if (!offset_right.empty()) {
          const SpatialTvOffset offset = terms.spatial_tv_offset_at(p);
          offset_right[p] = offset.right;
          offset_below[p] = offset.below;
        }
        const bool here = mask.active(p);
        const bool below = y + 1 < height && mask.active(p + width);
        if (mask_right[p] > 0.0 || mask_below[p] > 0.0 || below) need(x);
        if (here) {
          need(x);
          if (x > 0) need(x - 1);
        }
      }
      if (last >= first) {
        row.coef_begin = first;
        row.coef_end = last + 1;
      }
    }
  }

  // Bands of rows with about equal work: an active pixel costs its time series' terms, a
  // spatial TV column its latent frames.
  std::vector<double> row_work(height);
  double total_work = 0.0;
  for (int y = 0; y < height; ++y) {
    int64_t active_in_row = 0;
    for (int r = rows[y].run_begin; r < rows[y].run_end; ++r) {
      active_in_row += runs[r].end - runs[r].begin;
    }
    row_work[y] = static_cast<double>(active_in_row) * 4.0 * num_latent +
                  static_cast<double>(rows[y].coef_end - rows[y].coef_begin) * num_latent +
                  0.1 * width * num_latent;  // clearing and copying the gradient row
    total_work += row_work[y];
  }
  // A few bands per thread, handed out dynamically: a thread that the system deschedules for a
  // while does not hold up the others. Each band recomputes the TV row above it.
  constexpr int kBandsPerThread = 4;
  const int num_bands = std::max(1, std::min(kBandsPerThread * options.num_threads, height));
  double done = 0.0;
  Band band;
  for (int y = 0; y < height; ++y) {
    done += row_work[y];
    const int bands_left = num_bands - static_cast<int>(bands.size()) - 1;
    if (bands_left > 0 && done >= total_work * (bands.size() + 1) / num_bands &&
        height - (y + 1) >= bands_left) {
      band.row_end = y + 1;
      bands.push_back(band);
      band.row_begin = y + 1;
    }
  }
  band.row_end = height;
  bands.push_back(band);

  scratch.resize(bands.size());
  for (Scratch& s : scratch) {
    s.cost.assign(width, 0.0);
    s.discard.assign(width, 0.0);
    s.gradient.assign(static_cast<size_t>(num_latent) * width, 0.0);
    s.row_sum.assign(width, 0.0);
    if (spatial_weight > 0.0) {
      s.coef_right.assign(static_cast<size_t>(num_latent) * (width + 1), 0.0);
      s.coef_below.assign(static_cast<size_t>(num_latent) * width, 0.0);
      s.coef_below_previous.assign(static_cast<size_t>(num_latent) * width, 0.0);
    }
    if (event_weight > 0.0) {
      s.step_slope.assign(static_cast<size_t>(max_steps) * width, 0.0);
      if (event_model.model == EventModel::kLog) {
        s.transformed.assign(static_cast<size_t>(num_latent) * width, 0.0);
        s.transform_slope.assign(static_cast<size_t>(num_latent) * width, 0.0);
      }
    }
  }
  band_costs.assign(bands.size(), 0.0);

  const bool smoothed = options.penalty == L1Penalty::kSmoothed;
  const bool linear = event_model.model == EventModel::kLinear;
  evaluate_band = smoothed
                      ? (linear ? &Impl::EvaluateBand<L1Penalty::kSmoothed, EventModel::kLinear>
                                : &Impl::EvaluateBand<L1Penalty::kSmoothed, EventModel::kLog>)
                      : (linear ? &Impl::EvaluateBand<L1Penalty::kTrueL1, EventModel::kLinear>
                                : &Impl::EvaluateBand<L1Penalty::kTrueL1, EventModel::kLog>);
}

double FusedObjective::Impl::Evaluate(const double* latent, const Output& output) const {
  const int num_bands = static_cast<int>(bands.size());
  // Bands in any order on any thread: each band's cost and gradient are computed the same way
  // wherever it runs, and the costs are added in band order.
#pragma omp parallel for num_threads(options.num_threads) schedule(dynamic, 1) if (num_bands > 1)
  for (int b = 0; b < num_bands; ++b) band_costs[b] = (this->*evaluate_band)(b, latent, output);
  double cost = 0.0;
  for (const double band_cost : band_costs) cost += band_cost;
  return cost;
}

template <L1Penalty kPenalty>
void FusedObjective::Impl::SpatialRow(int y, const double* latent, double* coef_below, double* cost,
                                      Scratch* scratch) const {
  const Row& row = rows[y];
  if (row.coef_begin >= row.coef_end) return;
  const int64_t row_start = static_cast<int64_t>(y) * width;
  const double* row_mask_right = mask_right.data() + row_start;
  const double* row_mask_below = mask_below.data() + row_start;
  const bool offsets = !offset_right.empty();
  const double* row_offset_right = offsets ? offset_right.data() + row_start : nullptr;
  const double* row_offset_below = offsets ? offset_below.data() + row_start : nullptr;
  const auto terms = offsets ? SpatialTerms<kPenalty, true> : SpatialTerms<kPenalty, false>;
  // The last column has no right neighbour and the last row none below: they are read as the
  // pixel itself, and the masks drop the terms that would need them.
  const int inner_end = std::min(row.coef_end, width - 1);
  for (int t = 0; t < num_latent; ++t) {
    const double* center = latent + t * pixels + row_start;
    const double* below = y + 1 < height ? center + width : center;
    double* frame_coef_right = scratch->coef_right.data() + t * (width + 1) + 1;
    double* frame_coef_below = coef_below + t * width;
    terms(spatial_tv, center, center + 1, below, row_mask_right, row_mask_below, row_offset_right,
          row_offset_below, spatial_weight, eps, row.coef_begin, inner_end, frame_coef_right,
          frame_coef_below, cost);
    if (row.coef_end == width) {
      terms(spatial_tv, center, center, below, row_mask_right, row_mask_below, row_offset_right,
            row_offset_below, spatial_weight, eps, width - 1, width, frame_coef_right,
            frame_coef_below, cost);
    }
  }
}

template <L1Penalty kPenalty, EventModel kModel>
void FusedObjective::Impl::TimeSeriesTerms(int y, int begin, int end, const double* latent,
                                           Scratch* scratch) const {
  using P = Penalty<kPenalty>;
  const int64_t row_start = static_cast<int64_t>(y) * width;
  const auto intensity = [&](int t) { return latent + t * pixels + row_start; };
  const auto gradient = [&](int t) { return scratch->gradient.data() + t * width; };
  double* __restrict cost = scratch->cost.data();
  double* __restrict row_sum = scratch->row_sum.data();
  // Locals, so that the compiler need not reload them after every store in the loops.
  const double eps = this->eps;
  const double frame_weight = this->frame_weight, event_weight = this->event_weight;
  const double temporal_weight = this->temporal_weight;

  for (const FrameTerm& frame : frame_terms) {
    // r = F − (Σ_t H_t) / n  (FrameResidual)
    const double* observed = frame.image + row_start;
    const double count = frame.last - frame.first + 1;
    std::fill(row_sum + begin, row_sum + end, 0.0);
    for (int t = frame.first; t <= frame.last; ++t) {
      const double* h = intensity(t);
      for (int x = begin; x < end; ++x) row_sum[x] += h[x];
    }
    for (int x = begin; x < end; ++x) {
      double slope;
      cost[x] += frame_weight * P::Scalar(observed[x] - row_sum[x] / count, eps, &slope);
      row_sum[x] = frame_weight * slope / count;
    }
    for (int t = frame.first; t <= frame.last; ++t) {
      double* __restrict g = gradient(t);
      for (int x = begin; x < end; ++x) g[x] -= row_sum[x];
    }
  }

  if (!event_terms.empty()) {
    // g(H) and g'(H) of the run; the linear model reads H itself.
    const auto transformed = [&](int t) {
      return kModel == EventModel::kLinear ? intensity(t) : scratch->transformed.data() + t * width;
    };
    if constexpr (kModel == EventModel::kLog) {
      const double offset = event_model.log_offset;
      for (int t = 0; t < num_latent; ++t) {
        const double* h = intensity(t);
        double* __restrict g = scratch->transformed.data() + t * width;
        double* __restrict slope = scratch->transform_slope.data() + t * width;
        // IntensityTransform and its derivative: flat below 0.
        for (int x = begin; x < end; ++x) {
          g[x] = (h[x] >= 0.0 ? h[x] : 0.0) + offset;
          slope[x] = h[x] >= 0.0 ? 1.0 / (h[x] + offset) : 0.0;
        }
        for (int x = begin; x < end; ++x) g[x] = std::log(g[x]);
      }
    }
    for (const EventTerm& event : event_terms) {
      // r = E − Σ_s c tanh(α (g(H_{s+1}) − g(H_s)) / c)  (EventResidual)
      const float* observed = event.values + row_start;
      std::fill(row_sum + begin, row_sum + end, 0.0);
      for (int s = 0; s < event.steps; ++s) {
        const double* g_before = transformed(event.first + s);
        const double* g_after = transformed(event.first + s + 1);
        // e^{2z} with z = α Δg / c, kept in step_slope; std::exp has a loop of its own so that
        // the other two vectorise.
        double* __restrict step_slope = scratch->step_slope.data() + s * width;
        for (int x = begin; x < end; ++x) {
          const double saturation =
              SaturationForCount(observed[x], event.steps, event_model.saturation);
          const double change = g_after[x] - g_before[x];
          step_slope[x] = 2.0 * (event_model.AlphaFor(change) * change / saturation);
        }
        for (int x = begin; x < end; ++x) step_slope[x] = std::exp(step_slope[x]);
        for (int x = begin; x < end; ++x) {
          const double saturation =
              SaturationForCount(observed[x], event.steps, event_model.saturation);
          const double u = TanhFromExp(step_slope[x]);
          row_sum[x] += saturation * u;
          step_slope[x] = event_model.AlphaFor(g_after[x] - g_before[x]) * (1.0 - u * u);
        }
      }
      for (int x = begin; x < end; ++x) {
        double slope;
        cost[x] += event_weight * P::Scalar(observed[x] - row_sum[x], eps, &slope);
        row_sum[x] = event_weight * slope;
      }
      for (int s = 0; s < event.steps; ++s) {
        const double* step_slope = scratch->step_slope.data() + s * width;
        double* __restrict g_before = gradient(event.first + s);
        double* __restrict g_after = gradient(event.first + s + 1);
        if constexpr (kModel == EventModel::kLinear) {
          for (int x = begin; x < end; ++x) {
            const double coefficient = row_sum[x] * step_slope[x];
            g_before[x] += coefficient;
            g_after[x] -= coefficient;
          }
        } else {
          const double* slope_before = scratch->transform_slope.data() + (event.first + s) * width;
          const double* slope_after =
              scratch->transform_slope.data() + (event.first + s + 1) * width;
          for (int x = begin; x < end; ++x) {
            const double coefficient = row_sum[x] * step_slope[x];
            g_before[x] += coefficient * slope_before[x];
            g_after[x] -= coefficient * slope_after[x];
          }
        }
      }
    }
  }

  if (temporal_weight > 0.0) {
    // r = H_{t+1} − H_t  (DifferenceResidual), except where it is measured in g.
    const uint8_t* in_g = kModel == EventModel::kLog && !temporal_in_g.empty()
                              ? temporal_in_g.data() + row_start
                              : nullptr;
    for (int t = 0; t + 1 < num_latent; ++t) {
      const double* before = intensity(t);
      const double* after = intensity(t + 1);
      double* __restrict g_before = gradient(t);
      double* __restrict g_after = gradient(t + 1);
      for (int x = begin; x < end; ++x) {
        if (in_g != nullptr && in_g[x]) continue;
        double slope;
        cost[x] += temporal_weight * P::Scalar(after[x] - before[x], eps, &slope);
        g_before[x] -= temporal_weight * slope;
        g_after[x] += temporal_weight * slope;
      }
    }
    if (in_g != nullptr) TemporalTermsInG<P>(row_start, begin, end, latent, scratch);
  }
}

// The temporal terms of the run's pixels measured in g (TransformedDifferenceResidual),
// (0.5 + b)·|Δg| where TimeSeriesTerms leaves |ΔH| out.
template <typename P>
void FusedObjective::Impl::TemporalTermsInG(int64_t row_start, int begin, int end,
                                            const double* latent, Scratch* scratch) const {
  const double scale = TransformedDifferenceResidual::MidGreyScale(event_model);
  double* __restrict cost = scratch->cost.data();
  for (int x = begin; x < end; ++x) {
    if (!temporal_in_g[row_start + x]) continue;
    for (int t = 0; t + 1 < num_latent; ++t) {
      const double before = latent[t * pixels + row_start + x];
      const double after = latent[(t + 1) * pixels + row_start + x];
      double* g_before = scratch->gradient.data() + t * width + x;
      double* g_after = scratch->gradient.data() + (t + 1) * width + x;
      const double r = scale * (IntensityTransform(after, event_model) -
                                IntensityTransform(before, event_model));
      double slope;
      cost[x] += temporal_weight * P::Scalar(r, eps, &slope);
      const double coefficient = temporal_weight * slope * scale;
      *g_before -= coefficient * IntensityTransformDerivative(before, event_model);
      *g_after += coefficient * IntensityTransformDerivative(after, event_model);
    }
  }
}

template <L1Penalty kPenalty, EventModel kModel>
double FusedObjective::Impl::EvaluateBand(int band_index, const double* latent,
                                          const Output& output) const {
  const Band& band = bands[band_index];
  Scratch& s = scratch[band_index];
  std::fill(s.cost.begin(), s.cost.end(), 0.0);
  const bool spatial = spatial_weight > 0.0;
  double* coef_below_previous = s.coef_below_previous.data();
  double* coef_below = s.coef_below.data();
  if (spatial) {
    if (band.row_begin > 0) {
      SpatialRow<kPenalty>(band.row_begin - 1, latent, coef_below_previous, s.discard.data(), &s);
    } else {
      std::fill(s.coef_below_previous.begin(), s.coef_below_previous.end(), 0.0);
    }
  }
  const size_t row_bytes = sizeof(double) * width;
  for (int y = band.row_begin; y < band.row_end; ++y) {
    const Row& row = rows[y];
    if (spatial) SpatialRow<kPenalty>(y, latent, coef_below, s.cost.data(), &s);
    std::fill(s.gradient.begin(), s.gradient.end(), 0.0);
    for (int r = row.run_begin; r < row.run_end; ++r) {
      const int begin = static_cast<int>(runs[r].begin - static_cast<int64_t>(y) * width);
      const int end = begin + static_cast<int>(runs[r].end - runs[r].begin);
      TimeSeriesTerms<kPenalty, kModel>(y, begin, end, latent, &s);
      if (!spatial) continue;
      // ∂/∂H(x, y) of the terms at (x, y), (x−1, y) and (x, y−1).
      for (int t = 0; t < num_latent; ++t) {
        const double* right = s.coef_right.data() + t * (width + 1) + 1;
        const double* below = coef_below + t * width;
        const double* above = coef_below_previous + t * width;
        double* __restrict g = s.gradient.data() + t * width;
        for (int x = begin; x < end; ++x) {
          g[x] += (right[x - 1] - right[x]) + (above[x] - below[x]);
        }
      }
    }
    const int64_t row_start = static_cast<int64_t>(y) * width;
    if (output.gradient != nullptr) {
      for (int t = 0; t < num_latent; ++t) {
        std::memcpy(output.gradient + t * pixels + row_start, s.gradient.data() + t * width,
                    row_bytes);
      }
    }
    if (output.step != nullptr) {
      // The row's gradient is complete while it is still in cache.
      for (int r = row.run_begin; r < row.run_end; ++r) {
        const PixelRun& run = runs[r];
        for (int t = 0; t < num_latent; ++t) {
          const int64_t frame = t * pixels;
          (*output.step)(t, run, s.gradient.data() + t * width + (run.begin - row_start),
                         latent + frame + run.begin, output.next + frame + run.begin);
        }
      }
    }
    std::swap(coef_below_previous, coef_below);
  }
  double cost = 0.0;
  for (const double column_cost : s.cost) cost += column_cost;
  return cost;
}

FusedObjective::FusedObjective(const Scene& scene, const ObjectiveOptions& objective,
                               const ActivityMask& mask, const FusedObjectiveOptions& options)
    : impl_(std::make_unique<Impl>(scene, objective, mask, options)) {}

FusedObjective::~FusedObjective() = default;

double FusedObjective::Evaluate(const double* latent, double* gradient) const {
  Impl::Output output;
  output.gradient = gradient;
  return impl_->Evaluate(latent, output);
}

double FusedObjective::EvaluateAndStep(const double* latent, double* next,
                                       const StepFunction& step) const {
  Impl::Output output;
  output.step = &step;
  output.next = next;
  return impl_->Evaluate(latent, output);
}

double FusedObjective::Evaluate(const Video& latent, Video* gradient) const {
  if (latent.height() != height() || latent.width() != width() ||
      latent.num_frames() != num_latent_frames()) {
    throw InvalidArgumentError("the latent video does not match the scene's size");
  }
  if (gradient == nullptr) return Evaluate(latent.data(), nullptr);
  if (gradient->height() != height() || gradient->width() != width() ||
      gradient->num_frames() != num_latent_frames()) {
    *gradient = Video(height(), width(), num_latent_frames());
  }
  return Evaluate(latent.data(), gradient->data());
}

int FusedObjective::height() const { return impl_->height; }
int FusedObjective::width() const { return impl_->width; }
int FusedObjective::num_latent_frames() const { return impl_->num_latent; }
int64_t FusedObjective::pixels_per_frame() const { return impl_->pixels; }
int64_t FusedObjective::num_voxels() const { return impl_->pixels * impl_->num_latent; }
int64_t FusedObjective::num_active_pixels() const { return impl_->num_active; }
int64_t FusedObjective::num_active_voxels() const { return impl_->num_active * impl_->num_latent; }
const std::vector<PixelRun>& FusedObjective::active_runs() const { return impl_->runs; }
const FusedObjectiveOptions& FusedObjective::options() const { return impl_->options; }

void FusedObjective::GatherActive(const double* full, double* active) const {
  for (int t = 0; t < impl_->num_latent; ++t) {
    const double* frame = full + t * impl_->pixels;
    double* frame_active = active + t * impl_->num_active;
    for (const PixelRun& run : impl_->runs) {
      std::copy(frame + run.begin, frame + run.end, frame_active + run.offset);
    }
  }
}

void FusedObjective::ScatterActive(const double* active, double* full) const {
  for (int t = 0; t < impl_->num_latent; ++t) {
    double* frame = full + t * impl_->pixels;
    const double* frame_active = active + t * impl_->num_active;
    for (const PixelRun& run : impl_->runs) {
      std::copy(frame_active + run.offset, frame_active + run.offset + (run.end - run.begin),
                frame + run.begin);
    }
  }
}

}  // namespace evfs
