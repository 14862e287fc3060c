#include "tega/core/dataset.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/image.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace {

// A two-camera, two-frame dataset on a one-triangle template.
class DatasetTest : public ::testing::Test {
 protected:
  void SetUp() override { tega::test::write_tiny_dataset(tmp.path()); }

  std::string validation_error() {
    try {
      tega::validate_dataset(tega::read_dataset(tmp.path()));
    } catch (const tega::Error& e) {
      return e.what();
    }
    return "";
  }

  void edit_manifest(const std::function<void(nlohmann::json&)>& edit) {
    auto manifest = nlohmann::json::parse(tega::read_text_file(tmp / "dataset.json"));
    edit(manifest);
    tega::write_text_atomic(tmp / "dataset.json", manifest.dump());
  }

  tega::test::TempDir tmp;
};

TEST_F(DatasetTest, RoundTripsAndValidates) {
  const tega::Dataset d = tega::read_dataset(tmp.path());
  EXPECT_EQ(d.frames.size(), 2u);
  EXPECT_EQ(d.rig.cameras.size(), 2u);
  EXPECT_EQ(d.template_mesh.num_vertices(), 3);
  EXPECT_EQ(d.eyeball_faces, std::vector<int32_t>{0});
  EXPECT_EQ(d.train.cameras, std::vector<std::string>{"cam00"});
  EXPECT_EQ(d.test.frames, std::vector<std::string>{"blink_000000"});
  EXPECT_NEAR(d.frame("smile_000000").head_to_world.t.x(), 0.01, 1e-12);
  EXPECT_EQ(d.load_mesh("smile_000000").rows(), 3);
  EXPECT_EQ(validation_error(), "");
}

TEST_F(DatasetTest, MissingImageIsNamed) {
  fs::remove(tmp / "images/cam01/smile_000000.png");
  EXPECT_NE(validation_error().find("images/cam01/smile_000000.png: is missing"), std::string::npos)
      << validation_error();
}

TEST_F(DatasetTest, AMissingImageThatIsRecordedIsAcceptedAndRoundTrips) {
  fs::remove(tmp / "images/cam01/smile_000000.png");
  edit_manifest([](auto& m) {
    m["missing_images"] = {{{"camera", "cam01"}, {"frame", "smile_000000"}, {"reason", "x.png: is missing"}}};
    m["dropped_frames"] = {{{"frame", "smile_000003"}, {"reason", "usable images from 0 of 2 cameras"}}};
  });
  EXPECT_EQ(validation_error(), "");
  tega::Dataset d = tega::read_dataset(tmp.path());
  EXPECT_FALSE(d.has_image("cam01", "smile_000000"));
  EXPECT_TRUE(d.has_image("cam00", "smile_000000"));
  EXPECT_TRUE(d.has_image("cam01", "blink_000000"));

  tega::write_dataset_manifest(d);
  const tega::Dataset again = tega::read_dataset(tmp.path());
  ASSERT_EQ(again.missing_images.size(), 1u);
  EXPECT_EQ(again.missing_images[0].camera, "cam01");
  EXPECT_EQ(again.missing_images[0].frame, "smile_000000");
  EXPECT_EQ(again.missing_images[0].reason, "x.png: is missing");
  ASSERT_EQ(again.dropped_frames.size(), 1u);
  EXPECT_EQ(again.dropped_frames[0].frame, "smile_000003");
  EXPECT_EQ(again.dropped_frames[0].reason, "usable images from 0 of 2 cameras");

  // Another image missing, but not recorded: still an error naming it.
  fs::remove(tmp / "images/cam00/blink_000000.png");
  const std::string message = validation_error();
  EXPECT_NE(message.find("images/cam00/blink_000000.png: is missing"), std::string::npos) << message;
  EXPECT_NE(message.find("missing_images does not record it"), std::string::npos) << message;
}

