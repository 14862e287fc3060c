// Landmarks from a dlib shape predictor that the test trains on virtual-studio
// renders of ICT-FaceKit's head and scores on frames and a camera it never
// saw, against the true mesh's landmark vertices projected through the rig.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "small_studio.h"
#include "tega/core/image.h"
#include "tega/landmarks/landmarks.h"
#include "tega/scoring/landmark_capture_training.h"
#include "tega/scoring/studio_landmarks.h"
#include "tega/synth/virtual_studio.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace tega::landmarks {
namespace {

constexpr int kCameras = 9;
constexpr int kFrames = 6;
const std::vector<std::string> kTakes = {"expressions", "speech"};
// Training sees the even frames of every camera but one, scoring the odd
// frames of every camera: new expressions and poses, and a new view.
const std::string kHeldOutCamera = "cam04";
bool is_training_frame(int frame) { return frame % 2 == 0; }

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Cameras within 30 degrees of the face's front: the 68-point markup, like
// dlib's frontal face detector, is for faces seen from the front. Two samples
// per pixel and axis and one subdivision level render three times faster
// than the defaults and change nothing a landmark depends on.
synth::Options studio_options(const fs::path& ict) {
  synth::Options o = test::small_studio(kCameras, 512, 384, kFrames);
  o.head = ict.string();
  o.takes = kTakes;
  o.studio.cap_half_angle_deg = 30;
  o.supersampling = 2;
  o.fine_subdivisions = 1;
  o.write_fine_meshes = false;
  return o;
}

struct Capture {
  fs::path root;
  std::vector<int> landmark_vertices;
  std::unique_ptr<scoring::StudioLandmarkTruth> truth;
};

const Capture& studio_capture(const fs::path& ict) {
  static const test::TempDir dir;
  static const Capture capture = [&] {
    const auto start = std::chrono::steady_clock::now();
    const synth::SynthSummary summary = synth::render_virtual_studio(studio_options(ict), dir / "capture");
    std::cout << "rendered " << summary.images << " images in " << seconds_since(start) << " s\n";
    Capture c;
    c.root = dir / "capture";
    c.landmark_vertices = scoring::model_landmark_vertices(ict);
    c.truth = std::make_unique<scoring::StudioLandmarkTruth>(c.root, c.landmark_vertices);
    return c;
  }();
  return capture;
}

// The true landmarks of one image.
landmarks::LandmarkSample true_sample(const Capture& capture, const std::string& take, const std::string& camera_name,
                           int frame) {
  return capture.truth->sample(capture.truth->frame(take, frame), camera_name);
}

double median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

double percentile95(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[static_cast<size_t>(0.95 * (values.size() - 1))];
}

// Pixel distance of every known landmark from its detection.
std::vector<double> landmark_errors(const landmarks::LandmarkSample& truth, const std::vector<Eigen::Vector2d>& detected) {
  std::vector<double> errors;
  for (int i = 0; i < landmarks::kLandmarkCount; ++i)
    if (truth.landmarks[i].allFinite()) errors.push_back((detected[i] - truth.landmarks[i]).norm());
  return errors;
}

const fs::path& trained_predictor(const fs::path& ict) {
  static const test::TempDir dir;
  static const fs::path predictor = [&] {
    const Capture& capture = studio_capture(ict);
    scoring::LandmarkSamplingOptions sampling;
    sampling.frame_stride = 2;  // the even frames
    sampling.max_view_angle_deg = 180;
    for (const std::string& camera : capture.truth->rig().camera_names())
      if (camera != kHeldOutCamera) sampling.cameras.push_back(camera);
    std::vector<landmarks::LandmarkSample> samples;
    for (scoring::CaptureLandmarkSample& sample : scoring::capture_landmark_samples(capture.root, capture.landmark_vertices, sampling))
      samples.push_back(std::move(sample.sample));
    const auto start = std::chrono::steady_clock::now();
    landmarks::train_landmark_predictor(samples, landmarks::LandmarkTrainingOptions{}, dir / "predictor.dat");
    std::cout << "trained on " << samples.size() << " images in " << seconds_since(start) << " s\n";
    return dir / "predictor.dat";
  }();
  return predictor;
}

TEST(Landmarks, TrainedPredictorFindsTheLandmarksOfUnseenFramesAndCameras) {
  TEGA_REQUIRE_ICT_FACEKIT(ict);
  const Capture& capture = studio_capture(ict);
  const landmarks::LandmarkDetector detector(trained_predictor(ict));
  std::vector<double> errors, held_out_camera_errors;
  for (const std::string& take : kTakes)
    for (const std::string& camera : capture.truth->rig().camera_names())
      for (int frame = 0; frame < kFrames; ++frame) {
        if (is_training_frame(frame)) continue;
        const landmarks::LandmarkSample truth = true_sample(capture, take, camera, frame);
        const auto detected = detector.detect(truth.image, truth.box);
        ASSERT_TRUE(detected.has_value());
        ASSERT_EQ(detected->size(), size_t{landmarks::kLandmarkCount});
        const std::vector<double> image_errors = landmark_errors(truth, *detected);
        errors.insert(errors.end(), image_errors.begin(), image_errors.end());
        if (camera == kHeldOutCamera)
          held_out_camera_errors.insert(held_out_camera_errors.end(), image_errors.begin(), image_errors.end());
      }
  std::cout << "landmark error on unseen frames, px: median " << median(errors) << ", 95th percentile "
            << percentile95(errors) << "; of the unseen camera: median " << median(held_out_camera_errors)
            << ", 95th percentile " << percentile95(held_out_camera_errors) << "\n";
  // Measured: medians 1.2 and 1.1 px, 95th percentiles 7.0 and 5.8 px (the
  // outliers are expressions at their peak, which training saw less of).
  EXPECT_LE(median(errors), 2.0);
  EXPECT_LE(median(held_out_camera_errors), 2.0);
  EXPECT_LE(percentile95(errors), 10.0);
}

// The predictor learnt boxes drawn around the landmarks, not the tighter,
// squarer ones of dlib's face detector, so without a box the landmarks are
// only roughly right (4 to 32 px off); what is tested is that the detector
// finds the face, and nothing where there is none.
TEST(Landmarks, FrontalFaceDetectorFindsTheFaceWithoutABox) {
  TEGA_REQUIRE_ICT_FACEKIT(ict);
  const Capture& capture = studio_capture(ict);
  const landmarks::LandmarkDetector detector(trained_predictor(ict));
  std::vector<landmarks::LandmarkSample> frontal_views;
  for (int frame = 0; frame < kFrames; ++frame) frontal_views.push_back(true_sample(capture, "speech", "cam00", frame));
  for (size_t frame = 0; frame < frontal_views.size(); ++frame) {
    const landmarks::LandmarkSample& truth = frontal_views[frame];
    const auto detected = detector.detect(truth.image, std::nullopt);
    ASSERT_TRUE(detected.has_value()) << "no face found in frame " << frame;
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& landmark : *detected) centre += landmark / landmarks::kLandmarkCount;
    EXPECT_TRUE(truth.box.contains(centre)) << "frame " << frame << ": landmarks centred at " << centre.transpose()
                                               << ", away from the face";
  }
  const Image8 empty_studio = read_image_u8(capture.root / "takes/clean_plate/cam00/000000.png");
  EXPECT_FALSE(detector.detect(empty_studio, std::nullopt).has_value());
}

// Every detect() scans with a detector of its own: threads side by side find
// what one thread finds.
TEST(Landmarks, DetectsFromSeveralThreadsAtOnce) {
  TEGA_REQUIRE_ICT_FACEKIT(ict);
  const Capture& capture = studio_capture(ict);
  const landmarks::LandmarkDetector detector(trained_predictor(ict));
  std::vector<Image8> images;
  for (int frame = 0; frame < kFrames; ++frame)
    images.push_back(true_sample(capture, "expressions", "cam00", frame).image);
  std::vector<std::optional<std::vector<Eigen::Vector2d>>> alone, together(images.size());
  for (const Image8& image : images) alone.push_back(detector.detect(image, std::nullopt));
  std::vector<std::thread> threads;
  for (size_t i = 0; i < images.size(); ++i)
    threads.emplace_back([&, i] { together[i] = detector.detect(images[i], std::nullopt); });
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(together, alone);
}

}  // namespace
}  // namespace tega::landmarks
