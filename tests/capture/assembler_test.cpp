#include <gtest/gtest.h>

#include "tega/capture/frame_set_assembler.h"

namespace tega::capture {
namespace {

constexpr int64_t kMs = 1'000'000;

Frame frame_of(int camera, uint64_t id) {
  Frame f;
  f.camera = camera;
  f.frame_id = id;
  return f;
}

TEST(FrameSetAssembler, GroupsFramesWithinTheToleranceAndClosesCompleteSets) {
  FrameSetAssembler a(3, 5 * kMs, 1000 * kMs);
  EXPECT_TRUE(a.add(frame_of(0, 1), 100 * kMs, 0).empty());
  EXPECT_TRUE(a.add(frame_of(2, 1), 103 * kMs, 0).empty());
  const auto closed = a.add(frame_of(1, 1), 98 * kMs, 0);
  ASSERT_EQ(closed.size(), 1u);
  EXPECT_TRUE(closed[0].complete());
  EXPECT_EQ(closed[0].frames[2]->frame_id, 1u);
  EXPECT_EQ(a.open_sets(), 0u);
}

TEST(FrameSetAssembler, ASetMissingACameraClosesOnceThatCameraMovedPast) {
  FrameSetAssembler a(2, 5 * kMs, 1000 * kMs);
  a.add(frame_of(0, 1), 100 * kMs, 0);
  // Camera 1 missed the first instant; its next frame belongs to the second set.
  const auto closed = a.add(frame_of(1, 2), 133 * kMs, 0);
  ASSERT_EQ(closed.size(), 1u);
  EXPECT_FALSE(closed[0].complete());
  EXPECT_EQ(closed[0].key, 100 * kMs);
  const auto second = a.add(frame_of(0, 2), 134 * kMs, 0);
  ASSERT_EQ(second.size(), 1u);
  EXPECT_TRUE(second[0].complete());
}

TEST(FrameSetAssembler, SetsBeforeACameraStartedStreamingAreMarkedAsSuch) {
  FrameSetAssembler a(2, 5 * kMs, 50 * kMs);
  a.add(frame_of(0, 1), 100 * kMs, 0);
  // Camera 1's first frame comes an instant later: the first set closes without it.
  const auto first = a.add(frame_of(1, 1), 133 * kMs, 0);
  ASSERT_EQ(first.size(), 1u);
  EXPECT_TRUE(first[0].before_all_streaming);
  EXPECT_TRUE(a.add(frame_of(0, 2), 134 * kMs, 0)[0].complete());
  // Once both stream, a missed instant is a true gap.
  a.add(frame_of(0, 3), 166 * kMs, 0);
  const auto gap = a.add(frame_of(1, 4), 200 * kMs, 0);
  ASSERT_EQ(gap.size(), 1u);
  EXPECT_FALSE(gap[0].complete());
  EXPECT_FALSE(gap[0].before_all_streaming);

  // A camera that has delivered nothing yet when the set times out has not started either.
  FrameSetAssembler silent(2, 5 * kMs, 50 * kMs);
  silent.add(frame_of(0, 1), 100 * kMs, 0);
  const auto timed_out = silent.tick(60 * kMs);
  ASSERT_EQ(timed_out.size(), 1u);
  EXPECT_TRUE(timed_out[0].before_all_streaming);
}

TEST(FrameSetAssembler, TimeoutAndLostCamerasCloseSetsInOrder) {
  FrameSetAssembler a(2, 5 * kMs, 50 * kMs);
  a.add(frame_of(0, 1), 100 * kMs, 0);
  EXPECT_TRUE(a.tick(10 * kMs).empty());
  EXPECT_EQ(a.tick(60 * kMs).size(), 1u);

  a.add(frame_of(0, 2), 200 * kMs, 100 * kMs);
  a.add(frame_of(0, 3), 233 * kMs, 100 * kMs);
  const auto closed = a.drop_camera(1, 100 * kMs);
  ASSERT_EQ(closed.size(), 2u);
  EXPECT_LT(closed[0].key, closed[1].key);
  // Frames of a dropped camera, and frames for a set already closed, are counted, not grouped.
  a.add(frame_of(1, 4), 266 * kMs, 100 * kMs);
  a.add(frame_of(0, 1), 199 * kMs, 100 * kMs);
  EXPECT_EQ(a.late_frames()[1], 1);
  EXPECT_EQ(a.late_frames()[0], 1);
}

TEST(FrameSetAssembler, FrameIdsGroupExactly) {
  FrameSetAssembler a(2, 0, 1000 * kMs);
  a.add(frame_of(0, 7), 7, 0);
  a.add(frame_of(0, 8), 8, 0);
  const auto closed = a.add(frame_of(1, 8), 8, 0);
  ASSERT_EQ(closed.size(), 2u);  // set 7 lacks camera 1, which has moved on to 8
  EXPECT_FALSE(closed[0].complete());
  EXPECT_TRUE(closed[1].complete());
}

TEST(FrameIdUnwrapper, SixteenBitCountersKeepCountingAcrossTheWrap) {
  FrameIdUnwrapper unwrap(16);
  EXPECT_EQ(unwrap(65534), 65534);
  EXPECT_EQ(unwrap(65535), 65535);
  EXPECT_EQ(unwrap(1), 65537);  // GigE Vision skips block id 0
  EXPECT_EQ(unwrap(2), 65538);
  EXPECT_EQ(unwrap(1), 65537);  // a late frame, not a second wrap
}

}  // namespace
}  // namespace tega::capture