TEST_F(DatasetTest, MalformedGapRecordsAreNamed) {
  const auto read_error = [&] {
    try {
      tega::read_dataset(tmp.path());
    } catch (const tega::Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  edit_manifest([](auto& m) { m["missing_images"] = {{{"camera", "cam01"}, {"frame", "frown_000001"}}}; });
  EXPECT_NE(read_error().find("frame 'frown_000001') names an unknown frame"), std::string::npos) << read_error();
  edit_manifest([](auto& m) { m["missing_images"] = {{{"camera", "cam09"}, {"frame", "smile_000000"}}}; });
  EXPECT_NE(read_error().find("names a camera that is not in the rig"), std::string::npos) << read_error();
  edit_manifest([](auto& m) {
    m["missing_images"] = {{{"camera", "cam01"}, {"frame", "smile_000000"}}, {{"camera", "cam01"}, {"frame", "smile_000000"}}};
  });
  EXPECT_NE(read_error().find("is recorded twice"), std::string::npos) << read_error();
  edit_manifest([](auto& m) { m["missing_images"] = "cam01"; });
  EXPECT_NE(read_error().find("dataset.json: 'missing_images' must be a list"), std::string::npos) << read_error();
  edit_manifest([](auto& m) {
    m["missing_images"] = nlohmann::json::array();
    m["dropped_frames"] = {{{"frame", "smile_000000"}}};
  });
  EXPECT_NE(read_error().find("frame 'smile_000000' is both kept and dropped"), std::string::npos) << read_error();
}

TEST_F(DatasetTest, ImageOfTheWrongSizeIsNamed) {
  tega::write_image(tega::Image8(9, 6, 4), tmp / "images/cam00/blink_000000.png");
  EXPECT_NE(validation_error().find("cam00/blink_000000.png: is 9x6"), std::string::npos) << validation_error();
}

TEST_F(DatasetTest, MeshWithTheWrongVertexCountIsNamed) {
  tega::Vertices four(4, 3);
  four.setZero();
  tega::write_vertices_bin(four, tmp / "meshes/blink_000000.bin");
  EXPECT_NE(validation_error().find("meshes/blink_000000.bin: has 4 vertices"), std::string::npos)
      << validation_error();
}

TEST_F(DatasetTest, CameraMissingFromTheRigIsNamed) {
  edit_manifest([](auto& m) { m["split"]["test"]["cameras"] = {"cam07"}; });
  const auto message = validation_error();
  EXPECT_NE(message.find("dataset.json"), std::string::npos) << message;
  EXPECT_NE(message.find("camera 'cam07', which is not in the rig"), std::string::npos) << message;
}

TEST_F(DatasetTest, SplitNamingAnUnknownFrameIsNamed) {
  edit_manifest([](auto& m) { m["split"]["train"]["frames"] = {"smile_000000", "frown_000003"}; });
  EXPECT_NE(validation_error().find("split.train names unknown frame 'frown_000003'"), std::string::npos)
      << validation_error();
}

TEST_F(DatasetTest, NotADatasetIsNamed) {
  tega::test::TempDir empty;
  try {
    tega::read_dataset(empty.path());
    FAIL();
  } catch (const tega::Error& e) {
    EXPECT_NE(std::string(e.what()).find("is not a tega dataset"), std::string::npos);
  }
}

TEST(DatasetSampling, FramesAreTheMiddlesOfEqualParts) {
  EXPECT_EQ(tega::evenly_spaced_indices(6, 4), (std::vector<size_t>{0, 2, 3, 5}));
  EXPECT_EQ(tega::evenly_spaced_indices(400, 2), (std::vector<size_t>{100, 300}));
  EXPECT_EQ(tega::evenly_spaced_indices(3, 0), (std::vector<size_t>{0, 1, 2}));  // 0: all
  EXPECT_EQ(tega::evenly_spaced_indices(3, 5), (std::vector<size_t>{0, 1, 2}));
  EXPECT_TRUE(tega::evenly_spaced_indices(0, 4).empty());
}

TEST(DatasetSampling, TestCamerasAreSpreadOverTheRig) {
  tega::Rig rig;
  for (const char* name : {"c0", "c1", "c2", "c3", "c4", "c5"}) rig.cameras.push_back({name});
  EXPECT_EQ(tega::spread_test_cameras(rig, 2), (std::vector<std::string>{"c5", "c2"}));
  EXPECT_EQ(tega::spread_test_cameras(rig, 9), (std::vector<std::string>{"c5", "c4", "c3", "c2", "c1"}));
  rig.cameras.resize(1);
  EXPECT_EQ(tega::spread_test_cameras(rig, 2), (std::vector<std::string>{"c0"}));
}

}  // namespace
