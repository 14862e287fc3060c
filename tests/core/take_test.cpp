#include "tega/core/take.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/image.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace {

// Two cameras x three frames of 4x3 RGB PNGs, described by take.json.
class TakeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    take.name = "smile";
    take.kind = "performance";
    take.cameras = {"cam00", "cam01"};
    take.frames = 3;
    take.fps = 30;
    take.folder = folder();
    for (const auto& camera : take.cameras)
      for (int frame = 0; frame < take.frames; ++frame) tega::write_image(tega::Image8(4, 3, 3), take.image_path(camera, frame));
    tega::write_take(take, folder());
  }

  fs::path folder() const { return tmp / "takes/smile"; }

  std::string validation_error() const {
    try {
      tega::validate_take(tega::read_take(folder()));
    } catch (const tega::Error& e) {
      return e.what();
    }
    return "";
  }

  tega::test::TempDir tmp;
  tega::TakeInfo take;
};

TEST_F(TakeTest, RoundTrips) {
  take.pixel_format = "Mono16";
  take.bit_depth = 16;
  take.missing = {{"cam01", {0, 2}}};
  tega::write_take(take, folder());
  const tega::TakeInfo read = tega::read_take(folder());
  EXPECT_EQ(read.name, "smile");
  EXPECT_EQ(read.kind, "performance");
  EXPECT_EQ(read.cameras, take.cameras);
  EXPECT_EQ(read.frames, 3);
  EXPECT_EQ(read.fps, 30);
  EXPECT_EQ(read.images, "{camera}/{frame:06d}.png");
  EXPECT_EQ(read.pixel_format, "Mono16");
  EXPECT_EQ(read.bit_depth, 16);
  EXPECT_EQ(read.missing, take.missing);
  EXPECT_EQ(read.folder, folder());
  EXPECT_EQ(read.channels(), 1);
  EXPECT_EQ(read.image_path("cam01", 2), folder() / "cam01/000002.png");
  EXPECT_FALSE(read.has_image("cam01", 2));
  EXPECT_TRUE(read.has_image("cam01", 1));
  EXPECT_TRUE(read.has_image("cam00", 2));
}

TEST_F(TakeTest, OptionalFieldsDefaultAndUnpaddedFramesFill) {
  tega::write_text_atomic(folder() / "take.json",
                          R"({"name": "smile", "kind": "performance", "cameras": ["cam00"], "frames": 1,
                              "fps": 30, "images": "{camera}_{frame}.tif"})");
  const tega::TakeInfo read = tega::read_take(folder());
  EXPECT_EQ(read.pixel_format, "RGB8");
  EXPECT_EQ(read.bit_depth, 8);
  EXPECT_EQ(read.channels(), 3);
  EXPECT_TRUE(read.missing.empty());
  EXPECT_EQ(read.image_path("cam00", 12), folder() / "cam00_12.tif");
}

TEST_F(TakeTest, Validates) { EXPECT_EQ(validation_error(), ""); }

TEST_F(TakeTest, MissingImageIsNamed) {
  fs::remove(folder() / "cam01/000001.png");
  EXPECT_NE(validation_error().find("cam01/000001.png: is missing"), std::string::npos) << validation_error();
}

TEST_F(TakeTest, FrameListedAsMissingPasses) {
  fs::remove(folder() / "cam01/000001.png");
  take.missing = {{"cam01", {1}}};
  tega::write_take(take, folder());
  EXPECT_EQ(validation_error(), "");
}

TEST_F(TakeTest, ImageOfAnotherSizeIsNamed) {
  tega::write_image(tega::Image8(5, 3, 3), folder() / "cam00/000002.png");
  EXPECT_NE(validation_error().find("cam00/000002.png: is 5x3"), std::string::npos) << validation_error();
}

TEST_F(TakeTest, ChannelCountDisagreeingWithPixelFormatIsNamed) {
  take.pixel_format = "Mono8";
  tega::write_take(take, folder());
  EXPECT_NE(validation_error().find("cam00/000000.png: has 3 channel(s) of 8 bits; take.json says Mono8"),
            std::string::npos)
      << validation_error();
}

