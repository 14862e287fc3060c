// bench/calibrate: board detection and bundle adjustment for a 13-camera
// calibration take of 200 board poses, rendered once by the virtual studio
// into --capture (kept for the next run; rendering is not timed).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "tega/calibrate/calibration.h"
#include "tega/core/rig.h"
#include "tega/core/take.h"
#include "tega/synth/virtual_studio.h"

namespace fs = std::filesystem;
using namespace tega;

namespace {

// The worst camera's errors against the virtual studio's ground truth, expressed in the calibration's world.
void report_against_truth(const char* label, const Rig& calibrated, const Rig& truth,
                          const RigidTransform& truth_world_to_calibrated) {
  double focal = 0, principal = 0, centre = 0, rotation = 0;
  for (size_t c = 0; c < truth.cameras.size(); ++c) {
    const Camera& got = calibrated.cameras[c];
    const Camera& want = truth.cameras[c];
    const RigidTransform want_pose = want.world_to_camera * truth_world_to_calibrated.inverse();
    focal = std::max({focal, std::abs(got.K(0, 0) / want.K(0, 0) - 1), std::abs(got.K(1, 1) / want.K(1, 1) - 1)});
    principal = std::max(principal, (got.K.block<2, 1>(0, 2) - want.K.block<2, 1>(0, 2)).norm());
    centre = std::max(centre, (got.center() - (-want_pose.R.transpose() * want_pose.t)).norm());
    rotation = std::max(rotation, Eigen::AngleAxisd(got.world_to_camera.R * want_pose.R.transpose()).angle());
  }
  std::printf("worst camera against ground truth, %s: focal %.3f %%, principal point %.2f px, centre %.2f mm, "
              "rotation %.3f deg\n",
              label, 100 * focal, principal, 1000 * centre, rotation * 180 / M_PI);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Calibration time: detection and bundle adjustment."};
  int cameras = 13, poses = 200, width = 1024, height = 768, threads = 0;
  std::string capture = (fs::temp_directory_path() / "tega-calibrate-bench").string();
  app.add_option("--cameras", cameras, "Cameras.");
  app.add_option("--poses", poses, "Board poses (frames of the calibration take).");
  app.add_option("--width", width, "Image width.");
  app.add_option("--height", height, "Image height.");
  app.add_option("--threads", threads, "Threads (0 = all).");
  app.add_option("--capture", capture, "Where the rendered take is kept between runs.");
  CLI11_PARSE(app, argc, argv);

  const fs::path root = capture + "-" + std::to_string(cameras) + "x" + std::to_string(poses) + "-" +
                        std::to_string(width) + "x" + std::to_string(height);
  if (!fs::exists(root / "capture.json")) {
    std::printf("rendering %d cameras x %d board poses at %dx%d into %s (once)...\n", cameras, poses, width, height,
                root.c_str());
    std::fflush(stdout);
    synth::Options o;
    o.studio.cameras = cameras;
    o.studio.width = width;
    o.studio.height = height;
    o.calibration_frames = poses;
    o.frames = 1;
    o.takes = {"expressions"};
    o.test_takes = {};
    o.fine_subdivisions = 0;
    o.write_fine_meshes = false;
    o.supersampling = 1;
    synth::render_virtual_studio(o, root, true);
  }
  const TakeInfo take = read_take(root / "takes/calibration");
  const Rig truth = read_rig_json(root / "rig.json");
  std::vector<calibrate::CameraSize> sizes;
  for (const auto& c : truth.cameras) sizes.push_back({c.name, c.width, c.height});
  const calibrate::Board board = calibrate::make_board(calibrate::BoardOptions{});

  const auto start = std::chrono::steady_clock::now();
  const auto views = calibrate::detect_board_in_take(take, board, threads);
  const double detection = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  calibrate::CalibrationOptions options;
  options.threads = threads;
  const auto result = calibrate::calibrate_rig(views, board, sizes, options);
  size_t corners = 0;
  for (const auto& v : views) corners += v.ids.size();
  std::printf("%d cameras x %d poses, %dx%d, %u hardware threads\n", cameras, poses, width, height,
              std::thread::hardware_concurrency());
  std::printf("detection:   %6.1f s  (%d images, %zu views with corners, %zu corners)\n", detection,
              take.frames * int(take.cameras.size()), views.size(), corners);
  std::printf("calibration: %6.1f s  (intrinsics, pose graph, bundle adjustment twice; rms %.3f px, %d outliers)\n",
              result.seconds, result.rms_px, result.outliers);
  std::printf("total:       %6.1f s\n", detection + result.seconds);
  report_against_truth("world on cam00", result.rig, truth, truth.cameras[0].world_to_camera);

  options.world = "board";
  const auto on_board = calibrate::calibrate_rig(views, board, sizes, options);
  const int frame = std::stoi(on_board.world.substr(on_board.world.rfind(' ') + 1));
  const auto gt = nlohmann::json::parse(std::ifstream(root / "ground_truth/calibration/frames.json"));
  Eigen::Matrix<double, 3, 4> board_to_world;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) board_to_world(r, c) = gt["frames"][frame]["board_to_world"][r][c];
  report_against_truth(("world on the " + on_board.world).c_str(), on_board.rig, truth,
                       RigidTransform::from_matrix(board_to_world).inverse());
}
