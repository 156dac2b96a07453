#include "evfs/solver/reconstructor.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/core/metrics.h"
#include "evfs/scene/activity_mask.h"
#include "evfs/tests/scene/scene_test_scenes.h"
#include "evfs/tests/solver/solver_test_scenes.h"

namespace evfs {
namespace {

// Every voxel of a video, as one array.
Eigen::Map<const Eigen::ArrayXd> VoxelValues(const Video& video) {
  return Eigen::Map<const Eigen::ArrayXd>(video.data(),
                                          int64_t{video.num_frames()} * video.pixels_per_frame());
}

// Quality bars on the 48×40 synthetic scene, about 2 dB below what the default options reach
// (printed by the tests: +6.7, +8.0 and +4.3 dB when they were set) so that they catch
// regressions, not noise.
constexpr double kMinGainOverBlendDb = 4.5;
constexpr double kMinGainOverCopyDb = 6.0;
constexpr double kMinGainOverBlurredDb = 2.5;

double PsnrAt(const Video& video, const test::SyntheticRecording& recording, int truth) {
  const int index = video.NearestFrame(recording.rendered.timestamp_ns(truth));
  return Psnr(video.frame(index), recording.rendered.frame(truth));
}

TEST(Reconstructor, InterpolationBeatsTheBlend) {
  const test::SyntheticRecording recording;
  const Scene scene = MakeInterpolationScene(recording.Sharp(0), recording.Sharp(20),
                                             recording.events, BinningOptions());
  const Reconstruction result = Reconstruct(scene, ReconstructionOptions());
  ASSERT_TRUE(result.summary.solved);
  EXPECT_TRUE(result.summary.alpha_derived);
  EXPECT_GT(result.summary.model.alpha, 0.0);
  EXPECT_LE(result.summary.final_cost, result.summary.initial_cost);
  const double blend = PsnrAt(InitializeLatentVideo(scene), recording, 10);
  const double solved = PsnrAt(result.video, recording, 10);
  std::printf("interpolation: blend %.2f dB, evfs %.2f dB\n", blend, solved);
  EXPECT_GE(solved, blend + kMinGainOverBlendDb);
}

TEST(Reconstructor, AnInitialVideoHandedOverSolvesAsOnePointedTo) {
  const test::SyntheticRecording recording;
  const Scene scene = MakeInterpolationScene(recording.Sharp(0), recording.Sharp(20),
                                             recording.events, BinningOptions());
  Video initial = InitializeLatentVideo(scene);
  initial.frame(initial.num_frames() / 2).array() += 0.05;
  ReconstructionOptions options;
  options.solver.num_threads = 1;  // the same sums in the same order: equal to the last bit
  const Reconstruction pointed = Reconstruct(scene, options, &initial);
  const Reconstruction handed = Reconstruct(scene, options, Video(initial));
  ASSERT_TRUE(handed.summary.solved);
  EXPECT_EQ(handed.summary.initial_cost, pointed.summary.initial_cost);
  EXPECT_EQ(handed.summary.final_cost, pointed.summary.final_cost);
  EXPECT_TRUE((VoxelValues(handed.video) == VoxelValues(pointed.video)).all());
  EXPECT_THROW(Reconstruct(scene, ReconstructionOptions(), Video(scene.height, scene.width, 2)),
               InvalidArgumentError);
}

TEST(Reconstructor, SharedStructureTvKeepsTheTextureBothFramesShow) {
  // A static random texture that both frames show, two events and every pixel active: plain
  // spatial TV flattens the texture between the frames, TV measured from the structure the
  // frames share keeps it.
  constexpr int kTextureHeight = 12, kTextureWidth = 14;
  std::mt19937 random(7);
  std::uniform_real_distribution<double> level(0.3, 0.7);
  Image texture(kTextureHeight, kTextureWidth);
  for (int i = 0; i < texture.size(); ++i) texture.data()[i] = level(random);
  Scene scene = MakeSceneWithEvents(kTextureHeight, kTextureWidth, {{1, 5, 6}, {2, 6, 7}});
  scene.frames[0].image = texture;
  scene.frames[1].image = texture;
  ReconstructionOptions options;
  options.activity_radius_px = -1;
  options.objective.event_model.alpha = 0.5;
  const auto middle_psnr = [&](bool shared_structure_tv) {
    options.objective.shared_structure_tv = shared_structure_tv;
    const Reconstruction result = Reconstruct(scene, options);
    EXPECT_TRUE(result.summary.solved);
    return Psnr(result.video.frame(1), texture);
  };
  const double plain = middle_psnr(false);
  const double shared = middle_psnr(true);
  std::printf("texture between two frames: plain TV %.2f dB, shared structure %.2f dB\n", plain,
              shared);
  EXPECT_GE(shared, plain + 10.0);
}

TEST(Reconstructor, PredictionBeatsTheCopy) {
  const test::SyntheticRecording recording;
  const Scene scene = MakePredictionScene(recording.Sharp(0), recording.rendered.timestamp_ns(10),
                                          recording.events, BinningOptions());
  const Reconstruction result = Reconstruct(scene, ReconstructionOptions());
  const double copy = PsnrAt(InitializeLatentVideo(scene), recording, 10);
  const double solved = PsnrAt(result.video, recording, 10);
  std::printf("prediction: copy %.2f dB, evfs %.2f dB\n", copy, solved);
  EXPECT_GE(solved, copy + kMinGainOverCopyDb);
}

TEST(Reconstructor, MixedSharpAndBlurredObservationsSolveTogether) {
  // A sharp frame at the start and a frame blurred over the second half of the window: neither
  // preset, the same code path.
  const test::SyntheticRecording recording;
  BinningOptions binning;
  binning.method = BinningOptions::Method::kStacked;
  binning.stacked.num_frames = 20;
  const Scene scene =
      MakeScene({recording.Sharp(0), recording.Blurred(10, 20)}, recording.events,
                recording.rendered.timestamp_ns(0), recording.rendered.timestamp_ns(20), binning);
  ASSERT_EQ(scene.frames.size(), 2u);
  EXPECT_EQ(scene.frames[1].latent_first, 10);
  EXPECT_EQ(scene.frames[1].latent_last, 20);
  const Reconstruction result = Reconstruct(scene, ReconstructionOptions());
  ASSERT_TRUE(result.summary.solved);
  // The end of the window is inside the blurred exposure: the solve must sharpen it.
  const double blurred = Psnr(recording.Blurred(10, 20).image, recording.rendered.frame(20));
  const double solved = PsnrAt(result.video, recording, 20);
  std::printf("mixed: blurred frame %.2f dB, evfs %.2f dB at its end\n", blurred, solved);
  EXPECT_GE(solved, blurred + kMinGainOverBlurredDb);
}

TEST(Reconstructor, WindowWithoutEventsIsAnsweredWithoutSolving) {
  const test::SyntheticRecording recording;
  const EventStream no_events(recording.events.width(), recording.events.height());
  const Scene scene =
      MakeInterpolationScene(recording.Sharp(0), recording.Sharp(20), no_events, BinningOptions());
  ReconstructionOptions options;
  options.objective.event_model.alpha = 5.0;
  const Reconstruction result = Reconstruct(scene, options);
  EXPECT_FALSE(result.summary.solved);
  EXPECT_FALSE(result.summary.skipped_reason.empty());
  EXPECT_EQ(result.video.num_frames(), 2);
}

TEST(Reconstructor, ContinuationOnTheSmoothingScaleEndsOnTheObjectivesOwn) {
  const test::SyntheticRecording recording;
  const Scene scene = MakeInterpolationScene(recording.Sharp(0), recording.Sharp(20),
                                             recording.events, BinningOptions());
  ReconstructionOptions options;
  options.objective.event_model.alpha = 5.0;
  const Reconstruction plain = Reconstruct(scene, options);
  options.smoothing_continuation = {0.3, 0.1};
  const Reconstruction continued = Reconstruct(scene, options);
  ASSERT_TRUE(continued.summary.solved);
  // Three solves: more iterations in all, and the last one's cost is the objective's own.
  EXPECT_GT(continued.summary.iterations, plain.summary.iterations);
  EXPECT_NEAR(continued.summary.final_cost, plain.summary.final_cost,
              0.05 * plain.summary.final_cost);
  EXPECT_NEAR(PsnrAt(continued.video, recording, 10), PsnrAt(plain.video, recording, 10), 1.0);
  options.smoothing_continuation = {0.3, 0.0};
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("smoothing_continuation"), std::string::npos) << error;
}

// A callback that stops the solve stops it whole: with a smoothing continuation, no later scale
// is built and solved (a caller that stops on Ctrl-C would otherwise wait for every scale's
// build and first iteration).
TEST(Reconstructor, CallbackThatStopsEndsTheContinuation) {
  const test::SyntheticRecording recording;
  const Scene scene = MakeInterpolationScene(recording.Sharp(0), recording.Sharp(20),
                                             recording.events, BinningOptions());
  ReconstructionOptions options;
  options.objective.event_model.alpha = 5.0;
  options.smoothing_continuation = {0.3, 0.1};
  int calls = 0;
  Reconstruct(scene, options, nullptr, [&](const SolverIteration&) {
    ++calls;
    return false;
  });
  EXPECT_EQ(calls, 1);
}

// A start Ceres cannot evaluate (NaN intensities) ends its solve with FAILURE: a solver
// failure, not an invalid argument of the user's.
TEST(Reconstructor, CeresFailureIsASolverError) {
  const test::SyntheticRecording recording;
  const Scene scene = MakeInterpolationScene(recording.Sharp(0), recording.Sharp(20),
                                             recording.events, BinningOptions());
  ReconstructionOptions options;
  options.objective.event_model.alpha = 5.0;
  Video initial = InitializeLatentVideo(scene);
  initial.frame(initial.num_frames() / 2).setConstant(std::nan(""));
  try {
    Reconstruct(scene, options, &initial);
    ADD_FAILURE() << "the solve did not fail";
  } catch (const SolverError& error) {
    EXPECT_NE(std::string(error.what()).find("the solver failed: "), std::string::npos)
        << error.what();
  } catch (const std::exception& error) {
    ADD_FAILURE() << "not a SolverError: " << error.what();
  }
}

// Two shapes far apart on a wide sensor: two independent regions, each its own part.
Scene TwoRegionScene(const test::SyntheticRecording& recording) {
  return MakeInterpolationScene(recording.Sharp(0), recording.Sharp(20), recording.events,
                                BinningOptions());
}

ReconstructionOptions EveryRegionAPart() {
  ReconstructionOptions options;
  options.objective.event_model.alpha = 5.0;
  options.min_part_pixels = 1;
  return options;
}

TEST(Reconstructor, IndependentPartsReachTheOneProblemsSolution) {
  const test::SyntheticRecording recording(/*width=*/120, /*height=*/40);
  const Scene scene = TwoRegionScene(recording);
  ReconstructionOptions options = EveryRegionAPart();
  options.solver.function_tolerance = 1e-8;  // both run to convergence
  options.solver.max_num_iterations = 100;
  const Reconstruction split = Reconstruct(scene, options);
  options.split_independent_parts = false;
  const Reconstruction whole = Reconstruct(scene, options);
  ASSERT_GE(split.summary.problem.parts, 2);
  EXPECT_EQ(whole.summary.problem.parts, 1);
  EXPECT_EQ(split.summary.problem.residual_blocks(), whole.summary.problem.residual_blocks());
  EXPECT_NEAR(split.summary.initial_cost, whole.summary.initial_cost,
              1e-12 * whole.summary.initial_cost);
  EXPECT_NEAR(split.summary.final_cost, whole.summary.final_cost, 1e-3 * whole.summary.final_cost);
  const double split_psnr = PsnrAt(split.video, recording, 10);
  const double whole_psnr = PsnrAt(whole.video, recording, 10);
  std::printf("parts %lld: %.2f dB, one problem %.2f dB\n",
              static_cast<long long>(split.summary.problem.parts), split_psnr, whole_psnr);
  EXPECT_NEAR(split_psnr, whole_psnr, 0.1);
}

// Ceres' SUBSET preconditioner factorises each pixel's temporal chain (frame, event and
// temporal TV terms) exactly: without spatial TV that is the whole system, so every linear
// solve ends at Ceres' convergence test after its first conjugate-gradient step (two counted),
// where Jacobi needs more; with spatial TV, the solve reaches Jacobi's answer.
TEST(Reconstructor, SubsetPreconditionerFactorisesEachPixelsTemporalChain) {
  const test::SyntheticRecording recording;
  const Scene scene = MakeInterpolationScene(recording.Sharp(0), recording.Sharp(20),
                                             recording.events, BinningOptions());
  ReconstructionOptions options;
  options.solver.function_tolerance = 1e-8;
  options.solver.max_num_iterations = 50;
  const Reconstruction jacobi = Reconstruct(scene, options);
  options.solver.preconditioner_type = ceres::SUBSET;
  std::string error;
  ASSERT_TRUE(options.IsValid(&error)) << error;
  const Reconstruction subset = Reconstruct(scene, options);
  ASSERT_TRUE(subset.summary.solved);
  EXPECT_GT(jacobi.summary.linear_solver_iterations, 0);
  EXPECT_GT(subset.summary.linear_solver_iterations, 0);
  EXPECT_NEAR(subset.summary.final_cost, jacobi.summary.final_cost,
              1e-3 * jacobi.summary.final_cost);
  EXPECT_NEAR(PsnrAt(subset.video, recording, 10), PsnrAt(jacobi.video, recording, 10), 0.05);

  options.objective.spatial_tv_weight = 0.0;
  const Reconstruction chains = Reconstruct(scene, options);
  ASSERT_TRUE(chains.summary.solved);
  const int64_t steps =
      chains.summary.ceres.num_successful_steps + chains.summary.ceres.num_unsuccessful_steps;
  ASSERT_GT(steps, 0);
  std::printf("CG steps: Jacobi %lld, subset %lld; without spatial TV %lld in %lld LM steps\n",
              static_cast<long long>(jacobi.summary.linear_solver_iterations),
              static_cast<long long>(subset.summary.linear_solver_iterations),
              static_cast<long long>(chains.summary.linear_solver_iterations),
              static_cast<long long>(steps));
  EXPECT_LE(chains.summary.linear_solver_iterations, 2 * steps);
  options.solver.preconditioner_type = ceres::JACOBI;
  const Reconstruction jacobi_chains = Reconstruct(scene, options);
  const int64_t jacobi_steps = jacobi_chains.summary.ceres.num_successful_steps +
                               jacobi_chains.summary.ceres.num_unsuccessful_steps;
  std::printf("without spatial TV, Jacobi: %lld CG steps in %lld LM steps\n",
              static_cast<long long>(jacobi_chains.summary.linear_solver_iterations),
              static_cast<long long>(jacobi_steps));
  EXPECT_GT(jacobi_chains.summary.linear_solver_iterations, 2 * jacobi_steps);
}

// The whole solve, every part and batch, stops once its StopCondition is reached; what was not
// solved keeps its start, and nothing is reported as a failure.
TEST(Reconstructor, StopConditionEndsEveryPartAndKeepsTheStart) {
  const test::SyntheticRecording recording(/*width=*/120, /*height=*/40);
  const Scene scene = TwoRegionScene(recording);
  ReconstructionOptions options = EveryRegionAPart();
  options.solver.max_num_iterations = 1000;
  options.solver.function_tolerance = 1e-16;
  options.stop = StopCondition::After(0.0);
  const Video initial = InitializeLatentVideo(scene);
  const Reconstruction stopped = Reconstruct(scene, options, &initial);
  EXPECT_FALSE(stopped.summary.stopped_early.empty());
  EXPECT_LE(stopped.summary.iterations, 1);
  EXPECT_TRUE(VoxelValues(stopped.video).allFinite());

  std::atomic<bool> interrupt(false);
  options.stop = StopCondition().WhenRaised(&interrupt);
  int calls = 0;
  const Reconstruction interrupted =
      Reconstruct(scene, options, &initial, [&](const SolverIteration&) {
        if (++calls == 2) interrupt = true;  // raised during the solve, as Ctrl-C would be
        return true;
      });
  EXPECT_EQ(interrupted.summary.stopped_early, "interrupted");
  EXPECT_LE(interrupted.summary.iterations, 3);
}

TEST(Reconstructor, CallbackSeesTheWholeObjectiveAcrossParts) {
  const test::SyntheticRecording recording(/*width=*/120, /*height=*/40);
  const Scene scene = TwoRegionScene(recording);
  std::vector<SolverIteration> seen;
  const Reconstruction result =
      Reconstruct(scene, EveryRegionAPart(), nullptr, [&](const SolverIteration& iteration) {
        EXPECT_NE(iteration.latent, nullptr);
        seen.push_back(iteration);
        return true;
      });
  ASSERT_GE(result.summary.problem.parts, 2);
  ASSERT_GE(seen.size(), 2u);
  EXPECT_EQ(seen.front().iteration, 0);
  EXPECT_NEAR(seen.front().cost, result.summary.initial_cost, 1e-12 * result.summary.initial_cost);
  EXPECT_NEAR(seen.back().cost, result.summary.final_cost, 1e-12 * result.summary.final_cost);
  for (size_t i = 1; i < seen.size(); ++i) {
    EXPECT_EQ(seen[i].iteration, seen[i - 1].iteration + 1);
    EXPECT_LE(seen[i].cost, seen[i - 1].cost * (1 + 1e-12));
  }
}

// Plug & play's coupling term: as ρ grows, the solved voxels go to the prior's target. The
// target is constant in time, so that merged segments can reach it exactly.
TEST(Reconstructor, LargePriorWeightPinsTheSolvedVoxelsToTheTarget) {
  // ρ = 1e7 over voxels against ℓ1 weights of order 1 over pixels: the data terms' pull moves a
  // voxel by about (their weight · latent frames) / ρ ≈ 1e-5, well inside this bound.
  constexpr double kPinnedTolerance = 1e-3;
  // Without the prior the solution is a reconstruction of the scene, far from a ramp.
  constexpr double kUnpinnedMinDistance = 0.05;
  const test::SyntheticRecording recording;
  const Scene scene = MakeInterpolationScene(recording.Sharp(0), recording.Sharp(20),
                                             recording.events, BinningOptions());
  auto target = std::make_shared<Video>(InitializeLatentVideo(scene));
  for (int t = 0; t < target->num_frames(); ++t) {
    for (int y = 0; y < scene.height; ++y) {
      for (int x = 0; x < scene.width; ++x) {
        target->frame(t)(y, x) = 0.3 + 0.4 * x / scene.width;
      }
    }
  }
  ReconstructionOptions options;
  const ActivityMask mask(scene.events, options.activity_radius_px);
  ASSERT_GT(mask.num_active(), 0);
  const auto max_distance = [&](const Video& video) {
    double distance = 0.0;
    for (int t = 0; t < video.num_frames(); ++t) {
      for (int64_t p = 0; p < mask.num_pixels(); ++p) {
        if (!mask.active(p)) continue;
        distance = std::max(distance, std::abs(video.frame_data(t)[p] - target->frame_data(t)[p]));
      }
    }
    return distance;
  };
  const Reconstruction free = Reconstruct(scene, options);
  EXPECT_GT(max_distance(free.video), kUnpinnedMinDistance);
  options.objective.prior_weight = 1e7;
  options.objective.prior_target = target;
  const Reconstruction pinned = Reconstruct(scene, options);
  ASSERT_TRUE(pinned.summary.solved);
  EXPECT_GT(pinned.summary.problem.prior_residuals, 0);
  EXPECT_LT(max_distance(pinned.video), kPinnedTolerance);
}

// A budget below the problem's estimate: one part, all active, solved in overlapping bands of
// rows one after another. The answer stays that of the one problem.
TEST(Reconstructor, BandsWithinAMemoryBudgetReachTheWholeProblemsAccuracy) {
  const test::SyntheticRecording recording(/*width=*/64, /*height=*/96);
  const Scene scene = MakeInterpolationScene(recording.Sharp(0), recording.Sharp(20),
                                             recording.events, BinningOptions());
  ReconstructionOptions options;
  options.activity_radius_px = -1;  // one part of every pixel
  const Reconstruction whole = Reconstruct(scene, options);
  ASSERT_EQ(whole.summary.problem.batches, 1);
  const double estimated_mb =
      static_cast<double>(whole.summary.problem.estimated_bytes) / (1 << 20);
  options.max_problem_mb = static_cast<int64_t>(estimated_mb / 3);
  ASSERT_GE(options.max_problem_mb, 1) << "the scene is too small to cut into bands";
  const Reconstruction bands = Reconstruct(scene, options);
  EXPECT_GE(bands.summary.problem.batches, 3);
  EXPECT_EQ(bands.summary.problem.parts, bands.summary.problem.batches);
  EXPECT_EQ(bands.summary.problem.active_pixels, whole.summary.problem.active_pixels);
  EXPECT_EQ(bands.summary.problem.skipped_pixels, 0);
  const double whole_psnr = PsnrAt(whole.video, recording, 10);
  const double bands_psnr = PsnrAt(bands.video, recording, 10);
  std::printf("estimate %.1f MB; one problem %.2f dB; %lld bands within %lld MB: %.2f dB\n",
              estimated_mb, whole_psnr, static_cast<long long>(bands.summary.problem.batches),
              static_cast<long long>(options.max_problem_mb), bands_psnr);
  EXPECT_NEAR(bands_psnr, whole_psnr, 0.1);
}

// Parts that fit together are one batch; when they do not, batches take them one after another.
TEST(Reconstructor, PartsBeyondTheBudgetAreSolvedInBatches) {
  const test::SyntheticRecording recording(/*width=*/120, /*height=*/40);
  const Scene scene = TwoRegionScene(recording);
  ReconstructionOptions options = EveryRegionAPart();
  const Reconstruction together = Reconstruct(scene, options);
  ASSERT_GE(together.summary.problem.parts, 2);
  EXPECT_EQ(together.summary.problem.batches, 1);
  options.max_problem_mb = 1;
  const Reconstruction batched = Reconstruct(scene, options);
  EXPECT_GE(batched.summary.problem.batches, 2);
  EXPECT_NEAR(PsnrAt(batched.video, recording, 10), PsnrAt(together.video, recording, 10), 0.1);
}

TEST(Reconstructor, MemoryBudgetBeyondOneTebibyteIsRefused) {
  ReconstructionOptions options;
  options.max_problem_mb = ReconstructionOptions::kMaxProblemMb + 1;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("max_problem_mb"), std::string::npos) << error;
  options.max_problem_mb = 0;  // no limit
  EXPECT_TRUE(options.IsValid(nullptr));
}

