#include "evfs/solver/fused_objective.h"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/scene/activity_mask.h"
#include "evfs/solver/objective_terms.h"
#include "evfs/solver/problem_builder.h"

namespace evfs {
namespace {

// The fused pass and Ceres add the same terms in another order, with tanh from another formula
// (within 4e-16): they agree to ~1e-14 relative; a wrong term, weight or mask is off by far
// more than 1e-9.
constexpr double kRelativeTolerance = 1e-9;
// Thread counts only change the order of the final additions.
constexpr double kThreadTolerance = 1e-12;

constexpr int kHeight = 8;
constexpr int kWidth = 11;
constexpr int kNumLatent = 7;

enum class Binning { kCollision, kStacked };
enum class Activity { kAll, kPartial };

// A scene with random observations. Collision binning: one event frame per latent step with
// values in {-1, 0, 1}. Stacked: frames spanning 2, 1 and 3 steps holding counts up to ±4, so
// that the saturation c = |E| / steps exceeds 1. Partial activity: events only in a 3×2 patch,
// so that with radius 1 there are active, ring and inactive pixels.
Scene MakeRandomScene(Binning binning, Activity activity, uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> intensity(0.0, 1.0);
  std::uniform_int_distribution<int> collision_value(-1, 1);
  std::uniform_int_distribution<int> count_value(-4, 4);
  Scene scene;
  scene.height = kHeight;
  scene.width = kWidth;
  scene.events = EventFrames(kHeight, kWidth);
  std::vector<std::pair<int, int>> spans;
  if (binning == Binning::kCollision) {
    for (int k = 0; k + 1 < kNumLatent; ++k) spans.emplace_back(k, k + 1);
  } else {
    spans = {{0, 2}, {2, 3}, {3, 6}};
  }
  std::vector<int64_t> latent_ns;
  for (int t = 0; t < kNumLatent; ++t) latent_ns.push_back(10 * t);
  scene.events.set_latent_timestamps_ns(latent_ns);
  for (const auto& [first, last] : spans) {
    const int k = scene.events.AddFrame({first, last, latent_ns[first], latent_ns[last], 0});
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        const bool in_patch = x >= 4 && x <= 6 && y >= 3 && y <= 4;
        if (activity == Activity::kPartial && !in_patch) continue;
        const int value =
            binning == Binning::kCollision ? collision_value(random) : count_value(random);
        scene.events.value(k, y, x) = static_cast<float>(value);
        scene.num_events += std::abs(value);
      }
    }
  }
  // Sharp frames at both ends and one blurred over latent frames 2..4.
  for (const auto& [first, last] : {std::pair{0, 0}, std::pair{2, 4}, std::pair{6, 6}}) {
    FrameObservation frame;
    frame.image = Image(kHeight, kWidth);
    for (int i = 0; i < frame.image.size(); ++i) frame.image.data()[i] = intensity(random);
    frame.latent_first = first;
    frame.latent_last = last;
    frame.label = "random frame " + std::to_string(first);
    scene.frames.push_back(frame);
  }
  return scene;
}

// A latent video with values slightly outside [0, 1], so that the log model's clamp at 0 is
// exercised too.
Video MakeRandomLatent(uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> intensity(-0.05, 1.05);
  Video latent(kHeight, kWidth, kNumLatent);
  for (int64_t i = 0; i < latent.num_frames() * latent.pixels_per_frame(); ++i) {
    latent.data()[i] = intensity(random);
  }
  return latent;
}

ReconstructionOptions MakeOptions(SpatialTv spatial_tv, EventModel model, Activity activity) {
  ReconstructionOptions options;
  // The fused objective sees every ring voxel's own value; Ceres' problem, held to the same.
  options.ring_tolerance = 0.0;
  options.objective.frame_weight = 1.3;
  options.objective.event_weight = 0.7;
  options.objective.spatial_tv_weight = 2.0;
  options.objective.temporal_tv_weight = 1.5;
  options.objective.spatial_tv = spatial_tv;
  options.objective.event_model.model = model;
  // α large enough that α Δg / c reaches both branches of the fused tanh (|z| ≷ 0.625).
  options.objective.event_model.alpha = model == EventModel::kLog ? 1.5 : 4.0;
  options.activity_radius_px = activity == Activity::kAll ? -1 : 1;
  options.merge_quiet_steps = false;  // one parameter block per voxel
  return options;
}

