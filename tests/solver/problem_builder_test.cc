#include "evfs/solver/problem_builder.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "evfs/tests/scene/scene_test_scenes.h"
#include "evfs/tests/solver/solver_test_scenes.h"

namespace evfs {
namespace {

// A 5×4 scene with one frame at each end and three collision steps whose events are set by
// hand, so that every count and the cost can be written down.
Scene MakeTinyScene() {
  Scene scene;
  scene.height = 4;
  scene.width = 5;
  scene.events = EventFrames(4, 5);
  for (int k = 0; k < 3; ++k) scene.events.AddFrame({k, k + 1, 10 * k, 10 * k + 5, 1});
  scene.events.set_latent_timestamps_ns({0, 10, 20, 30});
  scene.events.value(1, 2, 3) = 1.0f;
  scene.num_events = 1;
  scene.frames.push_back({Image::Constant(4, 5, 0.2), 0, 0, "first"});
  scene.frames.push_back({Image::Constant(4, 5, 0.6), 3, 3, "last"});
  return scene;
}

TEST(ProblemBuilder, BuildsOneResidualPerTermAndPixel) {
  const Scene scene = MakeTinyScene();
  ReconstructionOptions options;
  options.objective.event_model.alpha = 5.0;
  options.activity_radius_px = -1;    // every pixel
  options.merge_quiet_steps = false;  // one parameter block per voxel
  Video latent = InitializeLatentVideo(scene);
  const auto built = ProblemBuilder(scene, options).Build(&latent);
  const ProblemStatistics& stats = built->statistics();
  constexpr int kPixels = 20, kLatent = 4, kSteps = 3;
  EXPECT_EQ(stats.parameter_blocks, kPixels * kLatent);
  EXPECT_EQ(stats.frame_residuals, 2 * kPixels);
  EXPECT_EQ(stats.event_residuals, kSteps * kPixels);
  // Anisotropic TV: horizontal (4 rows × 4) plus vertical (3 rows × 5) differences per frame.
  EXPECT_EQ(stats.spatial_tv_residuals, kLatent * (4 * 4 + 3 * 5));
  EXPECT_EQ(stats.temporal_tv_residuals, kSteps * kPixels);
  EXPECT_EQ(built->problem().NumResidualBlocks(), stats.residual_blocks());
  // Shared cost functions: 2 frame values, 2 event values (0 and 1), TV difference (spatial
  // and temporal each keep their own).
  EXPECT_EQ(stats.distinct_cost_functions, 2 + 2 + 1 + 1);
}

TEST(ProblemBuilder, ZeroWeightTermsAreNotBuilt) {
  const Scene scene = MakeTinyScene();
  ReconstructionOptions options;
  options.objective.event_model.alpha = 5.0;
  options.activity_radius_px = -1;
  options.merge_quiet_steps = false;
  options.objective.spatial_tv_weight = 0.0;
  options.objective.temporal_tv_weight = 0.0;
  Video latent = InitializeLatentVideo(scene);
  const auto built = ProblemBuilder(scene, options).Build(&latent);
  EXPECT_EQ(built->statistics().spatial_tv_residuals, 0);
  EXPECT_EQ(built->statistics().temporal_tv_residuals, 0);
  EXPECT_EQ(built->problem().NumResidualBlocks(), 20 * 2 + 20 * 3);
}

TEST(ProblemBuilder, CostMatchesTheObjectiveWrittenOut) {
  // Only the frame term on a blend: each frame is matched exactly except that the latent ends
  // are shifted by 0.1, so the cost is w × 2 frames × 20 pixels × (sqrt(ε² + 0.1²) − ε) / 20.
  const Scene scene = MakeTinyScene();
  ReconstructionOptions options;
  options.objective.event_model.alpha = 5.0;
  options.activity_radius_px = -1;
  options.merge_quiet_steps = false;
  options.objective.event_weight = 0.0;
  options.objective.spatial_tv_weight = 0.0;
  options.objective.temporal_tv_weight = 0.0;
  Video latent = InitializeLatentVideo(scene);
  latent.frame(0) += 0.1;
  latent.frame(3) -= 0.1;
  const auto built = ProblemBuilder(scene, options).Build(&latent);
  double cost = 0.0;
  built->problem().Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr);
  const double eps = options.objective.smoothing_scale;
  const double expected =
      options.objective.frame_weight * 2.0 * (std::sqrt(eps * eps + 0.01) - eps);
  constexpr double kTolerance = 1e-12;  // a handful of double additions
  EXPECT_NEAR(cost, expected, kTolerance);
}

TEST(ProblemBuilder, PixelsFarFromEventsAreSkipped) {
  // The only event is at (x 3, y 2); with radius 1 the active pixels are x 2..4, y 1..3 (9).
  const Scene scene = MakeTinyScene();
  ReconstructionOptions options;
  options.objective.event_model.alpha = 5.0;
  options.activity_radius_px = 1;
  options.merge_quiet_steps = false;
  Video latent = InitializeLatentVideo(scene);
  const auto built = ProblemBuilder(scene, options).Build(&latent);
  const ProblemStatistics& stats = built->statistics();
  constexpr int kActive = 9, kLatent = 4, kSteps = 3;
  EXPECT_EQ(stats.active_pixels, kActive);
  EXPECT_EQ(stats.skipped_pixels, 20 - kActive);
  EXPECT_EQ(stats.frame_residuals, 2 * kActive);
  EXPECT_EQ(stats.event_residuals, kSteps * kActive);
  EXPECT_EQ(stats.temporal_tv_residuals, kSteps * kActive);
  // Ring: columns x = 1 for rows 0..3 (4) and row y = 0 for x = 2..4 (3): 7 constant pixels.
  EXPECT_EQ(stats.parameter_blocks, kLatent * (kActive + 7));
  // Horizontal differences touching an active pixel: rows 1..3 × pairs (1,2),(2,3),(3,4) = 9;
  // vertical: columns 2..4 × pairs (0,1),(1,2),(2,3) = 9; per latent frame.
  EXPECT_EQ(stats.spatial_tv_residuals, kLatent * (9 + 9));
}

TEST(ProblemBuilder, RingPixelsAreOneConstantWhileTheirInitialValueHolds) {
  // Radius 1: 9 active pixels and 7 ring pixels (PixelsFarFromEventsAreSkipped). The blend
  // moves every ring pixel by 0.4 / 3 per latent frame: 0.2, 0.333, 0.467, 0.6.
  const Scene scene = MakeTinyScene();
  ReconstructionOptions options;
  options.objective.event_model.alpha = 5.0;
  options.activity_radius_px = 1;
  const auto build = [&](double tolerance, Video* latent) {
    options.ring_tolerance = tolerance;
    return ProblemBuilder(scene, options).Build(latent);
  };
  Video every_change = InitializeLatentVideo(scene);
  Video one_constant = every_change, two_constants = every_change;
  const auto exact = build(0.0, &every_change);   // a constant per latent frame
  const auto held = build(0.5, &one_constant);    // one constant per ring pixel
  const auto split = build(0.2, &two_constants);  // frames 0..1 and 2..3
  const int64_t unknowns = exact->statistics().variable_parameter_blocks;
  EXPECT_EQ(held->statistics().variable_parameter_blocks, unknowns);
  EXPECT_EQ(split->statistics().variable_parameter_blocks, unknowns);
  EXPECT_EQ(exact->statistics().parameter_blocks, unknowns + 7 * 4);
  EXPECT_EQ(held->statistics().parameter_blocks, unknowns + 7);
  EXPECT_EQ(split->statistics().parameter_blocks, unknowns + 7 * 2);
  // Each ring constant cuts the spatial TV runs of its active neighbours.
  EXPECT_LT(held->statistics().spatial_tv_residuals, split->statistics().spatial_tv_residuals);
  EXPECT_LT(split->statistics().spatial_tv_residuals, exact->statistics().spatial_tv_residuals);

  // The problem sees each constant's mean; the ring's voxels keep their own values.
  const LatentLayout& layout = split->layout();
  const int64_t ring = 1;  // (y 0, x 1)
  const double step = 0.4 / 3.0;
  EXPECT_NEAR(*layout.value(layout.segment_at(0, ring), &two_constants), 0.2 + step / 2, 1e-12);
  EXPECT_NEAR(*layout.value(layout.segment_at(3, ring), &two_constants), 0.6 - step / 2, 1e-12);
  layout.Expand(&two_constants);
  for (int t = 0; t < 4; ++t) EXPECT_NEAR(two_constants.at(t, 0, 1), 0.2 + step * t, 1e-12);
}

TEST(ProblemBuilder, MergedLayoutHasOneUnknownPerQuietRun) {
  // The one event (x 3, y 2, step 1 → 2) splits its pixel into H_0..1 and H_2..3; every other
  // pixel is one constant-in-time unknown.
  const Scene scene = MakeTinyScene();
  ReconstructionOptions options;
  options.objective.event_model.alpha = 5.0;
  options.activity_radius_px = -1;
  Video latent = InitializeLatentVideo(scene);
  const auto built = ProblemBuilder(scene, options).Build(&latent);
  const ProblemStatistics& stats = built->statistics();
  EXPECT_EQ(stats.parameter_blocks, 19 + 2);
  EXPECT_EQ(stats.variable_parameter_blocks, 19 + 2);
  EXPECT_EQ(stats.frame_residuals, 2 * 20);
  EXPECT_EQ(stats.event_residuals, 1);
  EXPECT_EQ(stats.temporal_tv_residuals, 1);
  // 31 neighbour pairs, one run each, except the 4 pairs of the split pixel (two runs each).
  EXPECT_EQ(stats.spatial_tv_residuals, 31 + 4);
  // Each unknown starts at the mean of the blend over its frames.
  EXPECT_NEAR(latent.at(0, 0, 0), 0.4, 1e-12);
  EXPECT_NEAR(latent.at(3, 0, 0), 0.4, 1e-12);
  EXPECT_NEAR(latent.at(1, 2, 3), 0.2 + 0.4 / 6.0, 1e-12);
  EXPECT_NEAR(latent.at(2, 2, 3), 0.6 - 0.4 / 6.0, 1e-12);
}

// Prediction (one frame, at latent frame 0) on a 5×6 scene: (2, 2) fires at steps 0 and 2,
// (2, 3) at step 2. An unfired pixel with at least two events at its 8 neighbours changes once,
// at the event frame of their median; with one (or none) it stays one constant; the change has
// no event residual.
TEST(ProblemBuilder, UnfiredPixelsChangeOnceWhereTheirNeighboursFireAfterTheLastFrame) {
  Scene scene = MakeSceneWithEvents(5, 6, {{0, 2, 2}, {2, 2, 2}, {2, 2, 3}});
  scene.frames.pop_back();
  ReconstructionOptions options;
  options.objective.event_model.alpha = 5.0;
  options.activity_radius_px = -1;
  const auto pixel = [&](int y, int x) { return static_cast<int64_t>(y) * scene.width + x; };

  Video latent = InitializeLatentVideo(scene);
  const auto built = ProblemBuilder(scene, options).Build(&latent);
  const LatentLayout& layout = built->layout();
  // Segments of pixel p: the latent frames where one starts.
  const auto starts = [&](const LatentLayout& of, int64_t p) {
    std::vector<int> frames;
    for (int t = 1; t < scene.num_latent_frames(); ++t) {
      if (of.segment_at(t, p) != of.segment_at(t - 1, p)) frames.push_back(t);
    }
    return frames;
  };
  // (1, 2) sees steps 0, 2, 2 (median 2); (1, 1) steps 0, 2 (median: the second, 2).
  EXPECT_EQ(starts(layout, pixel(1, 2)), std::vector<int>{3});
  EXPECT_TRUE(layout.segment(layout.segment_at(3, pixel(1, 2))).unfired_change);
  EXPECT_EQ(starts(layout, pixel(1, 1)), std::vector<int>{3});
  EXPECT_EQ(starts(layout, pixel(3, 3)), std::vector<int>{3});
  // One event next to it, or none: constant.
  EXPECT_TRUE(starts(layout, pixel(1, 4)).empty());
  EXPECT_TRUE(starts(layout, pixel(0, 0)).empty());
  // The pixels that fired keep their own segments, not flagged.
  EXPECT_EQ(starts(layout, pixel(2, 2)), (std::vector<int>{1, 3}));
  EXPECT_FALSE(layout.segment(layout.segment_at(3, pixel(2, 2))).unfired_change);
  EXPECT_EQ(built->statistics().event_residuals, 3);

  options.unfired_pixel_changes = false;
  Video constant_latent = InitializeLatentVideo(scene);
  const auto constant = ProblemBuilder(scene, options).Build(&constant_latent);
  EXPECT_TRUE(starts(constant->layout(), pixel(1, 2)).empty());
  EXPECT_EQ(constant->statistics().event_residuals, 3);
  EXPECT_LT(constant->statistics().variable_parameter_blocks,
            built->statistics().variable_parameter_blocks);

  // A frame at the end pins every pixel: no change.
  options.unfired_pixel_changes = true;
  const Scene interpolation = MakeSceneWithEvents(5, 6, {{0, 2, 2}, {2, 2, 2}, {2, 2, 3}});
  Video pinned_latent = InitializeLatentVideo(interpolation);
  const auto pinned = ProblemBuilder(interpolation, options).Build(&pinned_latent);
  EXPECT_TRUE(starts(pinned->layout(), pixel(1, 2)).empty());
}

TEST(ActivityMask, IndependentPartsAreConnectedRegionsOfTheProblem) {
  // Radius 1: events at (y 2, x 2) and (y 2, x 5) give active squares whose rings touch (one
  // region); the event at (y 2, x 14) is far from both (a second region).
  const Scene scene = MakeSceneWithEvents(6, 18, {{0, 2, 2}, {1, 2, 5}, {2, 2, 14}});
  const ActivityMask mask(scene.events, 1);
  const std::vector<std::vector<int64_t>> parts = mask.IndependentParts(1);
  ASSERT_EQ(parts.size(), 2u);
  // Active x 1..6 plus ring x 0..7, rows 0..4: 40 pixels; active x 13..15 plus ring: 25.
  EXPECT_EQ(parts[0].size(), 40u);
  EXPECT_EQ(parts[1].size(), 25u);
  for (const auto& part : parts) {
    EXPECT_TRUE(std::is_sorted(part.begin(), part.end()));
    for (const int64_t p : part) EXPECT_TRUE(mask.in_problem(p));
  }
  EXPECT_EQ(parts[1].front(), 12);  // (y 0, x 12), the corner of the second region's ring
  // Regions below the minimum size are packed into one part.
  EXPECT_EQ(mask.IndependentParts(41).size(), 1u);
  EXPECT_EQ(mask.IndependentParts(41).front().size(), 65u);
}

// Regression: a radius of 2^31 - 239 or more overflowed int in the dilation and
// crashed (SIGSEGV). Any radius beyond the sensor makes every pixel active, like the sensor size.
TEST(ActivityMask, RadiusBeyondTheSensorMakesEveryPixelActive) {
  const Scene scene = MakeSceneWithEvents(6, 18, {{0, 2, 2}});
  const ActivityMask small(scene.events, 1);
  EXPECT_EQ(small.num_active(), 9);
  for (const int radius :
       {18, 1000, std::numeric_limits<int>::max() - 238, std::numeric_limits<int>::max()}) {
    const ActivityMask mask(scene.events, radius);
    EXPECT_EQ(mask.num_active(), 6 * 18) << radius;
  }
  // With no event nothing is active, whatever the radius.
  const Scene quiet = MakeSceneWithEvents(6, 18, {});
  EXPECT_EQ(ActivityMask(quiet.events, std::numeric_limits<int>::max()).num_active(), 0);
}

TEST(ProblemBuilder, PartsSplitTheWholeProblemExactly) {
  // Every term lands in exactly one part: counts and costs add up to the one problem's.
  const Scene scene = MakeSceneWithEvents(6, 18, {{0, 2, 2}, {1, 2, 5}, {2, 2, 14}});
  for (const bool merge : {false, true}) {
    for (const SpatialTv tv : {SpatialTv::kAnisotropic, SpatialTv::kPaper}) {
      SCOPED_TRACE(std::string(merge ? "merged" : "per voxel") + ", " + SpatialTvName(tv));
      ReconstructionOptions options;
      options.objective.event_model.alpha = 5.0;
      options.objective.spatial_tv = tv;
      options.activity_radius_px = 1;
      options.merge_quiet_steps = merge;
      options.min_part_pixels = 1;
      Video whole_latent = InitializeLatentVideo(scene);
      Video parts_latent = whole_latent;
      const ProblemBuilder builder(scene, options);
      const auto whole = builder.Build(&whole_latent);
      const auto parts = builder.BuildParts(&parts_latent, 2);
      ASSERT_EQ(parts.size(), 2u);
      ProblemStatistics sum;
      sum.parts = 0;
      double cost_sum = 0.0;
      for (const auto& part : parts) {
        sum += part->statistics();
        double cost = 0.0;
        part->problem().Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr,
                                 nullptr);
        cost_sum += cost;
      }
      const ProblemStatistics& one = whole->statistics();
      EXPECT_EQ(sum.parts, 2);
      EXPECT_EQ(sum.parameter_blocks, one.parameter_blocks);
      EXPECT_EQ(sum.variable_parameter_blocks, one.variable_parameter_blocks);
      EXPECT_EQ(sum.frame_residuals, one.frame_residuals);
      EXPECT_EQ(sum.event_residuals, one.event_residuals);
      EXPECT_EQ(sum.spatial_tv_residuals, one.spatial_tv_residuals);
      EXPECT_EQ(sum.temporal_tv_residuals, one.temporal_tv_residuals);
      EXPECT_EQ(sum.active_pixels, one.active_pixels);
      double whole_cost = 0.0;
      whole->problem().Evaluate(ceres::Problem::EvaluateOptions(), &whole_cost, nullptr, nullptr,
                                nullptr);
      EXPECT_NEAR(cost_sum, whole_cost, 1e-12 * whole_cost);
    }
  }
}

