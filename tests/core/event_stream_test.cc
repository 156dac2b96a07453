#include "evfs/core/event_stream.h"

#include <gtest/gtest.h>

#include "evfs/core/event_frames.h"

namespace evfs {
namespace {

EventStream MakeStream() {
  EventStream events(4, 3);
  events.push_back(10, 0, 0, 1);
  events.push_back(20, 1, 2, -1);
  events.push_back(20, 3, 1, 1);
  events.push_back(35, 2, 2, 1);
  return events;
}

TEST(EventStream, SliceIsHalfOpenInTime) {
  const EventStream events = MakeStream();
  const EventStream slice = events.Slice(20, 35);
  ASSERT_EQ(slice.size(), 2u);
  EXPECT_EQ(slice.x(0), 1);
  EXPECT_EQ(slice.x(1), 3);
  EXPECT_EQ(slice.width(), 4);
  EXPECT_EQ(slice.height(), 3);
  EXPECT_TRUE(events.Slice(36, 100).empty());
  EXPECT_TRUE(events.Slice(30, 10).empty());
}

TEST(EventStream, AppendCountAndCompare) {
  EventStream events = MakeStream();
  EXPECT_TRUE(events.IsSorted());
  EXPECT_EQ(events.CountPositive(), 3u);
  EventStream copy = events.SliceIndex(0, 2);
  copy.Append(events.SliceIndex(2, 4));
  EXPECT_EQ(copy, events);
  copy.push_back(5, 0, 0, 1);
  EXPECT_FALSE(copy.IsSorted());
  EXPECT_FALSE(copy == events);
}

TEST(EventFrames, AddFrameAllocatesZeroedValues) {
  EventFrames frames(2, 3);
  const int k = frames.AddFrame({0, 1, 10, 20, 2});
  frames.value(k, 1, 2) = -1.0f;
  frames.AddFrame({1, 2, 30, 30, 1});
  frames.value(1, 0, 0) = 1.0f;
  EXPECT_EQ(frames.num_frames(), 2);
  EXPECT_EQ(frames.frame_data(0)[5], -1.0f);
  EXPECT_EQ(frames.frame_data(1)[0], 1.0f);
  EXPECT_DOUBLE_EQ(frames.TotalAbsoluteValue(), 2.0);
}

}  // namespace
}  // namespace evfs
