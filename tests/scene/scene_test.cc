#include "evfs/scene/scene.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <new>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/tests/scene/scene_test_scenes.h"

#if defined(__has_feature)
#define EVFS_HAS_FEATURE(x) __has_feature(x)
#else
#define EVFS_HAS_FEATURE(x) 0
#endif

namespace evfs {
namespace {

// Address space of the child in MemoryIsBoundedBeforeAllocating: the test binary and the
// scene's 2 latent frames of 4 M pixels fit, the 5 GB of the old binning do not.
constexpr rlim_t kChildAddressSpaceBytes = rlim_t{1} << 30;

template <typename Call>
void ExpectRefused(const Call& call) {
  try {
    call();
    ADD_FAILURE() << "expected an InvalidArgumentError naming max_latent_voxels";
  } catch (const InvalidArgumentError& error) {
    EXPECT_NE(std::string(error.what()).find("max_latent_voxels"), std::string::npos)
        << error.what();
  }
}

TEST(CheckSensorFitsLatentVoxels, RefusesADeclaredSizeBeforeAnyFrame) {
  BinningOptions binning;
  // An 8192x8192 sensor (an HDF5 file may declare it over two small compressed frames): two
  // latent frames are 134 M voxels, over the default cap; nothing of that size is allocated.
  ExpectRefused([&] { CheckSensorFitsLatentVoxels(8192, 8192, binning); });
  CheckSensorFitsLatentVoxels(346, 260, binning);
  binning.method = BinningOptions::Method::kStacked;
  binning.stacked.num_frames = 20;
  binning.stacked.steps_per_frame = 1;
  binning.max_latent_voxels = 346 * 260 * 21;
  CheckSensorFitsLatentVoxels(346, 260, binning);
  binning.max_latent_voxels -= 1;
  ExpectRefused([&] { CheckSensorFitsLatentVoxels(346, 260, binning); });
}

// `events` plus `count` events at (x, y), alternating in polarity, spread over [begin, end).
EventStream WithHotPixel(const EventStream& events, int x, int y, int count, int64_t begin_ns,
                         int64_t end_ns) {
  std::vector<std::tuple<int64_t, uint16_t, uint16_t, int8_t>> all;
  for (size_t i = 0; i < events.size(); ++i) {
    all.emplace_back(events.t_ns(i), events.x(i), events.y(i), events.polarity(i));
  }
  for (int i = 0; i < count; ++i) {
    all.emplace_back(begin_ns + (end_ns - begin_ns) * i / count, static_cast<uint16_t>(x),
                     static_cast<uint16_t>(y), i % 2 ? 1 : -1);
  }
  std::stable_sort(all.begin(), all.end(),
                   [](const auto& a, const auto& b) { return std::get<0>(a) < std::get<0>(b); });
  EventStream result(events.width(), events.height());
  for (const auto& [t_ns, ex, ey, polarity] : all) result.push_back(t_ns, ex, ey, polarity);
  return result;
}

TEST(Scene, InterpolationTiesFramesToTheEndsOfTheTimeline) {
  const test::SyntheticRecording recording;
  const Scene scene = MakeInterpolationScene(recording.Sharp(0), recording.Sharp(20),
                                             recording.events, BinningOptions());
  ASSERT_EQ(scene.frames.size(), 2u);
  const int last = scene.num_latent_frames() - 1;
  EXPECT_GT(last, 1);
  EXPECT_EQ(scene.frames[0].latent_first, 0);
  EXPECT_EQ(scene.frames[0].latent_last, 0);
  EXPECT_EQ(scene.frames[1].latent_first, last);
  EXPECT_EQ(scene.frames[1].latent_last, last);
  EXPECT_EQ(scene.latent_timestamps_ns().front(), recording.rendered.timestamp_ns(0));
  EXPECT_EQ(scene.latent_timestamps_ns().back(), recording.rendered.timestamp_ns(20));
  EXPECT_GT(scene.num_events, 0);
}

TEST(Scene, BlurredFrameSpansItsExposure) {
  const test::SyntheticRecording recording;
  BinningOptions binning;
  binning.method = BinningOptions::Method::kStacked;
  binning.stacked.num_frames = 10;
  const Scene scene = MakeDeblurScene(recording.Blurred(0, 20), recording.events, binning);
  ASSERT_EQ(scene.frames.size(), 1u);
  EXPECT_EQ(scene.num_latent_frames(), 11);
  EXPECT_EQ(scene.frames[0].latent_first, 0);
  EXPECT_EQ(scene.frames[0].latent_last, 10);
}

TEST(Scene, AutoBinningFallsBackToStackedWhenCollisionFramesAreTooMany) {
  const test::SyntheticRecording recording;
  const int64_t end_ns = recording.rendered.timestamp_ns(20);
  const Scene collision =
      MakePredictionScene(recording.Sharp(0), end_ns, recording.events, BinningOptions());
  ASSERT_GT(collision.events.num_frames(), 6);  // the premise: more than the limits below
  BinningOptions binning;
  binning.max_latent_frames = 5;
  const Scene capped = MakePredictionScene(recording.Sharp(0), end_ns, recording.events, binning);
  EXPECT_EQ(capped.events.num_frames(), 5);
  EXPECT_EQ(capped.num_latent_frames(), 6);
  EXPECT_EQ(capped.num_events, collision.num_events);
}

TEST(Scene, AutoBinningKeepsWithinTheVoxelBudget) {
  const test::SyntheticRecording recording;
  BinningOptions binning;
  const int64_t pixels = recording.events.width() * recording.events.height();
  binning.max_latent_voxels = pixels * 7;  // 7 latent frames: 6 steps
  const Scene scene = MakePredictionScene(recording.Sharp(0), recording.rendered.timestamp_ns(20),
                                          recording.events, binning);
  EXPECT_EQ(scene.num_latent_frames(), 7);
  // The cap wins over the wish for a few steps: 3 latent frames fit, so 2 steps.
  binning.max_latent_voxels = pixels * 3 + pixels / 2;
  const Scene tiny = MakePredictionScene(recording.Sharp(0), recording.rendered.timestamp_ns(20),
                                         recording.events, binning);
  EXPECT_EQ(tiny.events.num_frames(), 2);
  EXPECT_EQ(tiny.num_latent_frames(), 3);
  // Not even one step fits: a user error naming the limit.
  binning.max_latent_voxels = pixels * 2 - 1;
  ExpectRefused([&] {
    MakePredictionScene(recording.Sharp(0), recording.rendered.timestamp_ns(20), recording.events,
                        binning);
  });
}

// Regression: an explicit binning beyond the voxel cap used to be built whatever its
// size; it is now refused before any frame is allocated.
TEST(Scene, ExplicitBinningBeyondTheVoxelCapIsRefused) {
  const test::SyntheticRecording recording;
  const int64_t pixels = recording.events.width() * recording.events.height();
  const int64_t end_ns = recording.rendered.timestamp_ns(20);
  BinningOptions binning;
  binning.method = BinningOptions::Method::kCollision;
  const Scene collision =
      MakePredictionScene(recording.Sharp(0), end_ns, recording.events, binning);
  ASSERT_GT(collision.events.num_frames(), 6);  // the premise: more than the cap below
  binning.max_latent_voxels = pixels * 7;
  ExpectRefused(
      [&] { MakePredictionScene(recording.Sharp(0), end_ns, recording.events, binning); });
  binning.max_latent_voxels = pixels * (collision.num_latent_frames());  // exactly fits
  EXPECT_EQ(MakePredictionScene(recording.Sharp(0), end_ns, recording.events, binning)
                .num_latent_frames(),
            collision.num_latent_frames());

  binning.method = BinningOptions::Method::kStacked;
  binning.stacked.num_frames = 3;
  binning.stacked.steps_per_frame = 2;  // 7 latent frames
  binning.max_latent_voxels = pixels * 7;
  EXPECT_EQ(MakePredictionScene(recording.Sharp(0), end_ns, recording.events, binning)
                .num_latent_frames(),
            7);
  binning.max_latent_voxels = pixels * 7 - 1;
  ExpectRefused(
      [&] { MakePredictionScene(recording.Sharp(0), end_ns, recording.events, binning); });
  // M · S beyond int: refused by the options, not wrapped.
  binning.max_latent_voxels = std::numeric_limits<int64_t>::max();
  binning.stacked.num_frames = 1 << 20;
  binning.stacked.steps_per_frame = 1 << 20;
  EXPECT_THROW(MakePredictionScene(recording.Sharp(0), end_ns, recording.events, binning),
               InvalidArgumentError);
}

TEST(Scene, PlanBinningPredictsTheScene) {
  const test::SyntheticRecording recording;
  const int64_t begin_ns = recording.rendered.timestamp_ns(0);
  const int64_t end_ns = recording.rendered.timestamp_ns(20);
  // A window without events, too: its two ends are the latent frames.
  const EventStream none(recording.events.width(), recording.events.height());
  for (const auto method : {BinningOptions::Method::kAuto, BinningOptions::Method::kCollision,
                            BinningOptions::Method::kStacked}) {
    const BinningOptions empty_binning = [&] {
      BinningOptions binning;
      binning.method = method;
      return binning;
    }();
    const BinningPlan empty = PlanBinning(none, begin_ns, end_ns, empty_binning);
    const Scene quiet = MakePredictionScene(recording.Sharp(0), end_ns, none, empty_binning);
    EXPECT_EQ(empty.num_event_frames, quiet.events.num_frames());
    EXPECT_EQ(empty.num_latent_frames, quiet.num_latent_frames());
    for (const int max_latent_frames : {5, 48}) {
      BinningOptions binning;
      binning.method = method;
      binning.max_latent_frames = max_latent_frames;
      const BinningPlan plan = PlanBinning(recording.events, begin_ns, end_ns, binning);
      const Scene scene =
          MakePredictionScene(recording.Sharp(0), end_ns, recording.events, binning);
      EXPECT_EQ(plan.num_event_frames, scene.events.num_frames());
      EXPECT_EQ(plan.num_latent_frames, scene.num_latent_frames());
      EXPECT_EQ(plan.collision_frames, CountCollisionFrames(recording.events, begin_ns, end_ns));
      EXPECT_EQ(plan.activity.num_events, scene.num_events);
    }
  }
}

// Few collision frames: auto binning splits them up to min_latent_steps (never beyond
// max_latent_frames), an explicit --binning=collision keeps the paper's frames.
TEST(Scene, AutoBinningSplitsFewCollisionFramesUpToMinLatentSteps) {
  const test::SyntheticRecording recording;
  const int64_t begin_ns = recording.rendered.timestamp_ns(0);
  const int64_t end_ns = recording.rendered.timestamp_ns(1);
  const int64_t collisions = CountCollisionFrames(recording.events, begin_ns, end_ns);
  ASSERT_GT(collisions, 0);
  for (const auto method : {BinningOptions::Method::kAuto, BinningOptions::Method::kCollision}) {
    for (const int64_t extra : {0, 5}) {
      BinningOptions binning;
      binning.method = method;
      binning.max_latent_frames = static_cast<int>(collisions + 3);
      binning.min_latent_steps = static_cast<int>(collisions + extra);
      const BinningPlan plan = PlanBinning(recording.events, begin_ns, end_ns, binning);
      const Scene scene =
          MakePredictionScene(recording.Sharp(0), end_ns, recording.events, binning);
      const int64_t expected = method == BinningOptions::Method::kAuto
                                   ? collisions + std::min<int64_t>(extra, 3)
                                   : collisions;
      EXPECT_EQ(plan.method, BinningOptions::Method::kCollision);
      EXPECT_EQ(scene.num_latent_frames(), expected + 1) << "extra " << extra;
      EXPECT_EQ(plan.num_latent_frames, scene.num_latent_frames());
      EXPECT_EQ(scene.num_events, plan.activity.num_events);
    }
  }
}

// Regression: one pixel firing a thousand times in a quiet window made collision
// binning open a thousand frames of the whole sensor (auto binning then fell back to stacked
// frames). Its events are now left out as hot, and the scene is the one without it.
TEST(Scene, HotPixelDoesNotMultiplyTheLatentSteps) {
  const test::SyntheticRecording recording;
  const int64_t begin_ns = recording.rendered.timestamp_ns(0);
  const int64_t end_ns = recording.rendered.timestamp_ns(20);
  const int hot_x = 3, hot_y = 2;
  const EventStream hot = WithHotPixel(recording.events, hot_x, hot_y, 1000, begin_ns, end_ns);
  const Scene clean =
      MakePredictionScene(recording.Sharp(0), end_ns, recording.events, BinningOptions());
  const Scene scene = MakePredictionScene(recording.Sharp(0), end_ns, hot, BinningOptions());
  ASSERT_EQ(scene.hot_pixels.size(), 1u);
  EXPECT_EQ(scene.hot_pixels[0], hot_y * hot.width() + hot_x);
  EXPECT_GE(scene.hot_pixel_events, 1000);
  EXPECT_EQ(scene.num_events + scene.hot_pixel_events, clean.num_events + 1000);
  EXPECT_LE(scene.num_latent_frames(), clean.num_latent_frames());
  EXPECT_LT(scene.num_latent_frames(), 48);  // collision binning, not the stacked fallback
  EXPECT_EQ(scene.events.span(0).latent_last, 1);

  // Without the rule the hot pixel decides the timeline: the fallback to max_latent_frames.
  BinningOptions keep_all;
  keep_all.hot_pixel_factor = 0.0;
  keep_all.flicker_min_reversals = 0;  // the hot pixel alternates: the flicker rule takes it
  const Scene kept = MakePredictionScene(recording.Sharp(0), end_ns, hot, keep_all);
  EXPECT_TRUE(kept.hot_pixels.empty());
  EXPECT_EQ(kept.num_latent_frames(), keep_all.max_latent_frames + 1);
  EXPECT_EQ(kept.num_events, clean.num_events + 1000);
}

// The background-activity filter runs before binning: isolated events added to a
// recording are left out and counted, the recording's own edges are kept, and a filtered event
// neither fires a pixel nor opens a collision frame.
TEST(Scene, NoiseFilterLeavesOutIsolatedEventsBeforeBinning) {
  const test::SyntheticRecording recording;
  const int64_t begin_ns = recording.rendered.timestamp_ns(0);
  const int64_t end_ns = recording.rendered.timestamp_ns(20);
  // Five lone events at the corners and centre of the sensor, 1 ms into the window.
  const int w = recording.events.width(), h = recording.events.height();
  EventStream noisy(w, h);
  const int64_t t_noise = begin_ns + 1000000;
  bool added = false;
  for (size_t i = 0; i <= recording.events.size(); ++i) {
    if (!added && (i == recording.events.size() || recording.events.t_ns(i) > t_noise)) {
      for (const auto& [x, y] : {std::pair{0, 0}, {w - 1, 0}, {0, h - 1}, {w - 1, h - 1}}) {
        noisy.push_back(t_noise, x, y, 1);
      }
      added = true;
    }
    if (i < recording.events.size()) {
      noisy.push_back(recording.events.t_ns(i), recording.events.x(i), recording.events.y(i),
                      recording.events.polarity(i));
    }
  }
  BinningOptions filtered;
  filtered.noise_filter_ms = 2.0;
  const Scene kept_all = MakePredictionScene(recording.Sharp(0), end_ns, noisy, BinningOptions());
  const Scene scene = MakePredictionScene(recording.Sharp(0), end_ns, noisy, filtered);
  EXPECT_EQ(kept_all.noise_events, 0);
  EXPECT_GE(scene.noise_events, 4);
  EXPECT_EQ(scene.num_events + scene.noise_events, kept_all.num_events);
  // The synthetic scene's moving shapes fire runs of neighbouring pixels: few of its own events
  // are alone within 2 ms.
  EXPECT_LT(scene.noise_events, kept_all.num_events / 20);
  for (const auto& [x, y] : {std::pair{0, 0}, {w - 1, 0}, {0, h - 1}, {w - 1, h - 1}}) {
    double fired = 0.0;
    for (int k = 0; k < scene.events.num_frames(); ++k)
      fired += std::abs(scene.events.value(k, y, x));
    EXPECT_EQ(fired, 0.0) << "pixel " << x << ", " << y;
  }

  BinningOptions invalid;
  invalid.noise_filter_ms = -1.0;
  std::string error;
  EXPECT_FALSE(invalid.IsValid(&error));
  EXPECT_NE(error.find("noise_filter_ms"), std::string::npos) << error;
}

// Events at (x, y) of `events` in [begin_ns, end_ns).
int64_t EventsAtPixel(const EventStream& events, int x, int y, int64_t begin_ns, int64_t end_ns) {
  int64_t count = 0;
  for (size_t i = 0; i < events.size(); ++i) {
    count += events.x(i) == x && events.y(i) == y && events.t_ns(i) >= begin_ns &&
             events.t_ns(i) < end_ns;
  }
  return count;
}

// The busiest pixel of `events`: one where the moving shapes fire.
std::pair<int, int> BusiestPixel(const EventStream& events) {
  std::vector<int> count(static_cast<size_t>(events.width()) * events.height(), 0);
  for (size_t i = 0; i < events.size(); ++i) ++count[events.y(i) * events.width() + events.x(i)];
  const int p = static_cast<int>(std::max_element(count.begin(), count.end()) - count.begin());
  return {p % events.width(), p / events.width()};
}

// With leave_out_saturated, a pixel at full scale in every frame cannot show what its events
// record: they are left out and counted. Saturated in one frame only, its events time an edge
// and are kept; with a level above 1 every event is kept.
TEST(Scene, SaturatedPixelLeavesItsEventsToTheFrames) {
  const test::SyntheticRecording recording;
  const int64_t begin_ns = recording.rendered.timestamp_ns(0);
  const int64_t end_ns = recording.rendered.timestamp_ns(20);
  const auto [x, y] = BusiestPixel(recording.events);
  const int64_t at_pixel = EventsAtPixel(recording.events, x, y, begin_ns, end_ns);
  ASSERT_GT(at_pixel, 0);
  TimedFrame first = recording.Sharp(0);
  TimedFrame last = recording.Sharp(20);
  last.image(y, x) = 1.0;
  const Scene clean = MakeInterpolationScene(recording.Sharp(0), recording.Sharp(20),
                                             recording.events, BinningOptions());
  BinningOptions rule;
  rule.leave_out_saturated = true;
  const Scene one_side = MakeInterpolationScene(recording.Sharp(0), last, recording.events, rule);
  EXPECT_TRUE(one_side.saturated_pixels.empty());
  EXPECT_EQ(one_side.num_events, clean.num_events);
  first.image(y, x) = 1.0;
  EXPECT_TRUE(MakeInterpolationScene(first, last, recording.events, BinningOptions())
                  .saturated_pixels.empty());  // the rule is off by default
  const Scene scene = MakeInterpolationScene(first, last, recording.events, rule);
  EXPECT_TRUE(clean.saturated_pixels.empty());
  ASSERT_EQ(scene.saturated_pixels.size(), 1u);
  EXPECT_EQ(scene.saturated_pixels[0], y * recording.events.width() + x);
  EXPECT_EQ(scene.saturated_pixel_events, at_pixel);
  EXPECT_EQ(scene.num_events + at_pixel, clean.num_events);
  double fired = 0.0;
  for (int k = 0; k < scene.events.num_frames(); ++k)
    fired += std::abs(scene.events.value(k, y, x));
  EXPECT_EQ(fired, 0.0);

  BinningOptions keep = rule;
  keep.saturation_level = 1.5;
  const Scene kept = MakeInterpolationScene(first, last, recording.events, keep);
  EXPECT_TRUE(kept.saturated_pixels.empty());
  EXPECT_EQ(kept.num_events, clean.num_events);

  BinningOptions invalid;
  invalid.saturation_level = 0.0;
  std::string error;
  EXPECT_FALSE(invalid.IsValid(&error));
  EXPECT_NE(error.find("saturation_level"), std::string::npos) << error;
}

// A light blinking at one pixel (alternating bursts, far fewer events than a hot pixel's) next
// to where the frame saturates is brighter than the frame can show: left to the frames. The same
// light with the frame unsaturated keeps its events, and the moving shapes' own pixels are never
// taken for flicker.
TEST(Scene, FlickeringPixelNextToSaturationLeavesItsEventsToTheFrames) {
  const test::SyntheticRecording recording;
  const int64_t begin_ns = recording.rendered.timestamp_ns(0);
  const int64_t end_ns = recording.rendered.timestamp_ns(20);
  const int x = 1, y = 1;
  const int64_t own = EventsAtPixel(recording.events, x, y, begin_ns, end_ns);
  const EventStream lit = WithHotPixel(recording.events, x, y, 12, begin_ns, end_ns);
  const Scene clean =
      MakePredictionScene(recording.Sharp(0), end_ns, recording.events, BinningOptions());
  EXPECT_TRUE(clean.flickering_pixels.empty());
  const Scene unsaturated = MakePredictionScene(recording.Sharp(0), end_ns, lit, BinningOptions());
  EXPECT_TRUE(unsaturated.flickering_pixels.empty());
  EXPECT_EQ(unsaturated.num_events, clean.num_events + 12);

  TimedFrame glaring = recording.Sharp(0);
  glaring.image(y, x + 2) = 1.0;  // two pixels away: within reach of the light's glare
  const Scene scene = MakePredictionScene(glaring, end_ns, lit, BinningOptions());
  EXPECT_TRUE(scene.hot_pixels.empty());
  ASSERT_EQ(scene.flickering_pixels.size(), 1u);
  EXPECT_EQ(scene.flickering_pixels[0], y * lit.width() + x);
  EXPECT_EQ(scene.flickering_pixel_events, own + 12);
  EXPECT_EQ(scene.num_events + own + 12, clean.num_events + 12);

  BinningOptions keep;
  keep.flicker_min_reversals = 0;
  EXPECT_TRUE(MakePredictionScene(glaring, end_ns, lit, keep).flickering_pixels.empty());
  glaring.image(y, x + 2) = 0.5;
  glaring.image(y, x + 3) = 1.0;  // three pixels away: out of reach
  EXPECT_TRUE(
      MakePredictionScene(glaring, end_ns, lit, BinningOptions()).flickering_pixels.empty());
}

#if !defined(__SANITIZE_ADDRESS__) && !EVFS_HAS_FEATURE(address_sanitizer) && \
    !EVFS_HAS_FEATURE(memory_sanitizer) && !defined(__SANITIZE_THREAD__)
// Regression: the binning allocated collision frames × pixels before the voxel cap
// applied, so 300 events at one pixel of a 2048 x 2048 sensor asked for 300 frames of 4 M pixels
// (5 GB). Run in a child process limited to 1 GB of address space: it must finish there.
TEST(Scene, MemoryIsBoundedBeforeAllocating) {
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const rlimit limit = {kChildAddressSpaceBytes, kChildAddressSpaceBytes};
    setrlimit(RLIMIT_AS, &limit);
    int status = 1;
    try {
      constexpr int kSide = 2048;
      EventStream events(kSide, kSide);
      for (int i = 0; i < 300; ++i) events.push_back(1000 + i, 7, 9, i % 2 ? 1 : -1);
      TimedFrame first;
      first.image = Image::Zero(kSide, kSide);
      first.label = "zeros";
      BinningOptions binning;
      binning.flicker_min_reversals = 0;  // the pixel alternates: keep its events for the test
      const Scene scene = MakePredictionScene(first, 2000, events, binning);
      // 12 M voxels hold 2 latent frames of 4 M pixels: one stacked step.
      status = scene.num_latent_frames() == 2 && scene.num_events == 300 ? 0 : 2;
    } catch (const std::bad_alloc&) {
      status = 3;
    } catch (...) {
      status = 4;
    }
    _exit(status);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "2: wrong scene, 3: bad_alloc, 4: other exception";
}
#endif

TEST(Scene, RejectsBadWindowsAndSizes) {
  const test::SyntheticRecording recording;
  EXPECT_THROW(MakePredictionScene(recording.Sharp(10), recording.rendered.timestamp_ns(5),
                                   recording.events, BinningOptions()),
               InvalidArgumentError);
  TimedFrame wrong_size = recording.Sharp(0);
  wrong_size.image = Image::Zero(5, 5);
  EXPECT_THROW(
      MakeInterpolationScene(wrong_size, recording.Sharp(10), recording.events, BinningOptions()),
      InvalidArgumentError);
}

}  // namespace
}  // namespace evfs
