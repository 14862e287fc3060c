#include <gtest/gtest.h>

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <string>

#include "tega/core/options.h"
#include "tega/synth/options.h"
#include "tega/synth/studio_rig.h"

namespace tega::synth {
namespace {

// Not through __FILE__: ccache's base_dir makes it relative to the build folder.
const std::filesystem::path kStudio13 = std::filesystem::path(TEGA_STUDIO_CONFIGS) / "studio13.yaml";

// Every key of `defaults` (recursively) is in `file`.
void expect_every_key(const YAML::Node& file, const YAML::Node& defaults, const std::string& path) {
  for (const auto& item : defaults) {
    const std::string key = path + item.first.as<std::string>();
    const YAML::Node found = file[item.first.as<std::string>()];
    EXPECT_TRUE(found.IsDefined()) << "studio13.yaml lacks " << key;
    if (found.IsDefined() && item.second.IsMap()) expect_every_key(found, item.second, key + ".");
  }
}

// The file is the documented list of synth's options: equal to the defaults,
// and complete (a key it lacks would take its default unseen).
TEST(StudioRig, Studio13ConfigEqualsTheDefaults) {
  Options from_file;
  from_file.studio.cameras = 1;  // must be overwritten by the file
  load_options(from_file, kStudio13);
  EXPECT_EQ(options_to_yaml(from_file), options_to_yaml(Options{}));
  expect_every_key(YAML::LoadFile(kStudio13.string()), YAML::Load(options_to_yaml(Options{})), "");
}

TEST(StudioRig, CamerasSurroundTheFrontAtTheirDistanceAimedAtTheHead) {
  const StudioOptions o;
  const Rig rig = make_studio_rig(o);
  ASSERT_EQ(rig.cameras.size(), 13u);
  EXPECT_EQ(rig.cameras.front().name, "cam00");
  EXPECT_EQ(rig.cameras.back().name, "cam12");
  double min_x = 0, max_x = 0, min_y = 0, max_y = 0;
  for (const Camera& cam : rig.cameras) {
    const Eigen::Vector3d c = cam.center();
    EXPECT_NEAR(c.norm(), o.distance_m, 1e-9);
    EXPECT_GT(c.z(), 0.0) << cam.name << " is not in front of the face";
    min_x = std::min(min_x, c.x()), max_x = std::max(max_x, c.x());
    min_y = std::min(min_y, c.y()), max_y = std::max(max_y, c.y());
    const auto origin = cam.project(Eigen::Vector3d::Zero());
    ASSERT_TRUE(origin);
    EXPECT_NEAR(origin->x(), (o.width - 1) / 2.0, 0.05 * o.width) << cam.name;
    EXPECT_NEAR(origin->y(), (o.height - 1) / 2.0, 0.05 * o.width) << cam.name;
    EXPECT_TRUE(cam.has_distortion());
    EXPECT_NEAR(cam.K(0, 0), o.focal_length_mm / o.sensor_width_mm * o.width, 1e-9);
  }
  // Spread over the hemisphere: left and right, above and below.
  EXPECT_LT(min_x, -0.5);
  EXPECT_GT(max_x, 0.5);
  EXPECT_LT(min_y, -0.2);
  EXPECT_GT(max_y, 0.2);
  // Image up is world up for the frontal camera.
  const auto above = rig.cameras[0].project(Eigen::Vector3d(0, 0.1, 0));
  ASSERT_TRUE(above);
  EXPECT_LT(above->y(), (o.height - 1) / 2.0 - 10);
  // Lenses differ a little.
  EXPECT_NE(rig.cameras[1].distortion[0], rig.cameras[2].distortion[0]);
}

TEST(StudioRig, FewCamerasStartWithTheFrontalOne) {
  StudioOptions o;
  o.cameras = 1;
  const Rig rig = make_studio_rig(o);
  ASSERT_EQ(rig.cameras.size(), 1u);
  EXPECT_NEAR(rig.cameras[0].center().normalized().z(), 1.0, 1e-3);
}

}  // namespace
}  // namespace tega::synth