TEST_F(TakeTest, BadFieldsAreNamed) {
  take.missing = {{"cam00", {3}}};
  tega::write_take(take, folder());
  EXPECT_NE(validation_error().find("take.json: lists missing frame 3"), std::string::npos) << validation_error();
  take.missing = {};
  take.kind = "rehearsal";
  tega::write_take(take, folder());
  EXPECT_NE(validation_error().find("take.json: has kind 'rehearsal'"), std::string::npos) << validation_error();
  take.kind = "performance";
  take.cameras = {"cam00", "cam00"};
  tega::write_take(take, folder());
  EXPECT_NE(validation_error().find("take.json: lists camera 'cam00' twice"), std::string::npos) << validation_error();
}

TEST_F(TakeTest, MalformedJsonIsNamed) {
  tega::write_text_atomic(folder() / "take.json", "{\"name\": ");
  EXPECT_NE(validation_error().find("take.json: is not valid JSON"), std::string::npos) << validation_error();
  tega::write_text_atomic(folder() / "take.json", R"({"name": "smile", "kind": "performance"})");
  EXPECT_NE(validation_error().find("take.json: has no 'cameras'"), std::string::npos) << validation_error();
}

// nlohmann converts any number to an int unchecked: a float beyond an int's
// range is undefined behaviour (found by fuzzing capture.json).
TEST_F(TakeTest, NumbersOutOfAnIntegersRangeAreNamed) {
  for (const char* height : {"487e9", "2.5", "3000000000"}) {
    tega::write_text_atomic(tmp / "capture.json", std::string(R"({"format": "tega-capture", "version": 1,
                              "cameras": ["cam00"], "width": 4, "height": )") + height + R"(, "takes": []})");
    const std::string message = tega::test::error_message([&] { tega::read_capture(tmp.path()); });
    EXPECT_NE(message.find("capture.json: 'height' must be an integer from"), std::string::npos) << message;
  }
}

TEST_F(TakeTest, RecordedInACaptureValidates) {
  tega::write_text_atomic(tmp / "capture.json",
                          R"({"format": "tega-capture", "version": 1, "cameras": ["cam00"], "width": 4,
                              "height": 3, "takes": [{"name": "smile", "kind": "calibration", "frames": 9}],
                              "operator": "kim"})");
  tega::record_take_in_capture(tmp.path(), take, 4, 3, "test");
  const tega::CaptureInfo capture = tega::read_capture(tmp.path());
  EXPECT_EQ(capture.cameras, take.cameras);  // cam01 added
  ASSERT_EQ(capture.takes.size(), 1u);       // replaced, not appended
  EXPECT_EQ(capture.takes[0].kind, "performance");
  EXPECT_EQ(capture.takes[0].frames, 3);
  EXPECT_EQ(nlohmann::json::parse(tega::read_text_file(tmp / "capture.json"))["operator"], "kim");
  EXPECT_NO_THROW(tega::validate_capture(tmp.path()));

  fs::remove(folder() / "cam00/000000.png");
  EXPECT_THROW(tega::validate_capture(tmp.path()), tega::Error);
}

TEST_F(TakeTest, CaptureIsCreatedWhenAbsent) {
  tega::record_take_in_capture(tmp.path(), take, 4, 3, "test");
  const tega::CaptureInfo capture = tega::read_capture(tmp.path());
  EXPECT_EQ(capture.generator, "test");
  EXPECT_EQ(capture.width, 4);
  EXPECT_EQ(capture.rig, "");
  EXPECT_NO_THROW(tega::validate_capture(tmp.path()));
}

TEST(Take, FrameRangesParse) {
  int first = 0, end = 0;
  tega::parse_frame_range("3:7", first, end);
  EXPECT_EQ(first, 3);
  EXPECT_EQ(end, 7);
  tega::parse_frame_range("5:", first, end);
  EXPECT_EQ(end, -1);
  tega::parse_frame_range("4", first, end);
  EXPECT_EQ(end, 5);
  EXPECT_THROW(tega::parse_frame_range("7:3", first, end), tega::Error);
  EXPECT_THROW(tega::parse_frame_range("a:b", first, end), tega::Error);
}

}  // namespace
