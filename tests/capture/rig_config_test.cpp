#include <gtest/gtest.h>

#include "tega/capture/options.h"
#include "tega/core/error.h"
#include "test_support.h"

namespace tega::capture {
namespace {

std::string error_loading(const std::string& yaml) {
  test::TempDir dir;
  test::write_text(dir / "rig.yaml", yaml);
  try {
    load_rig_config(dir / "rig.yaml");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(RigConfig, CameraSettingsOverrideTheRigsKeyByKey) {
  test::TempDir dir;
  test::write_text(dir / "rig.yaml", R"(
settings: {pixel_format: BayerRG8, exposure_us: 4000, gain: 2}
cameras:
  - {name: cam00, serial: A1}
  - {name: cam01, serial: A2, settings: {exposure_us: 6000}}
sync: {incomplete_sets: keep}
)");
  const RigConfig rig = load_rig_config(dir / "rig.yaml");
  ASSERT_EQ(rig.cameras.size(), 2u);
  EXPECT_EQ(rig.cameras[0].settings.exposure_us, 4000);
  EXPECT_EQ(rig.cameras[1].settings.exposure_us, 6000);
  EXPECT_EQ(rig.cameras[1].settings.pixel_format, "BayerRG8");
  EXPECT_EQ(rig.cameras[1].settings.gain, 2);
  EXPECT_EQ(rig.sync.incomplete_sets, "keep");
}

TEST(RigConfig, MistakesAreErrorsNamingTheFileAndTheKey) {
  EXPECT_NE(error_loading("cameras: [{name: a, serial: 1, exposure: 3}]\n").find("cameras[0].exposure"),
            std::string::npos);
  EXPECT_NE(error_loading("cameras: [{name: a, serial: 1}, {name: a, serial: 2}]\n").find("appears twice"),
            std::string::npos);
  EXPECT_NE(error_loading("cameras: []\n").find("no cameras"), std::string::npos);
  EXPECT_NE(error_loading("settings: {pixel_format: Mono12Packed}\ncameras: [{name: a, serial: 1}]\n")
                .find("Mono12Packed"),
            std::string::npos);
  const auto message = error_loading("sync: {incomplete_sets: sometimes}\ncameras: [{name: a, serial: 1}]\n");
  EXPECT_NE(message.find("rig.yaml"), std::string::npos) << message;
  EXPECT_NE(message.find("incomplete_sets"), std::string::npos) << message;
}

}  // namespace
}  // namespace tega::capture