// Builds the Ceres problem over `latent` and expects the fused evaluation at the same point (the
// latent video as the problem sees it, segments expanded) to give its cost and gradient. A
// merged segment's gradient is the sum of its voxels' gradients; ring and inactive voxels have
// gradient 0.
void ExpectFusedMatchesCeres(const Scene& scene, const ReconstructionOptions& options,
                             const Video& latent, int num_threads) {
  Video problem_latent = latent;
  const std::unique_ptr<BuiltProblem> built = ProblemBuilder(scene, options).Build(&problem_latent);
  const LatentLayout& layout = built->layout();
  // The unknowns, in the order the gradient is wanted.
  std::vector<int64_t> unknowns;
  ceres::Problem::EvaluateOptions evaluate_options;
  for (int64_t s = 0; s < layout.num_segments(); ++s) {
    if (layout.segment(s).constant) continue;
    unknowns.push_back(s);
    evaluate_options.parameter_blocks.push_back(layout.value(s, &problem_latent));
  }
  double ceres_cost = 0.0;
  std::vector<double> ceres_gradient;
  ASSERT_TRUE(
      built->problem().Evaluate(evaluate_options, &ceres_cost, nullptr, &ceres_gradient, nullptr));
  ASSERT_EQ(ceres_gradient.size(), unknowns.size());

  Video expanded = problem_latent;
  layout.Expand(&expanded);
  const ActivityMask mask(scene.events, options.activity_radius_px);
  FusedObjectiveOptions fused_options;
  fused_options.num_threads = num_threads;
  const FusedObjective fused(scene, options.objective, mask, fused_options);
  Video fused_gradient;
  const double fused_cost = fused.Evaluate(expanded, &fused_gradient);

  EXPECT_GT(ceres_cost, 0.0);
  EXPECT_NEAR(fused_cost, ceres_cost, kRelativeTolerance * ceres_cost);
  double max_gradient = 0.0, max_difference = 0.0;
  std::vector<bool> unknown_voxel(fused.num_voxels(), false);
  for (size_t i = 0; i < unknowns.size(); ++i) {
    const LatentLayout::Segment& segment = layout.segment(unknowns[i]);
    double summed = 0.0;
    for (int t = segment.first; t <= segment.last; ++t) {
      summed += fused_gradient.frame_data(t)[segment.pixel];
      unknown_voxel[t * fused.pixels_per_frame() + segment.pixel] = true;
    }
    max_gradient = std::max(max_gradient, std::abs(ceres_gradient[i]));
    max_difference = std::max(max_difference, std::abs(summed - ceres_gradient[i]));
  }
  EXPECT_GT(max_gradient, 0.0);
  EXPECT_LE(max_difference, kRelativeTolerance * max_gradient);
  // Ring and inactive voxels are constants.
  for (int64_t v = 0; v < fused.num_voxels(); ++v) {
    if (!unknown_voxel[v]) {
      EXPECT_EQ(fused_gradient.data()[v], 0.0) << "voxel " << v;
    }
  }
  if (!options.merge_quiet_steps) {
    EXPECT_EQ(fused.num_active_voxels(), static_cast<int64_t>(unknowns.size()));
  }
}

using Case = std::tuple<SpatialTv, EventModel, Binning, Activity>;

class FusedObjectiveMatchesCeres : public ::testing::TestWithParam<Case> {};

TEST_P(FusedObjectiveMatchesCeres, CostAndGradient) {
  const auto [spatial_tv, model, binning, activity] = GetParam();
  const Scene scene = MakeRandomScene(binning, activity, /*seed=*/11);
  const ReconstructionOptions options = MakeOptions(spatial_tv, model, activity);
  // Three threads: bands of 2-3 rows, so that every band border is crossed by TV terms.
  ExpectFusedMatchesCeres(scene, options, MakeRandomLatent(/*seed=*/12), /*num_threads=*/3);
}

std::string CaseName(const ::testing::TestParamInfo<Case>& info) {
  const auto [spatial_tv, model, binning, activity] = info.param;
  return std::string(SpatialTvName(spatial_tv)) + "_" + EventModelName(model) +
         (binning == Binning::kCollision ? "_collision" : "_stacked") +
         (activity == Activity::kAll ? "_all" : "_partial");
}