// A pixel no event fired, whose frames differ by less than one event's change, takes the blend
// of the frames; a pixel that fired, and one whose frames differ by more, keep the solve's answer.
TEST(Reconstructor, EventSaturationFollowsHowTheChangePerEventIsKnown) {
  const test::SyntheticRecording recording;
  const Scene interpolation = MakeInterpolationScene(recording.Sharp(0), recording.Sharp(20),
                                                     recording.events, BinningOptions());
  const Scene prediction = MakePredictionScene(
      recording.Sharp(0), recording.rendered.timestamp_ns(10), recording.events, BinningOptions());
  ReconstructionOptions options;
  EventModelEstimate model;
  bool alpha_derived = false;
  // Measured between two frames: the estimation's c.
  options.estimation.measured_saturation = 3.0;
  EXPECT_EQ(ResolveObjective(interpolation, options, &model, &alpha_derived).event_model.saturation,
            3.0);
  EXPECT_TRUE(model.estimated_from_frames);
  EXPECT_EQ(model.saturation, 3.0);
  // Assumed (one frame) or given: the paper's c = 1.
  EXPECT_EQ(ResolveObjective(prediction, options, &model, &alpha_derived).event_model.saturation,
            1.0);
  options.objective.event_model.alpha = 5.0;
  EXPECT_EQ(ResolveObjective(interpolation, options, &model, &alpha_derived).event_model.saturation,
            1.0);
  // A user's c wins.
  options.objective.event_model.saturation = 1.5;
  EXPECT_EQ(ResolveObjective(interpolation, options, &model, &alpha_derived).event_model.saturation,
            1.5);
  options.objective.event_model.saturation = 0.5;
  EXPECT_THROW(Reconstruct(interpolation, options), InvalidArgumentError);
}

