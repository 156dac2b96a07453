// b of the log model chosen by interpolating frames outside the window (app/log_offset_search.h),
// alone and through the reconstruction job on the shared DAVIS snippet shapes_rotation_13_20.
#include "evfs/app/log_offset_search.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <vector>

#include "evfs/app/reconstruct_job.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

// Frame i at i · 40 ms.
int64_t FrameTime(int i) { return static_cast<int64_t>(i) * 40000000; }

TEST(LogOffsetSearch, TripletsSkipTheExcludedFramesAndPreferTheNearest) {
  // Frames 0..6 without 3 (inside the window) and 5 (the truth): 0, 1, 2, 4, 6 remain.
  std::vector<ValidationTriplet> all = ValidationTriplets(7, {3, 5}, FrameTime, FrameTime(3), 10);
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all[0].first, 0);
  EXPECT_EQ(all[0].middle, 1);
  EXPECT_EQ(all[0].last, 2);
  EXPECT_EQ(all[1].middle, 2);
  EXPECT_EQ(all[1].last, 4);
  EXPECT_EQ(all[2].first, 2);
  EXPECT_EQ(all[2].middle, 4);
  EXPECT_EQ(all[2].last, 6);
  // The two nearest to frame 3's time: middles 2 and 4, in frame order.
  const std::vector<ValidationTriplet> nearest =
      ValidationTriplets(7, {3, 5}, FrameTime, FrameTime(3), 2);
  ASSERT_EQ(nearest.size(), 2u);
  EXPECT_EQ(nearest[0].middle, 2);
  EXPECT_EQ(nearest[1].middle, 4);
  // Two usable frames make no triplet.
  EXPECT_TRUE(ValidationTriplets(4, {1, 2}, FrameTime, 0, 2).empty());
}

TEST(LogOffsetSearch, KeepsTheCandidateWithTheLeastErrorOverAllTriplets) {
  const std::vector<ValidationTriplet> triplets = {{0, 1, 2}, {2, 3, 4}};
  // Triplet 1 alone would choose 0.1; summed over both, 1 has the least error.
  const auto error = [&triplets](int k, double b) {
    if (triplets[k].middle == 1) return b == 0.1 ? 0.001 : 0.002;
    return std::abs(std::log(b)) * 0.01 + 0.001;
  };
  const LogOffsetChoice choice = ChooseLogOffset({0.1, 1.0, 2.0}, triplets, 0.5, error);
  EXPECT_EQ(choice.chosen, 1.0);
  ASSERT_EQ(choice.psnr.size(), 3u);
  EXPECT_NEAR(choice.psnr[1], -10.0 * std::log10((0.002 + 0.001) / 2.0), 1e-9);
  EXPECT_LT(choice.psnr[0], choice.psnr[1]);
  // The triplets solved side by side: the same choice and scores.
  const LogOffsetChoice side_by_side =
      ChooseLogOffset({0.1, 1.0, 2.0}, triplets, 0.5, error, /*workers=*/2);
  EXPECT_EQ(side_by_side.chosen, 1.0);
  EXPECT_EQ(side_by_side.psnr, choice.psnr);
  // Equal errors: the candidate nearest the fallback (in log b) stays.
  const auto flat = [](int, double) { return 0.001; };
  EXPECT_EQ(ChooseLogOffset({2.0, 0.1}, triplets, 0.5, flat).chosen, 2.0);
  EXPECT_EQ(ChooseLogOffset({2.0, 0.1}, triplets, 0.2, flat).chosen, 0.1);
  // Nothing to score: the fallback, said so.
  const LogOffsetChoice none = ChooseLogOffset({0.1, 2.0}, {}, 0.5, flat);
  EXPECT_EQ(none.chosen, 0.5);
  EXPECT_TRUE(none.psnr.empty());
  EXPECT_NE(none.description.find("no three frames"), std::string::npos);
}

