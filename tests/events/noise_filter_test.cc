#include "evfs/events/noise_filter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <tuple>
#include <vector>

#include "evfs/events/random.h"

namespace evfs {
namespace {

constexpr int64_t kMs = 1000000;

TEST(NoiseFilter, KeepsEventsThatANeighbourConfirmsEitherSideInTime) {
  EventStream events(8, 6);
  events.push_back(0 * kMs, 3, 3, 1);    // supported by (4, 3) 2 ms later (looking forward)
  events.push_back(2 * kMs, 4, 3, 1);    // supported by (3, 3) 2 ms before
  events.push_back(3 * kMs, 0, 0, -1);   // alone: its only pixel neighbour fires 10 ms later
  events.push_back(13 * kMs, 1, 1, 1);   // diagonal neighbour of (0, 0), 10 ms from it
  events.push_back(14 * kMs, 3, 3, -1);  // same pixel as the first: not its own support
  int64_t removed = -1;
  const EventStream kept = WithoutUnsupportedEvents(events, 5 * kMs, &removed);
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_EQ(removed, 3);
  EXPECT_EQ(kept.x(0), 3);
  EXPECT_EQ(kept.t_ns(0), 0);
  EXPECT_EQ(kept.x(1), 4);
  EXPECT_EQ(kept.width(), 8);
  EXPECT_EQ(kept.height(), 6);

  // A window reaching 10 ms confirms the corner pair too; the lone event at (3, 3) is 12 ms
  // from the nearest neighbour's.
  const EventStream wider = WithoutUnsupportedEvents(events, 10 * kMs, &removed);
  EXPECT_EQ(wider.size(), 4u);
  EXPECT_EQ(removed, 1);
}

TEST(NoiseFilter, ZeroWindowKeepsEverythingAndWindowIsInclusive) {
  EventStream events(4, 4);
  events.push_back(0, 0, 0, 1);
  events.push_back(7, 1, 0, 1);
  int64_t removed = -1;
  EXPECT_EQ(WithoutUnsupportedEvents(events, 0, &removed), events);
  EXPECT_EQ(removed, 0);
  EXPECT_EQ(WithoutUnsupportedEvents(events, 7).size(), 2u);
  EXPECT_EQ(WithoutUnsupportedEvents(events, 6).size(), 0u);
  EXPECT_TRUE(WithoutUnsupportedEvents(EventStream(4, 4), 5).empty());
}

TEST(NoiseFilter, EventsOffTheSensorAreLeftForTheBinningToReject) {
  EventStream events(4, 4);
  events.push_back(0, 9, 0, 1);
  EXPECT_EQ(WithoutUnsupportedEvents(events, kMs).size(), 1u);
}

// An edge sweeping across a sensor is kept whole while uniform background activity at 1 Hz per
// pixel, the rate of a DAVIS240 in the dark, is almost all removed.
TEST(NoiseFilter, SeparatesAMovingEdgeFromBackgroundActivity) {
  constexpr int kWidth = 60, kHeight = 40;
  Random random(7);
  std::vector<std::tuple<int64_t, int, int, bool>> all;  // t, x, y, is noise
  for (int x = 0; x < kWidth; ++x) {                     // a vertical edge at 2 px/ms
    for (int y = 0; y < kHeight; ++y) all.emplace_back(x * kMs / 2, x, y, false);
  }
  const int64_t duration_ns = 30 * kMs;
  const int noise = static_cast<int>(kWidth * kHeight * 1.0 * duration_ns / 1e9);  // 1 Hz
  for (int i = 0; i < noise; ++i) {
    all.emplace_back(static_cast<int64_t>(random.UniformIndex(duration_ns)),
                     static_cast<int>(random.UniformIndex(kWidth)),
                     static_cast<int>(random.UniformIndex(kHeight)), true);
  }
  std::sort(all.begin(), all.end());
  EventStream events(kWidth, kHeight);
  for (const auto& [t, x, y, is_noise] : all) events.push_back(t, x, y, is_noise ? -1 : 1);
  const EventStream kept = WithoutUnsupportedEvents(events, 2 * kMs);
  int edge = 0, noise_kept = 0;
  for (size_t i = 0; i < kept.size(); ++i) (kept.polarity(i) > 0 ? edge : noise_kept) += 1;
  EXPECT_EQ(edge, kWidth * kHeight);
  ASSERT_GT(noise, 50);
  // A noise event survives only next to the edge or another noise event within 2 ms.
  EXPECT_LT(noise_kept, noise / 4) << noise_kept << " of " << noise;
}

// A pixel under a light blinking at 500 Hz fires bursts of alternating sign; an edge crossing
// another pixel fires one run of one sign and a bar crossing a third fires one run of each.
TEST(FlickeringPixels, FindsAlternatingBurstsWithNoNetChange) {
  constexpr int kWidth = 6, kHeight = 4;
  EventStream events(kWidth, kHeight);
  const int32_t led = 1 * kWidth + 2;  // the edge is at (4, 2), the bar at (0, 3)
  for (int period = 0; period < 10; ++period) {
    const int64_t t = period * 2 * kMs;
    events.push_back(t, 2, 1, 1);
    events.push_back(t + kMs / 10, 2, 1, 1);
    events.push_back(t + kMs, 2, 1, -1);
    events.push_back(t + kMs + kMs / 10, 2, 1, -1);
    if (period < 4) events.push_back(t + kMs / 2, 4, 2, 1);
    if (period == 2) events.push_back(t + kMs / 3, 0, 3, 1);
    if (period == 3) events.push_back(t + kMs / 3, 0, 3, -1);
  }
  int64_t at = -1;
  const std::vector<int32_t> found = FindFlickeringPixels(events, 0, 20 * kMs, 3, &at);
  ASSERT_EQ(found, std::vector<int32_t>({led}));
  EXPECT_EQ(at, 40);
  // Within a window holding two periods the LED reverses 3 times: still flickering at 3.
  EXPECT_EQ(FindFlickeringPixels(events, 0, 4 * kMs, 3), std::vector<int32_t>({led}));
  EXPECT_TRUE(FindFlickeringPixels(events, 0, 4 * kMs, 4).empty());
  EXPECT_TRUE(FindFlickeringPixels(events, 0, 20 * kMs, 0).empty());
}

// Alternating events that add up to a large net change are the scene, not a light: a texture
// crossing the pixel while it brightens overall.
TEST(FlickeringPixels, KeepsPixelsWhoseEventsAddUpToAChange) {
  EventStream events(2, 2);
  int64_t t = 0;
  for (int run = 0; run < 4; ++run) {
    for (int k = 0; k < 4; ++k) events.push_back(t += kMs, 0, 0, 1);
    events.push_back(t += kMs, 0, 0, -1);
  }
  // 16 ON, 4 OFF: |net| 12 is more than a quarter of 20 events, though it reversed 7 times.
  EXPECT_TRUE(FindFlickeringPixels(events, 0, t + 1, 3).empty());
}

}  // namespace
}  // namespace evfs