// Cost and gradient of `problem` at its current values, the gradient in `blocks`' order.
double EvaluateProblem(ceres::Problem* problem, const std::vector<double*>& blocks,
                       std::vector<double>* gradient) {
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = blocks;
  evaluate.num_threads = 1;
  double cost = 0.0;
  problem->Evaluate(evaluate, &cost, nullptr, gradient, nullptr);
  return cost;
}

TEST(ProblemBuilder, MergedProblemIsTheFullProblemOnSegmentConstantVideos) {
  // On any video constant over each segment, the merged problem has the full problem's cost,
  // and its gradient is the sum of the full gradient over each segment's voxels.
  const test::SyntheticRecording recording(24, 20, 0.012);
  TimedFrame blurred = recording.Blurred(6, 12);  // a mixed scene: sharp first, blurred last
  const Scene scene =
      MakeScene({recording.Sharp(0), blurred}, recording.events, recording.rendered.timestamp_ns(0),
                recording.rendered.timestamp_ns(12) + 1, BinningOptions());
  ReconstructionOptions options;
  options.objective.event_model.alpha = 8.0;
  // An unfired pixel's change has no event residual, by design a different objective (tested
  // in UnfiredPixelsChangeOnce...): compare the plain merge.
  options.unfired_pixel_changes = false;
  // The full problem sees every ring voxel: so must the merged one.
  options.ring_tolerance = 0.0;
  Video merged_video = InitializeLatentVideo(scene);
  const auto merged = ProblemBuilder(scene, options).Build(&merged_video);
  const LatentLayout& layout = merged->layout();
  ASSERT_LT(layout.num_variable_segments(),
            merged->statistics().active_pixels * scene.num_latent_frames());
  // Move every unknown to a pseudo-random value in [0.1, 0.9].
  std::vector<double*> segment_blocks;
  for (int64_t s = 0; s < layout.num_segments(); ++s) {
    if (layout.segment(s).constant) continue;
    double* value = layout.value(s, &merged_video);
    *value = 0.1 + 0.8 * std::fmod(0.618034 * static_cast<double>(s), 1.0);
    segment_blocks.push_back(value);
  }
  layout.Expand(&merged_video);

  options.merge_quiet_steps = false;
  Video full_video = merged_video;
  const auto full = ProblemBuilder(scene, options).Build(&full_video);
  std::vector<double*> voxel_blocks;
  for (int64_t s = 0; s < layout.num_segments(); ++s) {
    const LatentLayout::Segment& segment = layout.segment(s);
    if (segment.constant) continue;
    for (int t = segment.first; t <= segment.last; ++t) {
      voxel_blocks.push_back(full_video.frame_data(t) + segment.pixel);
    }
  }
  std::vector<double> merged_gradient, full_gradient;
  const double merged_cost = EvaluateProblem(&merged->problem(), segment_blocks, &merged_gradient);
  const double full_cost = EvaluateProblem(&full->problem(), voxel_blocks, &full_gradient);
  EXPECT_NEAR(merged_cost, full_cost, 1e-12 * full_cost);
  size_t voxel = 0;
  double max_difference = 0.0, max_gradient = 0.0;
  for (size_t i = 0, s = 0; s < static_cast<size_t>(layout.num_segments()); ++s) {
    const LatentLayout::Segment& segment = layout.segment(s);
    if (segment.constant) continue;
    double sum = 0.0;
    for (int t = segment.first; t <= segment.last; ++t) sum += full_gradient[voxel++];
    max_difference = std::max(max_difference, std::abs(sum - merged_gradient[i]));
    max_gradient = std::max(max_gradient, std::abs(sum));
    ++i;
  }
  EXPECT_GT(max_gradient, 0.0);
  EXPECT_LE(max_difference, 1e-9 * max_gradient);
}