INSTANTIATE_TEST_SUITE_P(
    AllTermForms, FusedObjectiveMatchesCeres,
    ::testing::Combine(::testing::Values(SpatialTv::kPaper, SpatialTv::kAnisotropic,
                                         SpatialTv::kIsotropic),
                       ::testing::Values(EventModel::kLinear, EventModel::kLog),
                       ::testing::Values(Binning::kCollision, Binning::kStacked),
                       ::testing::Values(Activity::kAll, Activity::kPartial)),
    CaseName);

TEST(FusedObjective, ZeroWeightFamiliesAreLeftOutAsInTheProblem) {
  const Scene scene = MakeRandomScene(Binning::kStacked, Activity::kPartial, 21);
  const Video latent = MakeRandomLatent(22);
  for (int family = 0; family < 4; ++family) {
    ReconstructionOptions options =
        MakeOptions(SpatialTv::kAnisotropic, EventModel::kLinear, Activity::kPartial);
    double* weights[] = {&options.objective.frame_weight, &options.objective.event_weight,
                         &options.objective.spatial_tv_weight,
                         &options.objective.temporal_tv_weight};
    *weights[family] = 0.0;
    SCOPED_TRACE("family " + std::to_string(family) + " has weight 0");
    ExpectFusedMatchesCeres(scene, options, latent, /*num_threads=*/2);
  }
}

TEST(FusedObjective, MatchesTheProblemOverMergedSegments) {
  // With quiet steps merged, Ceres' unknowns are segments and each stands for its voxels: on a
  // video constant over segments its gradient is the sum of the voxels' gradients.
  for (const Binning binning : {Binning::kCollision, Binning::kStacked}) {
    const Scene scene = MakeRandomScene(binning, Activity::kPartial, 31);
    ReconstructionOptions options =
        MakeOptions(SpatialTv::kPaper, EventModel::kLinear, Activity::kPartial);
    options.merge_quiet_steps = true;
    ExpectFusedMatchesCeres(scene, options, MakeRandomLatent(32), /*num_threads=*/2);
  }
}

TEST(FusedObjective, MatchesTheProblemWithAnOffSlope) {
  // Darkening steps with their own α (EventModelParams::off_alpha_ratio), both event models.
  for (const EventModel model : {EventModel::kLinear, EventModel::kLog}) {
    const Scene scene = MakeRandomScene(Binning::kCollision, Activity::kPartial, 41);
    ReconstructionOptions options = MakeOptions(SpatialTv::kAnisotropic, model, Activity::kPartial);
    options.objective.event_model.off_alpha_ratio = 1.7;
    SCOPED_TRACE(EventModelName(model));
    ExpectFusedMatchesCeres(scene, options, MakeRandomLatent(42), /*num_threads=*/2);
  }
}

TEST(FusedObjective, MatchesTheProblemWithSharedStructureTv) {
  // Spatial TV measured from the minmod of the two sharp frames' differences (random frames:
  // offsets of both signs and zeros), every form, one unknown per voxel and merged segments.
  for (const SpatialTv form : {SpatialTv::kPaper, SpatialTv::kAnisotropic, SpatialTv::kIsotropic}) {
    for (const bool merged : {false, true}) {
      Scene scene = MakeRandomScene(Binning::kCollision, Activity::kPartial, 51);
      // The last frame half the first: their differences correlate, so the offsets apply.
      scene.frames.back().image = 0.5 * scene.frames.front().image;
      ReconstructionOptions options = MakeOptions(form, EventModel::kLog, Activity::kPartial);
      options.objective.shared_structure_tv = true;
      options.merge_quiet_steps = merged;
      const ActivityMask mask(scene.events, options.activity_radius_px);
      ASSERT_TRUE(ObjectiveTerms(scene, options.objective, mask).has_spatial_tv_offsets());
      SCOPED_TRACE(std::string(SpatialTvName(form)) + (merged ? " merged" : " per voxel"));
      ExpectFusedMatchesCeres(scene, options, MakeRandomLatent(52), /*num_threads=*/3);
    }
  }
}