TEST(LogOffsetSearch, WalksFromTheFallbackAndStopsWhereTheErrorRisesAgain) {
  const std::vector<ValidationTriplet> triplets = {{0, 1, 2}};
  std::atomic<int> solves{0};
  const auto valley_at = [&solves](double minimum) {
    return [&solves, minimum](int, double b) {
      ++solves;
      return 0.001 + std::pow(std::log(b / minimum), 2);
    };
  };
  const std::vector<double> candidates = {5.0, 0.05, 1.5, 0.15, 0.5};
  // A minimum at the fallback: it and its two neighbours.
  LogOffsetChoice choice = ChooseLogOffset(candidates, triplets, 0.5, valley_at(0.5));
  EXPECT_EQ(choice.chosen, 0.5);
  EXPECT_EQ(solves, 3);
  ASSERT_EQ(choice.candidates, (std::vector<double>{0.05, 0.15, 0.5, 1.5, 5.0}));
  EXPECT_TRUE(std::isnan(choice.psnr[0]));
  EXPECT_TRUE(std::isnan(choice.psnr[4]));
  // A minimum at an end: every candidate between, once each.
  solves = 0;
  choice = ChooseLogOffset(candidates, triplets, 0.5, valley_at(0.04));
  EXPECT_EQ(choice.chosen, 0.05);
  EXPECT_EQ(solves, 4);
  solves = 0;
  EXPECT_EQ(ChooseLogOffset(candidates, triplets, 0.5, valley_at(1.4)).chosen, 1.5);
  EXPECT_EQ(solves, 4);
  // Repeated candidates are solved once; a single one is chosen without a solve.
  solves = 0;
  choice = ChooseLogOffset({0.5, 0.05, 0.5, 0.05}, triplets, 0.5, valley_at(0.04));
  EXPECT_EQ(choice.candidates, (std::vector<double>{0.05, 0.5}));
  EXPECT_EQ(choice.chosen, 0.05);
  EXPECT_EQ(solves, 2);
  solves = 0;
  choice = ChooseLogOffset({1.5, 1.5}, triplets, 0.5, valley_at(0.04));
  EXPECT_EQ(choice.chosen, 1.5);
  EXPECT_EQ(solves, 0);
  // Solves side by side (the first step's three at once): the same solves and choice.
  solves = 0;
  EXPECT_EQ(ChooseLogOffset(candidates, triplets, 0.5, valley_at(0.04), /*workers=*/3).chosen,
            0.05);
  EXPECT_EQ(solves, 4);
}

// shapes 18, 20 → 19 (lines 2, 4 → 3): b chosen on 13, 18 → 14 and 14, 20 → 18, never on 19.
TEST(LogOffsetSearch, ReconstructionChoosesOnFramesOutsideTheWindowAndTheTruth) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  ReconstructRequest request;
  request.data_path = (std::filesystem::path(data_dir) / "shapes_rotation_13_20").string();
  request.mode = Mode::kInterpolate;
  request.first = 2;
  request.last = 4;
  request.truth = 3;
  request.log_offset_search = {0.1, 2.0};
  const ReconstructResult result = RunReconstruction(request);
  ASSERT_TRUE(result.log_offset_choice.has_value());
  const LogOffsetChoice& choice = *result.log_offset_choice;
  ASSERT_EQ(choice.triplets.size(), 2u);
  for (const ValidationTriplet& triplet : choice.triplets) {
    for (const int frame : {triplet.first, triplet.middle, triplet.last}) EXPECT_NE(frame, 3);
  }
  // This DAVIS240 clip interpolates better with a small offset, the withheld frame as well.
  EXPECT_EQ(choice.chosen, 0.1);
  ASSERT_EQ(choice.psnr.size(), 2u);
  EXPECT_GT(choice.psnr[0], choice.psnr[1]);
  EXPECT_GE(result.truth.psnr, 37.0);
  EXPECT_GT(choice.seconds, 0.0);
  EXPECT_NE(SummaryJson(request, result).find("\"log_offset_search\""), std::string::npos);
  // A prediction does not search.
  request.mode = Mode::kPredict;
  request.first = 2;
  request.last = 3;
  request.method.method = Method::kCopy;
  EXPECT_FALSE(RunReconstruction(request).log_offset_choice.has_value());
}

}  // namespace
}  // namespace evfs
