#include "evfs/solver/objective_terms.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/scene/activity_mask.h"
#include "evfs/solver/problem_builder.h"
#include "evfs/tests/solver/solver_test_scenes.h"

namespace evfs {
namespace {

constexpr int kHeight = 4;
constexpr int kWidth = 5;
constexpr int kPixels = kHeight * kWidth;
constexpr int kNumLatent = 4;  // three collision steps

// The 5×4 scene of MakeSceneWithEvents, with one ON event per {step, y, x} given.
Scene MakeScene(const std::vector<std::array<int, 3>>& events) {
  return MakeSceneWithEvents(kHeight, kWidth, events);
}

ObjectiveOptions MakeObjective(SpatialTv form) {
  ObjectiveOptions objective;
  objective.frame_weight = 1.3;
  objective.event_weight = 0.7;
  objective.spatial_tv_weight = 2.0;
  objective.temporal_tv_weight = 1.5;
  objective.spatial_tv = form;
  objective.event_model.alpha = 5.0;
  return objective;
}

TEST(ObjectiveTerms, WeightsAreNormalisedByImageSizeAndSpatialTvByFrames) {
  const Scene scene = MakeScene({{1, 2, 3}});
  const ActivityMask mask(scene.events, /*radius_px=*/-1);
  const ObjectiveOptions objective = MakeObjective(SpatialTv::kAnisotropic);
  const ObjectiveTerms terms(scene, objective, mask);
  // Products and quotients of a few doubles: equal to within an ulp or two.
  EXPECT_DOUBLE_EQ(terms.weight(TermFamily::kFrame), 1.3 / kPixels);
  EXPECT_DOUBLE_EQ(terms.weight(TermFamily::kEvent), 0.7 / kPixels);
  EXPECT_DOUBLE_EQ(terms.weight(TermFamily::kSpatialTv), 2.0 / kPixels / kNumLatent);
  EXPECT_DOUBLE_EQ(terms.weight(TermFamily::kTemporalTv), 1.5 / kPixels);
  for (const TermFamily family :
       {TermFamily::kFrame, TermFamily::kEvent, TermFamily::kSpatialTv, TermFamily::kTemporalTv}) {
    EXPECT_TRUE(terms.has(family));
  }
}

TEST(ObjectiveTerms, CountsTermsOverVoxelsOfActivePixels) {
  const Scene scene = MakeScene({{1, 2, 3}});
  const ActivityMask every_pixel(scene.events, /*radius_px=*/-1);
  const ObjectiveTerms anisotropic(scene, MakeObjective(SpatialTv::kAnisotropic), every_pixel);
  EXPECT_EQ(anisotropic.num_terms(TermFamily::kFrame), 2 * kPixels);
  EXPECT_EQ(anisotropic.num_terms(TermFamily::kEvent), 3 * kPixels);
  // Horizontal (4 rows × 4) plus vertical (3 rows × 5) differences per frame.
  EXPECT_EQ(anisotropic.num_terms(TermFamily::kSpatialTv), kNumLatent * (4 * 4 + 3 * 5));
  EXPECT_EQ(anisotropic.num_terms(TermFamily::kTemporalTv), 3 * kPixels);
  // One three-point term per pixel with a right and a lower neighbour.
  const ObjectiveTerms paper(scene, MakeObjective(SpatialTv::kPaper), every_pixel);
  EXPECT_EQ(paper.num_terms(TermFamily::kSpatialTv), kNumLatent * (3 * 4));
}

TEST(ObjectiveTerms, ZeroWeightFamiliesHaveNoTerms) {
  const Scene scene = MakeScene({{1, 2, 3}});
  const ActivityMask mask(scene.events, /*radius_px=*/-1);
  // The ℓ1 families; the prior (kPrior, last) has weight 0 unless a target is given.
  const int prior = static_cast<int>(TermFamily::kPrior);
  for (int family = 0; family < prior; ++family) {
    ObjectiveOptions objective = MakeObjective(SpatialTv::kAnisotropic);
    double* weights[] = {&objective.frame_weight, &objective.event_weight,
                         &objective.spatial_tv_weight, &objective.temporal_tv_weight};
    *weights[family] = 0.0;
    SCOPED_TRACE("family " + std::to_string(family) + " has weight 0");
    const ObjectiveTerms terms(scene, objective, mask);
    for (int other = 0; other < kNumTermFamilies; ++other) {
      const TermFamily f = static_cast<TermFamily>(other);
      const bool expected = other != family && other != prior;
      EXPECT_EQ(terms.has(f), expected);
      EXPECT_EQ(terms.weight(f) > 0.0, expected);
      EXPECT_EQ(terms.num_terms(f) > 0, expected);
    }
    if (family == static_cast<int>(TermFamily::kSpatialTv)) {
      for (int64_t p = 0; p < kPixels; ++p) {
        EXPECT_FALSE(terms.spatial_tv_terms_at(p).right);
        EXPECT_FALSE(terms.spatial_tv_terms_at(p).below);
      }
    }
  }
}

TEST(ObjectiveTerms, OneLatentFrameHasNoTemporalTerms) {
  Scene scene;
  scene.height = kHeight;
  scene.width = kWidth;
  scene.events = EventFrames(kHeight, kWidth);
  scene.events.set_latent_timestamps_ns({0});
  scene.frames.push_back({Image::Constant(kHeight, kWidth, 0.2), 0, 0, "only"});
  ASSERT_EQ(scene.num_latent_frames(), 1);
  const ActivityMask mask(scene.events, /*radius_px=*/-1);
  const ObjectiveTerms terms(scene, MakeObjective(SpatialTv::kAnisotropic), mask);
  EXPECT_FALSE(terms.has(TermFamily::kTemporalTv));
  EXPECT_EQ(terms.weight(TermFamily::kTemporalTv), 0.0);
  EXPECT_EQ(terms.num_terms(TermFamily::kTemporalTv), 0);
  EXPECT_TRUE(terms.has(TermFamily::kFrame));
}

// One event at (y, x) = (2, 3) with radius 0: only that pixel is active. A spatial TV term
// exists when any pixel it touches is active, and belongs to its top-left pixel.
TEST(ObjectiveTerms, SpatialTvTermsTouchAnActivePixel) {
  const Scene scene = MakeScene({{1, 2, 3}});
  const ActivityMask mask(scene.events, /*radius_px=*/0);
  ASSERT_EQ(mask.num_active(), 1);
  const int64_t active = 2 * kWidth + 3;
  const int64_t left = active - 1, above = active - kWidth, above_left = above - 1;

  const ObjectiveTerms anisotropic(scene, MakeObjective(SpatialTv::kAnisotropic), mask);
  for (int64_t p = 0; p < kPixels; ++p) {
    const SpatialTvTermsAt owned = anisotropic.spatial_tv_terms_at(p);
    EXPECT_EQ(owned.right, p == active || p == left) << "pixel " << p;
    EXPECT_EQ(owned.below, p == active || p == above) << "pixel " << p;
  }
  EXPECT_EQ(anisotropic.num_terms(TermFamily::kSpatialTv), kNumLatent * 4);

  for (const SpatialTv form : {SpatialTv::kPaper, SpatialTv::kIsotropic}) {
    SCOPED_TRACE(SpatialTvName(form));
    const ObjectiveTerms three_point(scene, MakeObjective(form), mask);
    for (int64_t p = 0; p < kPixels; ++p) {
      const SpatialTvTermsAt owned = three_point.spatial_tv_terms_at(p);
      EXPECT_EQ(owned.right, p == active || p == left || p == above) << "pixel " << p;
      EXPECT_FALSE(owned.below) << "pixel " << p;
    }
    EXPECT_EQ(three_point.num_terms(TermFamily::kSpatialTv), kNumLatent * 3);
    EXPECT_EQ(three_point.spatial_tv_terms_at(above_left).right, false);
  }
  // Frame, event and temporal terms: the active pixel's only.
  EXPECT_EQ(anisotropic.num_terms(TermFamily::kFrame), 2);
  EXPECT_EQ(anisotropic.num_terms(TermFamily::kEvent), 3);
  EXPECT_EQ(anisotropic.num_terms(TermFamily::kTemporalTv), 3);
}

// The Ceres problem builds exactly these terms: with one parameter block per voxel, one
// residual block per term.
TEST(ObjectiveTerms, ProblemBuilderBuildsTheseTerms) {
  const Scene scene = MakeScene({{0, 1, 1}, {1, 2, 3}, {2, 2, 3}});
  for (const SpatialTv form : {SpatialTv::kPaper, SpatialTv::kAnisotropic, SpatialTv::kIsotropic}) {
    for (const int radius : {-1, 0, 1}) {
      SCOPED_TRACE(std::string(SpatialTvName(form)) + " radius " + std::to_string(radius));
      ReconstructionOptions options;
      options.objective = MakeObjective(form);
      options.activity_radius_px = radius;
      options.merge_quiet_steps = false;
      Video latent = InitializeLatentVideo(scene);
      options.objective.prior_weight = 3.0;
      options.objective.prior_target = std::make_shared<const Video>(latent);
      const auto built = ProblemBuilder(scene, options).Build(&latent);
      const ProblemStatistics& statistics = built->statistics();
      const ActivityMask mask(scene.events, radius);
      const ObjectiveTerms terms(scene, options.objective, mask);
      EXPECT_EQ(statistics.frame_residuals, terms.num_terms(TermFamily::kFrame));
      EXPECT_EQ(statistics.event_residuals, terms.num_terms(TermFamily::kEvent));
      EXPECT_EQ(statistics.spatial_tv_residuals, terms.num_terms(TermFamily::kSpatialTv));
      EXPECT_EQ(statistics.temporal_tv_residuals, terms.num_terms(TermFamily::kTemporalTv));
      EXPECT_EQ(statistics.prior_residuals, terms.num_terms(TermFamily::kPrior));
      EXPECT_EQ(statistics.prior_residuals, scene.num_latent_frames() * mask.num_active());
    }
  }
}

TEST(ObjectiveTerms, RejectsAMaskOfAnotherSize) {
  const Scene scene = MakeScene({{1, 2, 3}});
  const ActivityMask mask(EventFrames(kHeight + 1, kWidth), /*radius_px=*/-1);
  EXPECT_THROW(ObjectiveTerms(scene, MakeObjective(SpatialTv::kAnisotropic), mask),
               InvalidArgumentError);
}

TEST(ObjectiveTerms, PriorIsAMeanOverVoxelsAndNeedsATargetOfTheLatentSize) {
  const Scene scene = MakeScene({{1, 2, 3}});
  const ActivityMask mask(scene.events, /*radius_px=*/-1);
  ObjectiveOptions objective = MakeObjective(SpatialTv::kAnisotropic);
  objective.prior_weight = 5.0;
  std::string error;
  EXPECT_FALSE(objective.IsValid(&error)) << "a prior without a target";
  objective.prior_target = std::make_shared<const Video>(InitializeLatentVideo(scene));
  EXPECT_TRUE(objective.IsValid(&error)) << error;
  const ObjectiveTerms terms(scene, objective, mask);
  EXPECT_DOUBLE_EQ(terms.weight(TermFamily::kPrior), 5.0 / kPixels / kNumLatent);
  EXPECT_EQ(terms.num_terms(TermFamily::kPrior), kNumLatent * kPixels);

  Video short_target;
  short_target.AppendFrame(Image::Constant(kHeight, kWidth, 0.5), 0);
  objective.prior_target = std::make_shared<const Video>(short_target);
  EXPECT_THROW(ObjectiveTerms(scene, objective, mask), InvalidArgumentError);
}

TEST(ObjectiveTerms, SharedStructureOffsetsAreTheMinmodOfTheTwoFrames) {
  Scene scene = MakeScene({{1, 2, 3}});
  // Row 0 of the first frame rises by 0.1 per column, of the last by 0.3 (shared: 0.1); row 1
  // rises in the first and falls in the last (shared: none). Below: first frame's row 1 minus
  // row 0 is 0.2 at column 0, the last frame's 0.5 (shared: 0.2).
  Image& first = scene.frames[0].image;
  Image& last = scene.frames[1].image;
  first.setConstant(0.5);
  last.setConstant(0.5);
  for (int x = 0; x < kWidth; ++x) {
    first(0, x) = 0.1 + 0.1 * x;
    last(0, x) = 0.1 + 0.3 * x;
    first(1, x) = 0.3 + 0.05 * x;
    last(1, x) = 0.6 - 0.05 * x;
  }
  const ActivityMask mask(scene.events, /*radius_px=*/-1);
  ObjectiveOptions objective = MakeObjective(SpatialTv::kAnisotropic);
  objective.shared_structure_tv = false;
  EXPECT_FALSE(ObjectiveTerms(scene, objective, mask).has_spatial_tv_offsets());
  EXPECT_EQ(ObjectiveTerms(scene, objective, mask).spatial_tv_offset_at(0).right, 0.0);

  objective.shared_structure_tv = true;
  const ObjectiveTerms terms(scene, objective, mask);
  ASSERT_TRUE(terms.has_spatial_tv_offsets());
  // Rounded to the offset step: within half a step, and a whole number of steps.
  constexpr double kHalfStep = kSpatialTvOffsetStep / 2;
  EXPECT_NEAR(terms.spatial_tv_offset_at(0).right, 0.1, kHalfStep);
  EXPECT_NEAR(terms.spatial_tv_offset_at(2).right, 0.1, kHalfStep);
  const double steps = terms.spatial_tv_offset_at(2).right / kSpatialTvOffsetStep;
  EXPECT_EQ(steps, std::round(steps));
  EXPECT_EQ(terms.spatial_tv_offset_at(kWidth + 1).right, 0.0);      // opposite signs
  EXPECT_NEAR(terms.spatial_tv_offset_at(0).below, 0.2, kHalfStep);  // 0.3 − 0.1 and 0.6 − 0.1
  EXPECT_EQ(terms.spatial_tv_offset_at(kWidth - 1).right, 0.0);      // no right neighbour
  EXPECT_EQ(terms.spatial_tv_offset_at(kPixels - 1).below, 0.0);     // no lower neighbour
  // A falling edge in both frames: the smaller fall.
  first(3, 0) = 0.9;
  last(3, 0) = 0.7;
  const ObjectiveTerms falling(scene, objective, mask);
  EXPECT_NEAR(falling.spatial_tv_offset_at(3 * kWidth).right, 0.5 - 0.7, kHalfStep);
}

TEST(ObjectiveTerms, NoSharedStructureBetweenFramesThatShowNothingInPlace) {
  // A bright pixel at (1, 1) in the first frame and at (2, 3) in the last: the frames'
  // differences do not correlate (each frame's bump sits on the other's flat), so any sign
  // agreement is chance and TV stays plain. The same bump in both frames correlates fully.
  Scene scene = MakeScene({{1, 2, 3}});
  scene.frames[0].image(1, 1) = 0.9;
  scene.frames[1].image(2, 3) = 0.9;
  const ActivityMask mask(scene.events, /*radius_px=*/-1);
  ObjectiveOptions objective = MakeObjective(SpatialTv::kAnisotropic);
  objective.shared_structure_tv = true;
  const ObjectiveTerms moved(scene, objective, mask);
  EXPECT_LE(moved.shared_structure_correlation(), 0.0);
  EXPECT_FALSE(moved.has_spatial_tv_offsets());
  scene.frames[1].image(2, 3) = 0.6;
  scene.frames[1].image(1, 1) = 1.3;  // the same bump (+0.7 over its surround) in place
  const ObjectiveTerms in_place(scene, objective, mask);
  EXPECT_NEAR(in_place.shared_structure_correlation(), 1.0, 1e-12);
  EXPECT_TRUE(in_place.has_spatial_tv_offsets());
}

TEST(ObjectiveTerms, NoSharedStructureWithoutTwoSharpFrames) {
  Scene two_frames = MakeScene({{1, 2, 3}});
  two_frames.frames[0].image(1, 1) = two_frames.frames[1].image(1, 1) = 0.9;  // shared in place
  const ActivityMask mask(two_frames.events, /*radius_px=*/-1);
  ObjectiveOptions objective = MakeObjective(SpatialTv::kAnisotropic);
  objective.shared_structure_tv = true;
  EXPECT_TRUE(ObjectiveTerms(two_frames, objective, mask).has_spatial_tv_offsets());
  Scene one_frame = two_frames;  // a prediction: the first frame only
  one_frame.frames.pop_back();
  EXPECT_FALSE(ObjectiveTerms(one_frame, objective, mask).has_spatial_tv_offsets());
  Scene blurred = two_frames;  // the last frame blurred over the window
  blurred.frames[1].latent_first = 0;
  EXPECT_FALSE(ObjectiveTerms(blurred, objective, mask).has_spatial_tv_offsets());
  objective.spatial_tv_weight = 0.0;  // no spatial TV: nothing to measure
  EXPECT_FALSE(ObjectiveTerms(two_frames, objective, mask).has_spatial_tv_offsets());
}

}  // namespace
}  // namespace evfs