// The true-ℓ1 objective from Ceres' own residuals and Jacobian (no loss applied): cost
// Σ w_i |r_i| and gradient Σ w_i sign(r_i) ∂r_i/∂H (for isotropic TV, the norm of the block's
// two residuals and w r / ‖r‖).
TEST(FusedObjective, TrueL1MatchesTheProblemsResiduals) {
  for (const SpatialTv spatial_tv :
       {SpatialTv::kPaper, SpatialTv::kAnisotropic, SpatialTv::kIsotropic}) {
    SCOPED_TRACE(SpatialTvName(spatial_tv));
    const Scene scene = MakeRandomScene(Binning::kStacked, Activity::kPartial, 41);
    const ReconstructionOptions options =
        MakeOptions(spatial_tv, EventModel::kLog, Activity::kPartial);
    Video latent = MakeRandomLatent(42);
    const auto built = ProblemBuilder(scene, options).Build(&latent);
    const ProblemStatistics& statistics = built->statistics();
    const ActivityMask mask(scene.events, options.activity_radius_px);
    ceres::Problem::EvaluateOptions evaluate_options;
    evaluate_options.apply_loss_function = false;
    for (int t = 0; t < kNumLatent; ++t) {
      for (int64_t p = 0; p < latent.pixels_per_frame(); ++p) {
        if (mask.active(p)) evaluate_options.parameter_blocks.push_back(latent.frame_data(t) + p);
      }
    }
    std::vector<double> residuals;
    ceres::CRSMatrix jacobian;
    ASSERT_TRUE(
        built->problem().Evaluate(evaluate_options, nullptr, &residuals, nullptr, &jacobian));
    // Residuals come family by family, in the order ProblemBuilder adds them.
    const ObjectiveOptions& objective = options.objective;
    const double hw = static_cast<double>(latent.pixels_per_frame());
    std::vector<double> weight_of_residual;
    const auto append = [&](int64_t count, double weight) {
      weight_of_residual.insert(weight_of_residual.end(), count, weight);
    };
    const int spatial_width = spatial_tv == SpatialTv::kIsotropic ? 2 : 1;
    append(statistics.frame_residuals, objective.frame_weight / hw);
    append(statistics.event_residuals, objective.event_weight / hw);
    append(statistics.spatial_tv_residuals * spatial_width,
           objective.spatial_tv_weight / kNumLatent / hw);
    append(statistics.temporal_tv_residuals, objective.temporal_tv_weight / hw);
    ASSERT_EQ(weight_of_residual.size(), residuals.size());
    const int64_t spatial_begin = statistics.frame_residuals + statistics.event_residuals;
    const int64_t spatial_end = spatial_begin + statistics.spatial_tv_residuals * spatial_width;
    // Per residual: its cost and dcost/dr.
    double expected_cost = 0.0;
    std::vector<double> slope(residuals.size());
    for (int64_t i = 0; i < static_cast<int64_t>(residuals.size()); ++i) {
      const double w = weight_of_residual[i];
      if (spatial_width == 2 && i >= spatial_begin && i < spatial_end) {
        const double norm = std::hypot(residuals[i], residuals[i + 1]);
        expected_cost += w * norm;
        slope[i] = w * residuals[i] / norm;
        slope[i + 1] = w * residuals[i + 1] / norm;
        ++i;
        continue;
      }
      expected_cost += w * std::abs(residuals[i]);
      slope[i] = residuals[i] > 0.0 ? w : (residuals[i] < 0.0 ? -w : 0.0);
    }
    std::vector<double> expected_gradient(jacobian.num_cols, 0.0);
    for (int row = 0; row < jacobian.num_rows; ++row) {
      for (int j = jacobian.rows[row]; j < jacobian.rows[row + 1]; ++j) {
        expected_gradient[jacobian.cols[j]] += slope[row] * jacobian.values[j];
      }
    }

    FusedObjectiveOptions fused_options;
    fused_options.penalty = L1Penalty::kTrueL1;
    const FusedObjective fused(scene, objective, mask, fused_options);
    std::vector<double> gradient(fused.num_voxels());
    const double cost = fused.Evaluate(latent.data(), gradient.data());
    std::vector<double> active_gradient(fused.num_active_voxels());
    fused.GatherActive(gradient.data(), active_gradient.data());
    ASSERT_EQ(active_gradient.size(), expected_gradient.size());
    EXPECT_NEAR(cost, expected_cost, kRelativeTolerance * expected_cost);
    double max_gradient = 0.0, max_difference = 0.0;
    for (size_t i = 0; i < expected_gradient.size(); ++i) {
      max_gradient = std::max(max_gradient, std::abs(expected_gradient[i]));
      max_difference =
          std::max(max_difference, std::abs(active_gradient[i] - expected_gradient[i]));
    }
    EXPECT_LE(max_difference, kRelativeTolerance * max_gradient);
  }
}