TEST(ProblemBuilder, InitialisationBlendsLinearlyInTime) {
  const Scene scene = MakeTinyScene();
  const Video latent = InitializeLatentVideo(scene);
  ASSERT_EQ(latent.num_frames(), 4);
  EXPECT_NEAR(latent.at(0, 1, 1), 0.2, 1e-12);
  EXPECT_NEAR(latent.at(1, 1, 1), 0.2 + 0.4 / 3.0, 1e-12);
  EXPECT_NEAR(latent.at(3, 1, 1), 0.6, 1e-12);
  EXPECT_EQ(latent.timestamp_ns(2), 20);
}

// With a budget below the whole problem's estimate, an all-active scene (one part) is cut into
// bands of rows that cover every row, each estimated within the budget; a band's unknowns are
// its own rows', and the rows next to it are in its problem held constant.
TEST(ProblemBuilder, BandsCoverEveryRowWithinTheBudget) {
  const Scene scene = MakeSceneWithEvents(40, 18, {{0, 2, 2}, {1, 20, 5}, {2, 37, 14}});
  for (const SpatialTv tv : {SpatialTv::kAnisotropic, SpatialTv::kPaper}) {
    SCOPED_TRACE(SpatialTvName(tv));
    ReconstructionOptions options;
    options.objective.event_model.alpha = 5.0;
    options.objective.spatial_tv = tv;
    options.activity_radius_px = -1;
    Video latent = InitializeLatentVideo(scene);
    const ProblemBuilder builder(scene, options);
    const ProblemPlan whole = builder.Plan(&latent, -1);
    ASSERT_EQ(whole.batches().size(), 1u);
    ASSERT_EQ(whole.batches()[0].size(), 1u);
    EXPECT_FALSE(whole.batches()[0][0].band);
    const int64_t budget = whole.estimated_bytes() / 3;
    const ProblemPlan plan = builder.Plan(&latent, budget);
    ASSERT_GE(plan.batches().size(), 3u);
    int next_row = 0;  // every row is solved by some band, in order
    for (const std::vector<ProblemUnit>& batch : plan.batches()) {
      ASSERT_EQ(batch.size(), 1u);
      const ProblemUnit& band = batch[0];
      EXPECT_TRUE(band.band);
      EXPECT_LE(band.row_begin, next_row);
      EXPECT_GT(band.row_end, next_row);
      next_row = band.row_end;
      EXPECT_LE(band.estimated_bytes, budget);
      const auto built = builder.BuildUnit(plan, band, &latent);
      ceres::Problem& problem = built->problem();
      std::vector<double*> blocks;
      problem.GetParameterBlocks(&blocks);
      for (double* block : blocks) {
        int row = -1;
        for (int t = 0; t < latent.num_frames(); ++t) {
          const int64_t p = block - latent.frame_data(t);
          if (p >= 0 && p < int64_t{scene.height} * scene.width) row = p / scene.width;
        }
        ASSERT_GE(row, 0);
        const bool own = row >= band.row_begin && row < band.row_end;
        EXPECT_EQ(problem.IsParameterBlockConstant(block), !own) << "row " << row;
        EXPECT_GE(row, band.row_begin - 1);
        EXPECT_LE(row, band.row_end);
      }
      EXPECT_EQ(built->statistics().active_pixels,
                static_cast<int64_t>(band.row_end - band.row_begin) * scene.width);
    }
    EXPECT_EQ(next_row, scene.height);
  }
}

}  // namespace
}  // namespace evfs