// A prediction under a flickering light: one frame (0.7 everywhere) and then, on every pixel,
// ON and OFF events by turns, 12 cycles that end where they began. With |ΔH| as its temporal
// TV a pixel drifts dark a little each cycle (a brightening step costs more than the darkening
// one); measured in g, it ends near the frame.
TEST(Reconstructor, AFlickeringPixelDoesNotDriftDark) {
  constexpr int kRows = 6, kCols = 6, kCycles = 12, kSteps = 2 * kCycles;
  Scene scene;
  scene.height = kRows;
  scene.width = kCols;
  scene.events = EventFrames(kRows, kCols);
  std::vector<int64_t> times;
  for (int k = 0; k <= kSteps; ++k) times.push_back(1000000LL * k);
  for (int k = 0; k < kSteps; ++k) {
    scene.events.AddFrame({k, k + 1, times[k], times[k + 1], 1});
    for (int y = 0; y < kRows; ++y) {
      for (int x = 0; x < kCols; ++x) scene.events.value(k, y, x) = k % 2 == 0 ? 1.0f : -1.0f;
    }
  }
  scene.events.set_latent_timestamps_ns(times);
  scene.num_events = static_cast<int64_t>(kSteps) * kRows * kCols;
  constexpr double kFrame = 0.7;
  scene.frames.push_back({Image::Constant(kRows, kCols, kFrame), 0, 0, "first"});
  ReconstructionOptions options;
  options.objective.event_model.alpha = 5.0;
  const auto end_value = [&](int min_reversals) {
    options.objective.log_temporal_tv_reversals = min_reversals;
    const Reconstruction result = Reconstruct(scene, options);
    EXPECT_TRUE(result.summary.solved);
    EXPECT_EQ(result.summary.problem.log_temporal_tv_pixels, min_reversals > 0 ? kRows * kCols : 0);
    return result.video.frame(kSteps)(3, 3);
  };
  const double in_g = end_value(ObjectiveOptions().log_temporal_tv_reversals);
  const double linear = end_value(0);
  EXPECT_NEAR(in_g, kFrame, 0.05);
  EXPECT_LT(linear, kFrame - 0.15);
}