TEST(FusedObjective, ThreadCountsAgree) {
  const Scene scene = MakeRandomScene(Binning::kCollision, Activity::kPartial, 51);
  const ReconstructionOptions options =
      MakeOptions(SpatialTv::kIsotropic, EventModel::kLinear, Activity::kPartial);
  const ActivityMask mask(scene.events, options.activity_radius_px);
  const Video latent = MakeRandomLatent(52);
  Video reference_gradient;
  const double reference =
      FusedObjective(scene, options.objective, mask).Evaluate(latent, &reference_gradient);
  for (const int threads : {1, 3, 8}) {
    FusedObjectiveOptions fused_options;
    fused_options.num_threads = threads;
    Video gradient;
    const double cost =
        FusedObjective(scene, options.objective, mask, fused_options).Evaluate(latent, &gradient);
    EXPECT_NEAR(cost, reference, kThreadTolerance * reference) << threads << " threads";
    for (int64_t v = 0; v < latent.num_frames() * latent.pixels_per_frame(); ++v) {
      ASSERT_NEAR(gradient.data()[v], reference_gradient.data()[v], kThreadTolerance)
          << threads << " threads, voxel " << v;
    }
  }
}

TEST(FusedObjective, GatherAndScatterAreInverse) {
  const Scene scene = MakeRandomScene(Binning::kCollision, Activity::kPartial, 61);
  const ActivityMask mask(scene.events, 1);
  ObjectiveOptions objective;
  objective.event_model.alpha = 3.0;
  const FusedObjective fused(scene, objective, mask);
  ASSERT_GT(fused.num_active_pixels(), 0);
  ASSERT_LT(fused.num_active_pixels(), fused.pixels_per_frame());
  EXPECT_EQ(fused.num_active_pixels(), mask.num_active());
  const Video latent = MakeRandomLatent(62);
  std::vector<double> active(fused.num_active_voxels());
  fused.GatherActive(latent.data(), active.data());
  Video scattered(kHeight, kWidth, kNumLatent);
  fused.ScatterActive(active.data(), scattered.data());
  for (int t = 0; t < kNumLatent; ++t) {
    for (int64_t p = 0; p < fused.pixels_per_frame(); ++p) {
      EXPECT_EQ(scattered.frame_data(t)[p], mask.active(p) ? latent.frame_data(t)[p] : 0.0);
    }
  }
}

TEST(FusedObjective, RejectsAnUnderivedAlphaAndBadOptions) {
  const Scene scene = MakeRandomScene(Binning::kCollision, Activity::kAll, 71);
  const ActivityMask mask(scene.events, -1);
  ObjectiveOptions objective;  // α <= 0: "derive from the data"
  EXPECT_THROW(FusedObjective(scene, objective, mask), InvalidArgumentError);
  objective.event_model.alpha = 3.0;
  FusedObjectiveOptions options;
  options.num_threads = 0;
  EXPECT_THROW(FusedObjective(scene, objective, mask, options), InvalidArgumentError);
  const FusedObjective fused(scene, objective, mask);
  EXPECT_THROW(fused.Evaluate(Video(kHeight, kWidth + 1, kNumLatent), nullptr),
               InvalidArgumentError);
}

// The quadratic prior (plug & play) is built only by the Ceres problem.
TEST(FusedObjective, RejectsThePrior) {
  const Scene scene = MakeRandomScene(Binning::kCollision, Activity::kAll, 73);
  const ActivityMask mask(scene.events, -1);
  ObjectiveOptions objective;
  objective.event_model.alpha = 3.0;
  objective.prior_weight = 10.0;
  objective.prior_target = std::make_shared<const Video>(InitializeLatentVideo(scene));
  EXPECT_THROW(FusedObjective(scene, objective, mask), InvalidArgumentError);
}

}  // namespace
}  // namespace evfs
