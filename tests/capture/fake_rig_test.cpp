// Records takes from Aravis' in-process simulated cameras: the real Aravis
// streaming path, with pixels whose values the test can predict.
#include <gtest/gtest.h>

#include <atomic>
#include <nlohmann/json.hpp>
#include <thread>

#include "capture_test_support.h"
#include "tega/capture/recorder.h"
#include "tega/core/error.h"
#include "tega/core/image.h"
#include "tega/core/image_header.h"
#include "tega/core/json_file.h"
#include "tega/core/take.h"
#include "test_support.h"

namespace tega::capture {
namespace {

namespace fs = std::filesystem;

TakeRequest request(const std::string& name, int frames, Trigger trigger = Trigger::free_run) {
  TakeRequest r;
  r.name = name;
  r.frames = frames;
  r.trigger = trigger;
  r.live_status = false;
  return r;
}

TEST(FakeRig, ThirteenCamerasRecordCompleteFrameSetsHoldingTheCamerasPixels) {
  test::TempDir capture;
  const RigConfig rig = test::fake_rig(13);
  const TakeOutcome outcome = record_take(rig, request("expressions", 12), capture.path());

  EXPECT_EQ(outcome.frames, 12);
  EXPECT_TRUE(outcome.error.empty()) << outcome.error;
  const TakeInfo take = read_take(capture / "takes/expressions");
  EXPECT_EQ(take.frames, 12);
  EXPECT_EQ(take.cameras.size(), 13u);
  EXPECT_EQ(take.pixel_format, "Mono8");
  EXPECT_TRUE(take.missing.empty());
  validate_capture(capture.path());  // the layout checks every stage relies on

  const auto sets = test::read_frame_sets(capture / "takes/expressions");
  // Free-running cameras stamped on arrival: the cameras' start-up skew is
  // set apart, and a loaded machine may still delay a frame past half a
  // period now and then, but every such set is listed and none is written.
  int incomplete = 0, starting = 0;
  for (const auto& row : sets) {
    incomplete += row.at("status") == "incomplete_dropped";
    starting += row.at("status") == "before_all_streaming";
    if (row.at("frame") != "-1") EXPECT_EQ(row.at("status"), "complete");
  }
  EXPECT_EQ(incomplete, outcome.incomplete_sets);
  EXPECT_EQ(starting, outcome.before_all_streaming);
  EXPECT_LE(outcome.incomplete_sets, 2) << "timestamps no longer group the cameras' frames";
  int checked = 0;
  for (const auto& row : sets) {
    if (row.at("frame") == "-1") continue;
    const int frame = std::stoi(row.at("frame"));
    for (const auto& camera : take.cameras) {
      const uint64_t frame_id = std::stoull(row.at(camera + "_frame_id"));
      const Image8 image = read_image_u8(take.image_path(camera, frame));
      ASSERT_EQ(image.width, 160);
      ASSERT_EQ(image.height, 120);
      ASSERT_EQ(image.channels, 1);
      for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
          ASSERT_EQ(image.at(x, y, 0), test::fake_camera_ramp(x, y, frame_id))
              << camera << " frame " << frame << " at " << x << "," << y;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 12 * 13);

  const auto manifest = read_json_file(capture / "takes/expressions/manifest.json");
  EXPECT_EQ(manifest["frames"], 12);
  EXPECT_EQ(manifest["synchronised"], false);
  EXPECT_EQ(manifest["cameras"][4]["settings_read_back"]["PixelFormat"], "Mono8");
  EXPECT_EQ(manifest["cameras"][4]["frames_written"], 12);
  const auto listed = read_json_file(capture / "capture.json");
  EXPECT_EQ(listed["takes"][0]["name"], "expressions");
  EXPECT_EQ(listed["takes"][0]["frames"], 12);
}

TEST(FakeRig, HardwareTriggerGroupsByFrameIdAndIsMarkedSynchronised) {
  test::TempDir capture;
  RigConfig rig = test::fake_rig(3, 64, 48, 40);
  rig.sync.group_by = "frame_id";
  const TakeOutcome outcome = record_take(rig, request("rom", 6, Trigger::hardware), capture.path());
  EXPECT_EQ(outcome.frames, 6);
  EXPECT_EQ(outcome.incomplete_sets, 0);
  for (const auto& row : test::read_frame_sets(capture / "takes/rom"))
    if (row.at("status") == "complete") EXPECT_EQ(row.at("cam00_frame_id"), row.at("cam02_frame_id"));
  EXPECT_EQ(read_json_file(capture / "takes/rom/manifest.json")["synchronised"], true);
  EXPECT_EQ(read_json_file(capture / "takes/rom/manifest.json")["cameras"][0]["settings_read_back"]["TriggerSource"],
            "Line0");
}

TEST(FakeRig, ARefusedSettingNamesCameraFeatureWantedAndActualAndRecordsNothing) {
  test::TempDir capture;
  RigConfig rig = test::fake_rig(4);
  rig.cameras[1].settings.gain = 1.5;  // the simulated camera's gain is a whole number
  rig.cameras[3].settings.pixel_format = "BayerRG16";
  std::string message;
  try {
    record_take(rig, request("refused", 3), capture.path());
  } catch (const Error& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("camera cam01 (serial TEGA01): Gain: wanted 1.5, camera reports 1"), std::string::npos)
      << message;
  EXPECT_NE(message.find("camera cam03 (serial TEGA03): PixelFormat: wanted BayerRG16, camera offers"),
            std::string::npos)
      << message;
  EXPECT_FALSE(fs::exists(capture / "takes/refused"));
  EXPECT_FALSE(fs::exists(capture / "takes/refused.recording"));
  EXPECT_FALSE(fs::exists(capture / "capture.json"));
}

TEST(FakeRig, AWriteErrorStopsTheTakeAndKeepsWhatWasWrittenListed) {
  test::TempDir capture;
  const RigConfig rig = test::fake_rig(4);
  std::atomic<int> images{0};
  RecordHooks hooks;
  hooks.before_write = [&](const fs::path& file) {
    if (++images > 22) throw Error(file, "No space left on device (injected)");
  };
  const TakeOutcome outcome = record_take(rig, request("full", 1000), capture.path(), hooks);
  EXPECT_NE(outcome.error.find("injected"), std::string::npos) << outcome.error;
  EXPECT_EQ(outcome.stop_reason, "write error");
  EXPECT_GE(outcome.frames, 5);
  EXPECT_LE(outcome.frames, 6 + 1);

  const TakeInfo take = read_take(capture / "takes/full");
  validate_take(take);  // every image it lists exists; the rest is listed missing
  int on_disk = 0;
  for (const auto& camera : take.cameras)
    for (int f = 0; f < take.frames; ++f) on_disk += take.has_image(camera, f) ? 1 : 0;
  EXPECT_EQ(on_disk, 22);
  for (const auto& entry : fs::recursive_directory_iterator(capture / "takes/full"))
    EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos) << entry.path();
  const auto manifest = read_json_file(capture / "takes/full/manifest.json");
  EXPECT_NE(manifest["error"].get<std::string>().find("injected"), std::string::npos);
  validate_capture(capture.path());
}

TEST(FakeRig, AStopRequestFinalisesTheTake) {
  test::TempDir capture;
  const RigConfig rig = test::fake_rig(2);
  std::atomic<bool> stop{false};
  std::thread operator_thread([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(600));
    stop = true;
  });
  RecordHooks hooks;
  hooks.stop = &stop;
  const TakeOutcome outcome = record_take(rig, request("open_ended", 0), capture.path(), hooks);
  operator_thread.join();
  EXPECT_EQ(outcome.stop_reason, "stopped by the operator");
  EXPECT_GT(outcome.frames, 5);
  validate_take(read_take(capture / "takes/open_ended"));
}

TEST(FakeRig, AnExistingTakeIsNeverOverwritten) {
  test::TempDir capture;
  const RigConfig rig = test::fake_rig(2);
  record_take(rig, request("once", 2), capture.path());
  EXPECT_THROW(record_take(rig, request("once", 2), capture.path()), Error);
  EXPECT_EQ(read_take(capture / "takes/once").frames, 2);
}

TEST(FakeRig, SixteenBitFramesAreStoredAsSixteenBitPngs) {
  test::TempDir capture;
  RigConfig rig = test::fake_rig(2);
  for (auto& c : rig.cameras) c.settings.pixel_format = "Mono16";
  record_take(rig, request("deep", 2), capture.path());
  const TakeInfo take = read_take(capture / "takes/deep");
  EXPECT_EQ(take.bit_depth, 16);
  const ImageHeader header = read_image_header(take.image_path("cam01", 1));
  EXPECT_EQ(header.bit_depth, 16);
  EXPECT_EQ(header.channels, 1);
  validate_take(take);
}

}  // namespace
}  // namespace tega::capture