TEST(Reconstructor, QuietPixelsTakeTheBlendOfTheFrames) {
  Scene scene = MakeSceneWithEvents(6, 8, {{0, 2, 2}, {1, 2, 3}, {2, 3, 3}});
  scene.frames[0].image = Image::Constant(6, 8, 0.40);
  scene.frames[1].image = Image::Constant(6, 8, 0.42);
  scene.frames[1].image(3, 5) = 0.9;  // unfired, but a change of many events
  // Unfired, a change of 0.15 in g = log(x + 0.5): 3/4 of one event's (1/α = 0.2).
  const double three_quarters = 0.9 * std::exp(0.15) - 0.5;
  scene.frames[1].image(4, 6) = three_quarters;
  ReconstructionOptions options;
  options.objective.event_model.alpha = 5.0;
  options.activity_radius_px = -1;
  options.quiet_blend_fraction = 0.0;
  const Reconstruction solved = Reconstruct(scene, options);
  options.quiet_blend_fraction = 0.5;
  const Reconstruction half = Reconstruct(scene, options);
  options.quiet_blend_fraction = 1.0;
  const Reconstruction whole = Reconstruct(scene, options);
  ASSERT_TRUE(half.summary.solved);
  const auto& times = scene.latent_timestamps_ns();
  for (int t = 0; t < scene.num_latent_frames(); ++t) {
    const double w = static_cast<double>(times[t] - times[0]) / (times.back() - times[0]);
    for (const Reconstruction* blended : {&half, &whole}) {
      EXPECT_NEAR(blended->video.frame(t)(0, 0), (1.0 - w) * 0.40 + w * 0.42, 1e-12) << t;
      EXPECT_EQ(blended->video.frame(t)(2, 2), solved.video.frame(t)(2, 2)) << t;
      EXPECT_EQ(blended->video.frame(t)(3, 5), solved.video.frame(t)(3, 5)) << t;
    }
    // Under one event's change but over half of it: blended only with the whole fraction.
    EXPECT_EQ(half.video.frame(t)(4, 6), solved.video.frame(t)(4, 6)) << t;
    EXPECT_NEAR(whole.video.frame(t)(4, 6), (1.0 - w) * 0.40 + w * three_quarters, 1e-12) << t;
  }
  EXPECT_NE(solved.video.frame(1)(0, 0), half.video.frame(1)(0, 0));
}

}  // namespace
}  // namespace evfs
