// Bad input to the landmark predictor's reader and trainer: clear errors that
// name the file, never a half-loaded model.
#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "tega/core/error.h"
#include "tega/landmarks/landmarks.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace tega::landmarks {
namespace {

std::string error_of(const std::function<void()>& run) {
  try {
    run();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// Noise images with landmarks on a circle: enough for dlib to train a
// (useless) predictor in milliseconds, so that a valid file is at hand.
std::vector<landmarks::LandmarkSample> noise_samples() {
  std::mt19937 random(7);
  std::vector<landmarks::LandmarkSample> samples(3);
  for (landmarks::LandmarkSample& sample : samples) {
    sample.image = Image8(64, 48, 1);
    for (uint8_t& pixel : sample.image.pixels) pixel = static_cast<uint8_t>(random());
    sample.box = landmarks::FaceBox(Eigen::Vector2d(8, 4), Eigen::Vector2d(56, 44));
    for (int i = 0; i < landmarks::kLandmarkCount; ++i) {
      const double angle = 2 * M_PI * i / landmarks::kLandmarkCount;
      sample.landmarks.emplace_back(32 + 15 * std::cos(angle), 24 + 15 * std::sin(angle));
    }
  }
  return samples;
}

landmarks::LandmarkTrainingOptions tiny_training() {
  landmarks::LandmarkTrainingOptions options;
  options.cascade_depth = 1;
  options.trees_per_cascade_level = 2;
  options.oversampling = 1;
  options.threads = 1;
  return options;
}

TEST(LandmarkInput, MissingModelIsAnErrorNamingIt) {
  const test::TempDir dir;
  const fs::path missing = dir / "shape_predictor_68_face_landmarks.dat";
  const std::string error = error_of([&] { landmarks::LandmarkDetector detector(missing); });
  EXPECT_NE(error.find(missing.string()), std::string::npos) << error;
  EXPECT_NE(error.find("not found"), std::string::npos) << error;
}

TEST(LandmarkInput, FileThatIsNotAPredictorIsAnErrorNamingIt) {
  const test::TempDir dir;
  const fs::path text = dir / "predictor.dat";
  test::write_text(text, "version https://git-lfs.github.com/spec/v1\noid sha256:0\nsize 99693937\n");
  const std::string error = error_of([&] { landmarks::LandmarkDetector detector(text); });
  EXPECT_NE(error.find(text.string()), std::string::npos) << error;
  EXPECT_NE(error.find("not a dlib shape predictor"), std::string::npos) << error;
}

TEST(LandmarkInput, TruncatedPredictorIsAnErrorNamingIt) {
  const test::TempDir dir;
  const fs::path whole = dir / "whole.dat", truncated = dir / "truncated.dat";
  landmarks::train_landmark_predictor(noise_samples(), tiny_training(), whole);
  EXPECT_NO_THROW(landmarks::LandmarkDetector detector(whole));
  fs::copy_file(whole, truncated);
  fs::resize_file(truncated, fs::file_size(whole) / 2);
  const std::string error = error_of([&] { landmarks::LandmarkDetector detector(truncated); });
  EXPECT_NE(error.find(truncated.string()), std::string::npos) << error;
  EXPECT_NE(error.find("not a dlib shape predictor"), std::string::npos) << error;
}

TEST(LandmarkInput, TrainingRefusesSamplesWithoutAllLandmarks) {
  const test::TempDir dir;
  const fs::path out = dir / "predictor.dat";
  std::vector<landmarks::LandmarkSample> samples = noise_samples();
  samples[1].landmarks.resize(12);
  const std::string error = error_of([&] { landmarks::train_landmark_predictor(samples, tiny_training(), out); });
  EXPECT_NE(error.find(out.string()), std::string::npos) << error;
  EXPECT_NE(error.find("sample 1 has 12 landmarks"), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(out));
}

TEST(LandmarkInput, TrainingRefusesALandmarkUnknownEverywhere) {
  const test::TempDir dir;
  std::vector<landmarks::LandmarkSample> samples = noise_samples();
  for (landmarks::LandmarkSample& sample : samples) sample.landmarks[30] = Eigen::Vector2d::Constant(NAN);
  const std::string error = error_of([&] { landmarks::train_landmark_predictor(samples, tiny_training(), dir / "p.dat"); });
  EXPECT_NE(error.find("landmark 30 is unknown in every sample"), std::string::npos) << error;
}

TEST(LandmarkInput, DetectRefusesAnImageWithoutPixels) {
  const test::TempDir dir;
  landmarks::train_landmark_predictor(noise_samples(), tiny_training(), dir / "predictor.dat");
  const landmarks::LandmarkDetector detector(dir / "predictor.dat");
  EXPECT_THROW(detector.detect(Image8(), landmarks::FaceBox(Eigen::Vector2d(0, 0), Eigen::Vector2d(10, 10))), Error);
}

}  // namespace
}  // namespace tega::landmarks
