#include "evfs/events/binning.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <utility>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/events/random.h"

namespace evfs {
namespace {

constexpr int kWidth = 32;
constexpr int kHeight = 24;
constexpr uint64_t kSeed = 1234;

/// `count` events at uniformly drawn times in [t_begin_ns, t_end_ns), pixels and polarities.
EventStream RandomEvents(int count, int64_t t_begin_ns, int64_t t_end_ns, uint64_t seed) {
  Random random(seed);
  std::vector<int64_t> times(count);
  for (int64_t& t : times) {
    t = t_begin_ns + static_cast<int64_t>(random.UniformIndex(t_end_ns - t_begin_ns));
  }
  std::sort(times.begin(), times.end());
  EventStream events(kWidth, kHeight);
  for (const int64_t t : times) {
    events.push_back(t, static_cast<uint16_t>(random.UniformIndex(kWidth)),
                     static_cast<uint16_t>(random.UniformIndex(kHeight)), random.Sign());
  }
  return events;
}

/// Per-pixel sum of polarities of the events in [t_begin_ns, t_end_ns).
std::vector<double> PolaritySums(const EventStream& events, int64_t t_begin_ns, int64_t t_end_ns) {
  std::vector<double> sums(static_cast<size_t>(events.width()) * events.height(), 0.0);
  const EventStream window = events.Slice(t_begin_ns, t_end_ns);
  for (size_t i = 0; i < window.size(); ++i) {
    sums[window.y(i) * events.width() + window.x(i)] += window.polarity(i);
  }
  return sums;
}

/// Per-pixel sum over all frames of the frame values.
std::vector<double> FrameSums(const EventFrames& frames) {
  std::vector<double> sums(frames.pixels_per_frame(), 0.0);
  for (int k = 0; k < frames.num_frames(); ++k) {
    for (int64_t p = 0; p < frames.pixels_per_frame(); ++p) sums[p] += frames.frame_data(k)[p];
  }
  return sums;
}

/// Latent timestamps span the window and strictly increase; spans tile the latent timeline;
/// each frame's events lie inside its latent span (the last frame's before the exclusive end).
void ExpectValidTimeline(const EventFrames& frames, int64_t t_begin_ns, int64_t t_end_ns) {
  const std::vector<int64_t>& latent = frames.latent_timestamps_ns();
  ASSERT_GE(latent.size(), 2u);
  EXPECT_EQ(latent.front(), t_begin_ns);
  EXPECT_EQ(latent.back(), t_end_ns);
  for (size_t i = 1; i < latent.size(); ++i) EXPECT_LT(latent[i - 1], latent[i]) << i;
  int expected_first = 0;
  for (const EventFrameSpan& span : frames.spans()) {
    EXPECT_EQ(span.latent_first, expected_first);
    EXPECT_GT(span.latent_last, span.latent_first);
    ASSERT_LT(span.latent_last, frames.num_latent_frames());
    EXPECT_LE(span.t_first_ns, span.t_last_ns);
    if (span.num_events > 0) {
      EXPECT_LE(latent[span.latent_first], span.t_first_ns);
      EXPECT_LE(span.t_last_ns, latent[span.latent_last]);
    }
    expected_first = span.latent_last;
  }
  if (frames.num_frames() > 0) {
    EXPECT_EQ(expected_first, frames.num_latent_frames() - 1);
  }
}

void ExpectIdentical(const EventFrames& a, const EventFrames& b) {
  ASSERT_EQ(a.num_frames(), b.num_frames());
  EXPECT_EQ(a.latent_timestamps_ns(), b.latent_timestamps_ns());
  for (int k = 0; k < a.num_frames(); ++k) {
    EXPECT_EQ(a.span(k).latent_first, b.span(k).latent_first);
    EXPECT_EQ(a.span(k).latent_last, b.span(k).latent_last);
    EXPECT_EQ(a.span(k).t_first_ns, b.span(k).t_first_ns);
    EXPECT_EQ(a.span(k).t_last_ns, b.span(k).t_last_ns);
    EXPECT_EQ(a.span(k).num_events, b.span(k).num_events);
    EXPECT_TRUE(
        std::equal(a.frame_data(k), a.frame_data(k) + a.pixels_per_frame(), b.frame_data(k)));
  }
}

/// Three collision frames in [0, 100): [0, 25), [25, 45), [45, 100).
EventStream SmallCaseEvents() {
  EventStream events(3, 2);
  events.push_back(10, 0, 0, 1);   // frame 0
  events.push_back(20, 1, 0, -1);  // frame 0
  events.push_back(30, 0, 0, -1);  // (0,0) fired in frame 0: opens frame 1
  events.push_back(40, 1, 1, 1);   // frame 1
  events.push_back(50, 0, 0, 1);   // (0,0) fired in frame 1: opens frame 2
  events.push_back(60, 1, 0, 1);   // (1,0) last fired in frame 0: stays in frame 2
  events.push_back(100, 2, 1, 1);  // at the exclusive window end: not binned
  return events;
}

TEST(BinByCollision, HandComputedSmallCase) {
  const EventStream events = SmallCaseEvents();
  const EventFrames frames = BinByCollision(events, 0, 100);

  ASSERT_EQ(frames.num_frames(), 3);
  EXPECT_EQ(frames.latent_timestamps_ns(), (std::vector<int64_t>{0, 25, 45, 100}));
  EXPECT_EQ(frames.value(0, 0, 0), 1.0f);
  EXPECT_EQ(frames.value(0, 0, 1), -1.0f);
  EXPECT_EQ(frames.value(1, 0, 0), -1.0f);
  EXPECT_EQ(frames.value(1, 1, 1), 1.0f);
  EXPECT_EQ(frames.value(2, 0, 0), 1.0f);
  EXPECT_EQ(frames.value(2, 0, 1), 1.0f);
  EXPECT_EQ(frames.value(2, 1, 2), 0.0f);
  EXPECT_DOUBLE_EQ(frames.TotalAbsoluteValue(), 6.0);
  const int64_t expected_times[3][2] = {{10, 20}, {30, 40}, {50, 60}};
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(frames.span(k).latent_first, k);
    EXPECT_EQ(frames.span(k).latent_last, k + 1);
    EXPECT_EQ(frames.span(k).t_first_ns, expected_times[k][0]);
    EXPECT_EQ(frames.span(k).t_last_ns, expected_times[k][1]);
    EXPECT_EQ(frames.span(k).num_events, 2);
  }
  ExpectValidTimeline(frames, 0, 100);
}

TEST(BinByCollision, EachPixelFiresAtMostOncePerFrameAndEveryEventCountsOnce) {
  const EventStream events = RandomEvents(5000, 0, 1000000, kSeed);
  const int64_t t_begin_ns = 100000;
  const int64_t t_end_ns = 900000;
  const EventFrames frames = BinByCollision(events, t_begin_ns, t_end_ns);
  const int64_t num_in_window = static_cast<int64_t>(events.Slice(t_begin_ns, t_end_ns).size());

  ASSERT_GT(frames.num_frames(), 1);
  EXPECT_EQ(frames.num_latent_frames(), frames.num_frames() + 1);
  int64_t total_events = 0;
  for (int k = 0; k < frames.num_frames(); ++k) {
    int64_t nonzero = 0;
    for (int64_t p = 0; p < frames.pixels_per_frame(); ++p) {
      const float value = frames.frame_data(k)[p];
      EXPECT_LE(std::abs(value), 1.0f);
      nonzero += value != 0.0f;
    }
    EXPECT_EQ(nonzero, frames.span(k).num_events) << "frame " << k;
    total_events += frames.span(k).num_events;
  }
  EXPECT_EQ(total_events, num_in_window);
  EXPECT_DOUBLE_EQ(frames.TotalAbsoluteValue(), static_cast<double>(num_in_window));
  EXPECT_EQ(FrameSums(frames), PolaritySums(events, t_begin_ns, t_end_ns));
  ExpectValidTimeline(frames, t_begin_ns, t_end_ns);
}

TEST(BinByCollision, IsDeterministic) {
  const EventStream events = RandomEvents(3000, 0, 500000, kSeed);
  ExpectIdentical(BinByCollision(events, 0, 500000), BinByCollision(events, 0, 500000));
}

TEST(BinByCollision, EmptyWindowGivesOneLatentStep) {
  const EventStream events = RandomEvents(100, 0, 1000, kSeed);
  const EventFrames frames = BinByCollision(events, 5000, 6000);
  EXPECT_EQ(frames.num_frames(), 0);
  EXPECT_EQ(frames.latent_timestamps_ns(), (std::vector<int64_t>{5000, 6000}));
  EXPECT_EQ(frames.width(), kWidth);
  EXPECT_EQ(frames.height(), kHeight);
}

TEST(BinByCollision, SinglePixelFiringRepeatedlyOpensAFrameEachTime) {
  EventStream events(4, 4);
  for (int i = 1; i <= 10; ++i) events.push_back(100 * i, 2, 3, i % 2 == 0 ? 1 : -1);
  const EventFrames frames = BinByCollision(events, 0, 1100);
  ASSERT_EQ(frames.num_frames(), 10);
  std::vector<int64_t> expected_latent = {0};
  for (int i = 1; i < 10; ++i) expected_latent.push_back(100 * i + 50);
  expected_latent.push_back(1100);
  EXPECT_EQ(frames.latent_timestamps_ns(), expected_latent);
  for (int k = 0; k < 10; ++k) {
    EXPECT_EQ(frames.span(k).num_events, 1);
    EXPECT_EQ(frames.value(k, 3, 2), k % 2 == 0 ? -1.0f : 1.0f);
  }
  ExpectValidTimeline(frames, 0, 1100);
}

TEST(BinByCollision, CoincidentBoundariesAreNudgedApartByOneNanosecond) {
  EventStream events(2, 2);
  for (int i = 0; i < 5; ++i) events.push_back(50, 1, 1, 1);
  const EventFrames frames = BinByCollision(events, 0, 100);
  ASSERT_EQ(frames.num_frames(), 5);
  EXPECT_EQ(frames.latent_timestamps_ns(), (std::vector<int64_t>{0, 50, 51, 52, 53, 100}));

  // Forward nudging would pass the window end here; the backward pass keeps it inside.
  const EventFrames tight = BinByCollision(events, 0, 53);
  EXPECT_EQ(tight.latent_timestamps_ns(), (std::vector<int64_t>{0, 49, 50, 51, 52, 53}));

  // Five latent steps cannot fit in a window of two nanoseconds.
  EXPECT_THROW(BinByCollision(events, 50, 52), InvalidArgumentError);
}

TEST(BinByCollision, SplitsTheLongestCollisionFramesUntilTheWindowHasTheStepsAskedFor) {
  const EventStream events = SmallCaseEvents();
  // Six steps: the 55 ns frame gets a second part (27.5 ns), then a third (18.3 ns), then the
  // 25 ns frame a second (12.5 ns), which leaves the 20 ns frame the longest part.
  const EventFrames frames = BinByCollision(events, 0, 100, 6);
  ASSERT_EQ(frames.num_frames(), 6);
  EXPECT_EQ(frames.latent_timestamps_ns(), (std::vector<int64_t>{0, 12, 25, 45, 63, 81, 100}));
  const int64_t expected_events[6] = {1, 1, 2, 2, 0, 0};
  for (int k = 0; k < 6; ++k) {
    EXPECT_EQ(frames.span(k).latent_first, k);
    EXPECT_EQ(frames.span(k).latent_last, k + 1);
    EXPECT_EQ(frames.span(k).num_events, expected_events[k]) << "frame " << k;
  }
  EXPECT_EQ(frames.value(0, 0, 0), 1.0f);
  EXPECT_EQ(frames.value(1, 0, 1), -1.0f);
  EXPECT_EQ(frames.value(2, 0, 0), -1.0f);
  EXPECT_EQ(frames.value(2, 1, 1), 1.0f);
  EXPECT_EQ(frames.value(3, 0, 0), 1.0f);
  EXPECT_EQ(frames.value(3, 0, 1), 1.0f);
  // An empty part sits at its own start.
  EXPECT_EQ(frames.span(4).t_first_ns, 63);
  EXPECT_EQ(frames.span(5).t_last_ns, 81);
  ExpectValidTimeline(frames, 0, 100);
  // Asking for no more steps than the collision frames give changes nothing.
  ExpectIdentical(BinByCollision(events, 0, 100, 3), BinByCollision(events, 0, 100));
}

TEST(BinByCollision, SplitFramesStayCollisionFreeAndKeepTheCollisionBoundaries) {
  const EventStream events = RandomEvents(300, 0, 1000000, kSeed);
  const EventFrames plain = BinByCollision(events, 100000, 900000);
  const int steps = plain.num_frames() * 3 + 7;
  const EventFrames split = BinByCollision(events, 100000, 900000, steps);
  ASSERT_EQ(split.num_frames(), steps);
  EXPECT_EQ(CollisionLatentSteps(plain.num_frames(), steps, 800000), steps);
  for (int k = 0; k < split.num_frames(); ++k) {
    int64_t nonzero = 0;
    for (int64_t p = 0; p < split.pixels_per_frame(); ++p) {
      EXPECT_LE(std::abs(split.frame_data(k)[p]), 1.0f);
      nonzero += split.frame_data(k)[p] != 0.0f;
    }
    EXPECT_EQ(nonzero, split.span(k).num_events) << "frame " << k;
  }
  EXPECT_EQ(FrameSums(split), FrameSums(plain));
  const std::vector<int64_t>& fine = split.latent_timestamps_ns();
  for (const int64_t t : plain.latent_timestamps_ns()) {
    EXPECT_TRUE(std::binary_search(fine.begin(), fine.end(), t)) << t;
  }
  ExpectValidTimeline(split, 100000, 900000);
  // The parts are as even as whole frames allow: none is twice the shortest frame's part.
  int64_t longest = 0;
  for (size_t k = 0; k + 1 < fine.size(); ++k) longest = std::max(longest, fine[k + 1] - fine[k]);
  EXPECT_LE(longest, 2 * 800000 / steps + 1);
}

TEST(BinByCollision, AWindowWithoutEventsIsNotSplit) {
  const EventStream events = RandomEvents(100, 0, 1000, kSeed);
  const EventFrames frames = BinByCollision(events, 5000, 6000, 16);
  EXPECT_EQ(frames.num_frames(), 0);
  EXPECT_EQ(frames.latent_timestamps_ns(), (std::vector<int64_t>{5000, 6000}));
  EXPECT_EQ(CollisionLatentSteps(0, 16, 1000), 1);
}

TEST(BinByCollision, PartsAreNeverShorterThanOneNanosecond) {
  EventStream events(2, 1);
  events.push_back(1, 0, 0, 1);
  events.push_back(2, 0, 0, -1);
  const EventFrames frames = BinByCollision(events, 0, 4, 100);
  EXPECT_EQ(frames.latent_timestamps_ns(), (std::vector<int64_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(CollisionLatentSteps(2, 100, 4), 4);
  EXPECT_DOUBLE_EQ(frames.TotalAbsoluteValue(), 2.0);
  ExpectValidTimeline(frames, 0, 4);
}

TEST(BinByCollision, RejectsBadWindowsAndEvents) {
  const EventStream events = RandomEvents(10, 0, 100, kSeed);
  EXPECT_THROW(BinByCollision(events, 100, 100), InvalidArgumentError);
  EXPECT_THROW(BinByCollision(events, 100, 0), InvalidArgumentError);

  EventStream off_sensor(2, 2);
  off_sensor.push_back(5, 2, 0, 1);
  EXPECT_THROW(BinByCollision(off_sensor, 0, 10), InvalidArgumentError);

  EventStream bad_polarity(2, 2);
  bad_polarity.push_back(5, 0, 0, 0);
  EXPECT_THROW(BinByCollision(bad_polarity, 0, 10), InvalidArgumentError);
}

TEST(BinStacked, HandComputedEqualTime) {
  EventStream events(2, 1);
  events.push_back(10, 0, 0, 1);
  events.push_back(20, 0, 0, 1);
  events.push_back(30, 1, 0, -1);
  events.push_back(80, 0, 0, 1);
  events.push_back(99, 0, 0, -1);
  StackedBinningOptions options;
  options.num_frames = 4;
  const EventFrames frames = BinStacked(events, 0, 100, options);

  ASSERT_EQ(frames.num_frames(), 4);
  EXPECT_EQ(frames.latent_timestamps_ns(), (std::vector<int64_t>{0, 25, 50, 75, 100}));
  EXPECT_EQ(frames.value(0, 0, 0), 2.0f);
  EXPECT_EQ(frames.value(1, 0, 1), -1.0f);
  EXPECT_EQ(frames.value(3, 0, 0), 0.0f);  // +1 and -1 cancel
  const int64_t expected_counts[4] = {2, 1, 0, 2};
  for (int m = 0; m < 4; ++m) EXPECT_EQ(frames.span(m).num_events, expected_counts[m]);
  EXPECT_EQ(frames.span(2).t_first_ns, 50);  // empty: its start boundary
  EXPECT_EQ(frames.span(2).t_last_ns, 50);
  EXPECT_EQ(frames.span(3).t_first_ns, 80);
  EXPECT_EQ(frames.span(3).t_last_ns, 99);

  options.steps_per_frame = 2;
  const EventFrames substeps = BinStacked(events, 0, 100, options);
  EXPECT_EQ(substeps.latent_timestamps_ns(),
            (std::vector<int64_t>{0, 12, 25, 37, 50, 62, 75, 87, 100}));
  EXPECT_EQ(substeps.span(1).latent_first, 2);
  EXPECT_EQ(substeps.span(1).latent_last, 4);
  ExpectValidTimeline(substeps, 0, 100);
}

TEST(BinStacked, HandComputedEqualCount) {
  EventStream events(1, 1);
  for (int i = 1; i <= 6; ++i) events.push_back(10 * i, 0, 0, 1);
  StackedBinningOptions options;
  options.num_frames = 3;
  options.split = StackedBinningOptions::Split::kEqualCount;
  const EventFrames frames = BinStacked(events, 0, 100, options);
  EXPECT_EQ(frames.latent_timestamps_ns(), (std::vector<int64_t>{0, 25, 45, 100}));
  for (int m = 0; m < 3; ++m) {
    EXPECT_EQ(frames.span(m).num_events, 2);
    EXPECT_EQ(frames.value(m, 0, 0), 2.0f);
  }
}

TEST(BinStacked, EveryEventCountsOnceInBothSplits) {
  const EventStream events = RandomEvents(5000, 0, 1000000, kSeed);
  const int64_t t_begin_ns = 50000;
  const int64_t t_end_ns = 950000;
  const int64_t num_in_window = static_cast<int64_t>(events.Slice(t_begin_ns, t_end_ns).size());
  for (const auto split :
       {StackedBinningOptions::Split::kEqualTime, StackedBinningOptions::Split::kEqualCount}) {
    for (const int steps : {1, 3}) {
      SCOPED_TRACE(::testing::Message()
                   << "split " << static_cast<int>(split) << ", steps " << steps);
      StackedBinningOptions options;
      options.num_frames = 7;
      options.split = split;
      options.steps_per_frame = steps;
      const EventFrames frames = BinStacked(events, t_begin_ns, t_end_ns, options);
      ASSERT_EQ(frames.num_frames(), 7);
      EXPECT_EQ(frames.num_latent_frames(), 7 * steps + 1);
      int64_t total_events = 0;
      for (const EventFrameSpan& span : frames.spans()) {
        total_events += span.num_events;
        if (split == StackedBinningOptions::Split::kEqualCount) {
          // Ties in time may move an event across a boundary; the random times have few.
          constexpr int64_t kCountSlack = 3;
          EXPECT_NEAR(span.num_events, num_in_window / 7, kCountSlack);
        }
      }
      EXPECT_EQ(total_events, num_in_window);
      EXPECT_EQ(FrameSums(frames), PolaritySums(events, t_begin_ns, t_end_ns));
      ExpectValidTimeline(frames, t_begin_ns, t_end_ns);
    }
  }
}

TEST(BinStacked, IsDeterministic) {
  const EventStream events = RandomEvents(3000, 0, 500000, kSeed);
  StackedBinningOptions options;
  options.split = StackedBinningOptions::Split::kEqualCount;
  options.steps_per_frame = 2;
  ExpectIdentical(BinStacked(events, 0, 500000, options), BinStacked(events, 0, 500000, options));
}

TEST(BinStacked, EqualCountWithFewerEventsThanFramesFallsBackToEqualTime) {
  const EventStream events = RandomEvents(3, 0, 1000, kSeed);
  StackedBinningOptions equal_count;
  equal_count.split = StackedBinningOptions::Split::kEqualCount;
  const StackedBinningOptions equal_time;
  ExpectIdentical(BinStacked(events, 0, 1000, equal_count),
                  BinStacked(events, 0, 1000, equal_time));

  const EventFrames empty = BinStacked(events, 2000, 3000, equal_count);
  EXPECT_EQ(empty.num_frames(), equal_count.num_frames);
  EXPECT_DOUBLE_EQ(empty.TotalAbsoluteValue(), 0.0);
  ExpectValidTimeline(empty, 2000, 3000);
}

TEST(BinStacked, EqualCountSeparatesTiedBoundaries) {
  EventStream events(2, 2);
  for (int i = 0; i < 8; ++i) events.push_back(500, 0, 1, -1);
  StackedBinningOptions options;
  options.num_frames = 4;
  options.steps_per_frame = 2;
  options.split = StackedBinningOptions::Split::kEqualCount;
  const EventFrames frames = BinStacked(events, 0, 1000, options);
  // All boundaries fall on t = 500; they are spread 2 ns (one per latent step) apart, and all
  // events land in the frame that starts at 500.
  EXPECT_EQ(frames.latent_timestamps_ns(),
            (std::vector<int64_t>{0, 250, 500, 501, 502, 503, 504, 752, 1000}));
  EXPECT_EQ(frames.span(1).num_events, 8);
  EXPECT_EQ(frames.value(1, 1, 0), -8.0f);
  ExpectValidTimeline(frames, 0, 1000);
}

TEST(BinStacked, RejectsInvalidOptionsAndShortWindows) {
  const EventStream events = RandomEvents(10, 0, 100, kSeed);
  StackedBinningOptions options;
  std::string error;
  EXPECT_TRUE(options.IsValid(&error));
  options.num_frames = 0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("num_frames"), std::string::npos);
  EXPECT_THROW(BinStacked(events, 0, 100, options), InvalidArgumentError);

  options = StackedBinningOptions();
  options.steps_per_frame = 0;
  EXPECT_FALSE(options.IsValid(nullptr));

  options = StackedBinningOptions();
  options.num_frames = 10;
  options.steps_per_frame = 20;
  EXPECT_THROW(BinStacked(events, 0, 100, options), InvalidArgumentError);  // 200 steps > 100 ns
  EXPECT_THROW(BinStacked(events, 100, 0, StackedBinningOptions()), InvalidArgumentError);

  // M · S must stay an int latent index.
  options = StackedBinningOptions();
  options.num_frames = 1 << 16;
  options.steps_per_frame = 1 << 16;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("num_frames * steps_per_frame"), std::string::npos) << error;
}

// Regression: a window too short for the frames was found only after allocating one
// boundary per frame (16 GB for 2^31 - 2 frames); it is refused first.
TEST(BinStacked, ShortWindowIsRefusedBeforeAllocating) {
  const EventStream events = RandomEvents(10, 0, 100, kSeed);
  StackedBinningOptions options;
  options.num_frames = std::numeric_limits<int>::max() - 1;
  EXPECT_THROW(BinStacked(events, 0, 100, options), InvalidArgumentError);
}

TEST(CountCollisionFrames, AgreesWithBinByCollision) {
  const EventStream events = RandomEvents(5000, 0, 1000000, kSeed);
  for (const auto& [begin_ns, end_ns] : std::vector<std::pair<int64_t, int64_t>>{
           {0, 1000000}, {100000, 900000}, {5000, 6000}, {0, 1}, {999999, 2000000}}) {
    EXPECT_EQ(CountCollisionFrames(events, begin_ns, end_ns),
              BinByCollision(events, begin_ns, end_ns).num_frames())
        << begin_ns << ", " << end_ns;
  }
  EventStream one_pixel(4, 4);
  for (int i = 1; i <= 10; ++i) one_pixel.push_back(100 * i, 2, 3, 1);
  EXPECT_EQ(CountCollisionFrames(one_pixel, 0, 1100), 10);
  EXPECT_THROW(CountCollisionFrames(one_pixel, 10, 10), InvalidArgumentError);
  EventStream off_sensor(2, 2);
  off_sensor.push_back(5, 2, 0, 1);
  EXPECT_THROW(CountCollisionFrames(off_sensor, 0, 10), InvalidArgumentError);
}

TEST(MeasurePixelActivity, HandComputedHotPixel) {
  // 300 pixels fire once or twice, pixel (1, 0) 25 times: the reference is the busiest pixel
  // outside the busiest 1 % (rank 3), which fired twice.
  EventStream events(20, 20);
  int64_t t_ns = 0;
  for (int p = 0; p < 300; ++p) {
    const int repeats = p < 100 ? 2 : 1;
    for (int r = 0; r < repeats; ++r) {
      events.push_back(++t_ns, static_cast<uint16_t>(p % 20), static_cast<uint16_t>(p / 20), 1);
    }
  }
  // Pixel 1 already fired twice above; 23 more make 25.
  for (int i = 0; i < 23; ++i) events.push_back(++t_ns, 1, 0, i % 2 ? 1 : -1);
  const PixelActivity activity = MeasurePixelActivity(events, 0, t_ns + 1, 10.0);
  EXPECT_EQ(activity.num_events, 423);
  EXPECT_EQ(activity.pixels_fired, 300);
  EXPECT_EQ(activity.busiest_count, 25);
  EXPECT_EQ(activity.reference_count, 2);
  EXPECT_EQ(activity.hot_pixels, std::vector<int32_t>{1});
  EXPECT_EQ(activity.hot_pixel_events, 25);
  // 25 is not more than 12.5 times 2; a factor of 0 finds none.
  EXPECT_TRUE(MeasurePixelActivity(events, 0, t_ns + 1, 12.5).hot_pixels.empty());
  EXPECT_TRUE(MeasurePixelActivity(events, 0, t_ns + 1, 0.0).hot_pixels.empty());
}

TEST(MeasurePixelActivity, OnePixelAloneIsNotHot) {
  EventStream events(4, 4);
  for (int i = 1; i <= 1000; ++i) events.push_back(i, 2, 3, 1);
  const PixelActivity alone = MeasurePixelActivity(events, 0, 1001, 10.0);
  EXPECT_EQ(alone.pixels_fired, 1);
  EXPECT_TRUE(alone.hot_pixels.empty());
  // With a second pixel to compare with, it is.
  events.push_back(1001, 0, 0, 1);
  const PixelActivity pair = MeasurePixelActivity(events, 0, 1002, 10.0);
  EXPECT_EQ(pair.reference_count, 1);
  EXPECT_EQ(pair.hot_pixels, std::vector<int32_t>{3 * 4 + 2});
  EXPECT_EQ(pair.hot_pixel_events, 1000);
  const PixelActivity empty = MeasurePixelActivity(events, 5000, 6000, 10.0);
  EXPECT_EQ(empty.num_events, 0);
  EXPECT_EQ(empty.pixels_fired, 0);
}

TEST(WithoutPixels, DropsExactlyThosePixels) {
  const EventStream events = RandomEvents(2000, 0, 100000, kSeed);
  const std::vector<int32_t> dropped = {0, 5, kWidth * kHeight - 1};
  const EventStream kept = WithoutPixels(events, dropped);
  EXPECT_EQ(kept.width(), kWidth);
  EXPECT_EQ(kept.height(), kHeight);
  size_t expected = 0;
  for (size_t i = 0; i < events.size(); ++i) {
    const int32_t pixel = events.y(i) * kWidth + events.x(i);
    expected += std::find(dropped.begin(), dropped.end(), pixel) == dropped.end();
  }
  ASSERT_EQ(kept.size(), expected);
  EXPECT_TRUE(kept.IsSorted());
  for (size_t i = 0; i < kept.size(); ++i) {
    const int32_t pixel = kept.y(i) * kWidth + kept.x(i);
    EXPECT_EQ(std::find(dropped.begin(), dropped.end(), pixel), dropped.end());
  }
  EXPECT_EQ(WithoutPixels(events, {}), events);
}

}  // namespace
}  // namespace evfs
