#include "tega/core/dataset_gaps.h"

#include <gtest/gtest.h>

#include "tega/core/error.h"
#include "test_support.h"

namespace {

// In memory only: 6 cameras (c5 held out), train frames t0..t7, test frames s0, s1.
tega::Dataset gappy_dataset() {
  tega::Dataset d;
  for (int c = 0; c < 6; ++c) {
    tega::Camera camera;
    camera.name = "c" + std::to_string(c);
    d.rig.cameras.push_back(camera);
    (c < 5 ? d.train : d.test).cameras.push_back(camera.name);
  }
  for (int f = 0; f < 8; ++f) {
    d.frames.push_back({"t" + std::to_string(f), "train", {}});
    d.train.frames.push_back(d.frames.back().id);
  }
  for (int f = 0; f < 2; ++f) {
    d.frames.push_back({"s" + std::to_string(f), "test", {}});
    d.test.frames.push_back(d.frames.back().id);
  }
  return d;
}

void leave_out(tega::Dataset& d, const std::string& frame, const std::vector<std::string>& cameras) {
  for (const auto& c : cameras) d.missing_images.push_back({c, frame, c + "/" + frame + ".png: is missing"});
}

const tega::MissingImageLimits kDefaultLimits;

TEST(DatasetGaps, AFrameMostCamerasLackIsDroppedAndOneMissingAFewIsKeptWithItsGaps) {
  tega::Dataset d = gappy_dataset();
  leave_out(d, "t1", {"c0", "c1", "c2", "c5"});  // 2 of 6 usable: below half
  leave_out(d, "t2", {"c0"});
  leave_out(d, "t3", {"c1", "c2", "c3"});  // exactly half usable: kept
  tega::apply_missing_image_limits(d, kDefaultLimits, "capture", "restore the images");

  ASSERT_EQ(d.dropped_frames.size(), 1u);
  EXPECT_EQ(d.dropped_frames[0].frame, "t1");
  EXPECT_NE(d.dropped_frames[0].reason.find("usable images from 2 of 6 cameras"), std::string::npos)
      << d.dropped_frames[0].reason;
  EXPECT_NE(d.dropped_frames[0].reason.find("c0/t1.png: is missing"), std::string::npos) << d.dropped_frames[0].reason;
  EXPECT_EQ(d.train.frames, (std::vector<std::string>{"t0", "t2", "t3", "t4", "t5", "t6", "t7"}));
  EXPECT_EQ(d.frames.size(), 9u);
  EXPECT_EQ(d.missing_images.size(), 4u);  // t1's went with it
  EXPECT_FALSE(d.has_image("c0", "t2"));
  EXPECT_TRUE(d.has_image("c0", "t3"));
  EXPECT_EQ(tega::dataset_gap_summary(d), "4 missing images (c0: 1, c1: 1, c2: 1, c3: 1), 1 dropped frame");
  EXPECT_EQ(tega::dataset_gap_summary(gappy_dataset()), "");
}

TEST(DatasetGaps, ACameraMissingMostFramesStopsNamingIt) {
  tega::Dataset d = gappy_dataset();
  for (const char* frame : {"t0", "t1", "t2", "t3", "t4", "s1"}) leave_out(d, frame, {"c4"});
  const std::string message = tega::test::error_message(
      [&] { tega::apply_missing_image_limits(d, kDefaultLimits, "CAPTURE", "restore the images"); });
  EXPECT_NE(message.find("CAPTURE: camera c4 has no usable image of 6 of the 10 frames"), std::string::npos) << message;
  EXPECT_NE(message.find("missing_images.max_missing_fraction_per_camera = 0.5"), std::string::npos) << message;
  EXPECT_NE(message.find("first: frame t0, c4/t0.png: is missing"), std::string::npos) << message;
  EXPECT_NE(message.find("restore the images"), std::string::npos) << message;

  tega::MissingImageLimits lenient;
  lenient.max_missing_fraction_per_camera = 0.6;
  tega::Dataset kept = gappy_dataset();
  for (const char* frame : {"t0", "t1", "t2", "t3", "t4", "s1"}) leave_out(kept, frame, {"c4"});
  tega::apply_missing_image_limits(kept, lenient, "CAPTURE", "restore the images");
  EXPECT_EQ(kept.missing_images.size(), 6u);
}

TEST(DatasetGaps, TooManyDroppedFramesOrAnEmptySplitStops) {
  tega::Dataset d = gappy_dataset();
  for (const char* frame : {"t0", "t4", "t6"}) leave_out(d, frame, {"c0", "c1", "c2", "c3"});
  const std::string message = tega::test::error_message(
      [&] { tega::apply_missing_image_limits(d, kDefaultLimits, "CAPTURE", "restore the images"); });
  EXPECT_NE(message.find("3 of 8 train frames lack too many images"), std::string::npos) << message;
  EXPECT_NE(message.find("max_dropped_frame_fraction = 0.25"), std::string::npos) << message;

  tega::Dataset no_test = gappy_dataset();
  for (const char* frame : {"s0", "s1"}) leave_out(no_test, frame, {"c0", "c1", "c2", "c3", "c4", "c5"});
  tega::MissingImageLimits lenient;
  lenient.max_dropped_frame_fraction = 1;
  const std::string empty = tega::test::error_message(
      [&] { tega::apply_missing_image_limits(no_test, lenient, "CAPTURE", "restore the images"); });
  EXPECT_NE(empty.find("every test frame (2) lacks too many images"), std::string::npos) << empty;
}

TEST(DatasetGaps, LimitsOutsideZeroToOneAreRefused) {
  tega::MissingImageLimits limits;
  EXPECT_NO_THROW(tega::check_missing_image_limits(limits, "ingest"));
  limits.max_dropped_frame_fraction = 1.5;
  EXPECT_NE(tega::test::error_message([&] { tega::check_missing_image_limits(limits, "ingest"); })
                .find("ingest options: missing_images.max_dropped_frame_fraction must be in 0 .. 1"),
            std::string::npos);
}

}  // namespace
