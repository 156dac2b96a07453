#include "events/noise_filter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <tuple>
#include <vector>

#include "events/random.h"

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

}  // namespace
}  // namespace evfs
