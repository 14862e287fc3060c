// Training samples from a virtual-studio capture's truth, and `tega landmarks
// train` on one: a small ICT-FaceKit capture rendered once for the suite.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "cli_support.h"
#include "small_studio.h"
#include "tega/core/image.h"
#include "tega/scoring/landmark_capture_training.h"
#include "tega/scoring/studio_landmarks.h"
#include "tega/synth/virtual_studio.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace tega::scoring {
namespace {

// Six cameras over a 45-degree cap (cam00 frontal, the others up to 45
// degrees aside, where the far jaw line turns away) at 320 x 240; two samples
// per pixel and one subdivision level: what a landmark needs, fast.
constexpr int kStudioFrames = 6;

const fs::path& small_capture(const fs::path& ict) {
  static const test::TempDir dir;
  static const fs::path capture = [&] {
    synth::Options o = test::small_studio(6, 320, 240, kStudioFrames);
    o.head = ict.string();
    o.studio.cap_half_angle_deg = 45;
    o.supersampling = 2;
    o.fine_subdivisions = 1;
    o.write_fine_meshes = false;
    const auto start = std::chrono::steady_clock::now();
    synth::render_virtual_studio(o, dir / "capture");
    std::cout << "rendered the capture in "
              << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() << " s\n";
    return dir / "capture";
  }();
  return capture;
}

bool inside(const Image8& image, const Eigen::Vector2d& pixel) {
  return pixel.x() >= 0 && pixel.y() >= 0 && pixel.x() < image.width && pixel.y() < image.height;
}

// Coverage of the head at a pixel of the capture's true alpha.
int coverage(const Image8& alpha, const Eigen::Vector2d& pixel) {
  return alpha.at(int(std::lround(pixel.x())), int(std::lround(pixel.y())), 0);
}

// The camera and frame that see the face most nearly from the front.
std::pair<StudioFrameLandmarks, std::string> most_frontal_view(const StudioLandmarkTruth& truth) {
  std::pair<StudioFrameLandmarks, std::string> best;
  double best_angle = 180;
  for (int f = 0; f < kStudioFrames; ++f) {
    const StudioFrameLandmarks frame = truth.frame("expressions", f);
    for (const std::string& camera : truth.rig().camera_names())
      if (truth.view_angle_deg(frame, camera) < best_angle) {
        best_angle = truth.view_angle_deg(frame, camera);
        best = {frame, camera};
      }
  }
  return best;
}

// Seen from the front, every landmark but at most a jaw point at the silhouette,
// whose normal may turn just past the camera, is known, inside the photo and on
// the rendered head.
TEST(LandmarkCapture, FrontalViewHasTheLandmarksOnTheHead) {
  TEGA_REQUIRE_ICT_FACEKIT(ict);
  const fs::path& capture = small_capture(ict);
  const StudioLandmarkTruth truth(capture, model_landmark_vertices(studio_head_model(capture)));
  const auto [frame, camera] = most_frontal_view(truth);
  EXPECT_LT(truth.view_angle_deg(frame, camera), 10) << camera << ", frame " << frame.frame;
  const landmarks::LandmarkSample sample = truth.sample(frame, camera);
  char alpha_name[32];
  std::snprintf(alpha_name, sizeof alpha_name, "%06d.png", frame.frame);
  const Image8 alpha = read_image_u8(capture / "ground_truth/expressions/alpha" / camera / alpha_name);
  ASSERT_EQ(sample.landmarks.size(), size_t{landmarks::kLandmarkCount});
  int unknown_jaw_points = 0;
  for (int i = 0; i < landmarks::kLandmarkCount; ++i) {
    const Eigen::Vector2d& landmark = sample.landmarks[i];
    constexpr int kLastJawPoint = 16;
    if (!landmark.allFinite()) {
      EXPECT_LE(i, kLastJawPoint) << "landmark " << i << " unknown in " << camera << ", frame " << frame.frame;
      ++unknown_jaw_points;
      continue;
    }
    ASSERT_TRUE(inside(sample.image, landmark)) << "landmark " << i << " at " << landmark.transpose();
    // The rendered head covers every landmark: the projection is the renderer's.
    EXPECT_GT(coverage(alpha, landmark), 0) << "landmark " << i << " off the head";
  }
  EXPECT_LE(unknown_jaw_points, 2);
  // The box: the bounding box of all 68 projected landmarks grown by 15 %.
  landmarks::FaceBox tight;
  for (const Eigen::Vector3d& position : frame.positions)
    tight.extend(truth.rig().camera(camera).project(position).value());
  EXPECT_NEAR(sample.box.sizes().x(), 1.15 * tight.sizes().x(), 1e-9);
  EXPECT_NEAR(sample.box.sizes().y(), 1.15 * tight.sizes().y(), 1e-9);
  EXPECT_LT((sample.box.center() - tight.center()).norm(), 1e-9);
}

// Seen from well aside, the jaw line's far end turns away (unknown) and its
// near end faces the camera.
TEST(LandmarkCapture, FarSideLandmarkOfAnObliqueViewIsUnknown) {
  TEGA_REQUIRE_ICT_FACEKIT(ict);
  const fs::path& capture = small_capture(ict);
  const StudioLandmarkTruth truth(capture, model_landmark_vertices(studio_head_model(capture)));
  const StudioFrameLandmarks frame = truth.frame("expressions", 0);
  std::string oblique;
  for (const std::string& camera : truth.rig().camera_names())
    if (oblique.empty() || truth.view_angle_deg(frame, camera) > truth.view_angle_deg(frame, oblique)) oblique = camera;
  EXPECT_GT(truth.view_angle_deg(frame, oblique), 35);
  const Eigen::Vector3d centre = truth.rig().camera(oblique).center();
  constexpr int kJawRight = 0, kJawLeft = 16;  // the jaw line's ends, the subject's right and left
  const bool right_is_far = (frame.positions[kJawRight] - centre).norm() > (frame.positions[kJawLeft] - centre).norm();
  const int far = right_is_far ? kJawRight : kJawLeft, near = right_is_far ? kJawLeft : kJawRight;
  const landmarks::LandmarkSample sample = truth.sample(frame, oblique);
  EXPECT_FALSE(sample.landmarks[far].allFinite()) << "landmark " << far << " in " << oblique;
  EXPECT_TRUE(sample.landmarks[near].allFinite()) << "landmark " << near << " in " << oblique;
  EXPECT_TRUE(sample.landmarks[30].allFinite()) << "the nose tip in " << oblique;
}

TEST(LandmarkCapture, SamplesFollowTheOptions) {
  TEGA_REQUIRE_ICT_FACEKIT(ict);
  const fs::path& capture = small_capture(ict);
  const std::vector<int> vertices = model_landmark_vertices(studio_head_model(capture));
  const StudioLandmarkTruth truth(capture, vertices);
  LandmarkSamplingOptions options;
  options.frame_stride = 2;
  options.max_view_angle_deg = 180;
  const auto every_camera = capture_landmark_samples(capture, vertices, options);
  EXPECT_EQ(every_camera.size(), size_t{6 * kStudioFrames / 2});
  for (const CaptureLandmarkSample& s : every_camera) {
    EXPECT_EQ(s.frame % 2, 0);
    EXPECT_EQ(s.frame_position, s.frame / 2);
  }
  options.max_view_angle_deg = 20;
  const auto frontal = capture_landmark_samples(capture, vertices, options);
  EXPECT_LT(frontal.size(), every_camera.size());
  EXPECT_FALSE(frontal.empty());
  for (const CaptureLandmarkSample& s : frontal)
    EXPECT_LE(truth.view_angle_deg(truth.frame(s.take, s.frame), s.camera), 20) << s.camera << ", frame " << s.frame;
  options.cameras = {"cam09"};
  const std::string error = test::error_message([&] { capture_landmark_samples(capture, vertices, options); });
  EXPECT_NE(error.find("rig.json: has no camera cam09"), std::string::npos) << error;
}

// The median pixel error of a predictor on the capture's frame 3 (held out:
// the command trains on frames 0, 2 and 4) in every camera within 35 degrees.
double held_out_median_px(const fs::path& capture, const fs::path& predictor) {
  const StudioLandmarkTruth truth(capture, model_landmark_vertices(studio_head_model(capture)));
  const landmarks::LandmarkDetector detector(predictor);
  const StudioFrameLandmarks frame = truth.frame("expressions", 3);
  std::vector<double> errors;
  for (const std::string& camera : truth.rig().camera_names()) {
    if (truth.view_angle_deg(frame, camera) > 35) continue;
    const landmarks::LandmarkSample sample = truth.sample(frame, camera);
    const auto found = detector.detect(sample.image, sample.box).value();
    for (int i = 0; i < landmarks::kLandmarkCount; ++i)
      if (sample.landmarks[i].allFinite()) errors.push_back((found[i] - sample.landmarks[i]).norm());
  }
  std::nth_element(errors.begin(), errors.begin() + long(errors.size() / 2), errors.end());
  return errors[errors.size() / 2];
}

TEST(LandmarkCapture, CommandTrainsAPredictorThatFindsHeldOutLandmarks) {
  TEGA_REQUIRE_ICT_FACEKIT(ict);
  const fs::path& capture = small_capture(ict);
  const test::TempDir dir;
  const fs::path predictor = dir / "landmarks.dat";
  const auto r = test::run_tega("landmarks train --capture " + capture.string() + " --out " + predictor.string() +
                                " --threads 2 --set training.trees_per_cascade_level=100"
                                " --set training.oversampling=10");
  std::cout << r.output;
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("held-out fit"), std::string::npos) << r.output;
  const double median = held_out_median_px(capture, predictor);
  std::cout << "held-out frame 3: median landmark error " << median << " px\n";
  EXPECT_LE(median, 2.5);
}

TEST(LandmarkCapture, CommandRefusesAFolderThatIsNotACapture) {
  const test::TempDir dir;
  fs::create_directories(dir / "photos");
  const auto r = test::run_tega("landmarks train --capture " + (dir / "photos").string() + " --out " +
                                (dir / "p.dat").string());
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find((dir / "photos/ground_truth/head/head.json").string()), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "p.dat"));
}

TEST(LandmarkCapture, CommandNeedsOut) {
  const test::TempDir dir;
  const auto r = test::run_tega("landmarks train --capture " + dir.path().string());
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("--out"), std::string::npos) << r.output;
}

TEST(LandmarkCapture, CommandRefusesAnUnknownOption) {
  const auto r = test::run_tega("landmarks train --print-options --set sampling.frame_step=2");
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("frame_step"), std::string::npos) << r.output;
  const auto printed = test::run_tega("landmarks train --print-options --set sampling.frame_stride=3");
  EXPECT_EQ(printed.exit_code, 0) << printed.output;
  EXPECT_NE(printed.output.find("frame_stride: 3"), std::string::npos) << printed.output;
}

}  // namespace
}  // namespace tega::scoring
