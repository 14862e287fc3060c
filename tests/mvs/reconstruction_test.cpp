// tega mvs on a 13-camera virtual-studio capture at 512 x 384, scored against
// its ground truth (the CPU targets), plus resuming and bad input.
// The capture is rendered once; tests that damage it work on a copy.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/log.h"
#include "tega/core/rig.h"
#include "tega/mvs/reconstruction.h"
#include "tega/scoring/studio_truth.h"
#include "tega/scoring/surface_scores.h"
#include "tega/synth/virtual_studio.h"
#include "small_studio.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace tega::mvs {
namespace {

const fs::path& studio_capture() {
  static const tega::test::TempDir dir;
  static const fs::path root = [] {
    synth::render_virtual_studio(tega::test::small_studio(13, 512, 384, 2), dir / "capture");
    return dir / "capture";
  }();
  return root;
}

// One thread for Poisson: OpenMP's spinning threads stall when ctest runs
// other tests beside this one on a small machine.
Options cpu_options() {
  Options o;
  o.device = "cpu";
  o.surface.threads = 1;
  return o;
}

using tega::test::error_message;

// A copy of the capture with frame 1 only, to damage.
fs::path copy_capture(const tega::test::TempDir& dir) {
  fs::copy(studio_capture(), dir / "capture", fs::copy_options::recursive);
  return dir / "capture";
}

TEST(Mvs, MeshesTheFaceWithinTheTargets) {
  const tega::test::TempDir out;
  MvsRequest request;
  request.capture = studio_capture();
  request.out = out / "meshes";
  request.end_frame = 1;
  const MvsSummary summary = reconstruct_capture(request, cpu_options());
  EXPECT_EQ(summary.frames_done, 1);
  const Mesh mesh = read_mesh(out / "meshes" / "expressions" / "000000.ply");
  const scoring::StudioTruth truth = scoring::load_studio_truth(studio_capture(), "expressions", 0);
  scoring::EvaluationOptions eval;
  eval.tolerances_m = {0.003};
  const scoring::SurfaceScores scores = scoring::evaluate_surface(mesh, truth.fine, truth.face_region, eval);
  std::printf("512x384, 13 cameras: accuracy median %.2f mm (p90 %.2f mm), completeness at 3 mm %.1f %%\n",
              1000 * scores.accuracy_median_m, 1000 * scores.accuracy_p90_m, 100 * scores.completeness[0]);
  EXPECT_LE(scores.accuracy_median_m, 0.002);
  EXPECT_GE(scores.completeness[0], 0.90);

  const auto record = nlohmann::json::parse(read_text_file(out / "meshes" / "expressions" / "000000.json"));
  EXPECT_EQ(record["depth_map_cameras"].size(), 13u);
  EXPECT_GT(record["points"].get<int>(), 10000);

  // Run again: the frame is done with these options and rig, and kept.
  const auto before = fs::last_write_time(out / "meshes" / "expressions" / "000000.ply");
  const MvsSummary again = reconstruct_capture(request, cpu_options());
  EXPECT_EQ(again.frames_skipped, 1);
  EXPECT_EQ(again.frames_done, 0);
  EXPECT_EQ(fs::last_write_time(out / "meshes" / "expressions" / "000000.ply"), before);
}

TEST(Mvs, WarnsWhenTheWindowsAreSmallForTheImages) {
  const tega::test::TempDir dir;
  MvsRequest request{studio_capture(), {}, dir / "meshes", {}, 5, 6};  // no frame 5: it stops after the check
  init_logging(1);  // to stderr, as the tega command logs
  Options sized = cpu_options();
  sized.patch_match.window_radius = 2;  // 512 wide: as 12 at 3072, fine
  testing::internal::CaptureStderr();
  EXPECT_THROW(reconstruct_capture(request, sized), Error);
  EXPECT_EQ(testing::internal::GetCapturedStderr().find("window_radius"), std::string::npos);
  Options small = cpu_options();
  small.patch_match.window_radius = 1;  // as 4 at 2048, or 6 at 3072
  testing::internal::CaptureStderr();
  EXPECT_THROW(reconstruct_capture(request, small), Error);
  const std::string log = testing::internal::GetCapturedStderr();
  EXPECT_NE(log.find("the cameras are 512 pixels wide and patch_match.window_radius is 1"), std::string::npos) << log;
}

TEST(Mvs, ACameraMissingFromTheRigIsNamed) {
  const tega::test::TempDir dir;
  const fs::path capture = copy_capture(dir);
  Rig rig = read_rig_json(capture / "rig.json");
  rig.cameras.erase(rig.cameras.begin() + 4);
  write_rig_json(rig, dir / "partial-rig.json");
  MvsRequest request{capture, {}, dir / "meshes", dir / "partial-rig.json", 1, 2};
  const std::string error = error_message([&] { reconstruct_capture(request, cpu_options()); });
  EXPECT_NE(error.find("partial-rig.json"), std::string::npos) << error;
  EXPECT_NE(error.find("cam04"), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(dir / "meshes" / "expressions" / "000001.ply"));
}

TEST(Mvs, AnUnreadableImageNamesTheFrameAndFileAndLeavesNoMesh) {
  const tega::test::TempDir dir;
  const fs::path capture = copy_capture(dir);
  const fs::path image = capture / "takes" / "expressions" / "cam07" / "000001.png";
  write_text_atomic(image, "not a png");
  MvsRequest request{capture, {}, dir / "meshes", {}, 1, 2};
  const std::string error = error_message([&] { reconstruct_capture(request, cpu_options()); });
  EXPECT_NE(error.find("frame 1"), std::string::npos) << error;
  EXPECT_NE(error.find(image.string()), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(dir / "meshes" / "expressions" / "000001.ply"));
  EXPECT_FALSE(fs::exists(dir / "meshes" / "expressions" / "000001.json"));
}

TEST(Mvs, AFrameTooFewCamerasSeeIsRefused) {
  const tega::test::TempDir dir;
  const fs::path capture = copy_capture(dir);
  // All but two cameras see the empty studio in frame 1.
  const auto cameras = read_rig_json(capture / "rig.json").camera_names();
  for (size_t k = 2; k < cameras.size(); ++k)
    fs::copy_file(capture / "takes" / "clean_plate" / cameras[k] / "000000.png",
                  capture / "takes" / "expressions" / cameras[k] / "000001.png", fs::copy_options::overwrite_existing);
  MvsRequest request{capture, {}, dir / "meshes", {}, 1, 2};
  const std::string error = error_message([&] { reconstruct_capture(request, cpu_options()); });
  EXPECT_NE(error.find("frame 1: the subject is seen by 2 camera(s) (cam00, cam01)"), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(dir / "meshes" / "expressions" / "000001.ply"));
}

}  // namespace
}  // namespace tega::mvs
