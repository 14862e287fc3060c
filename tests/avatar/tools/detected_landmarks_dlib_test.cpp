// landmark_px with a real dlib shape predictor, trained here in about a
// second on a synthetic face-like pattern moved about in a fixed box, so
// that it reads the landmarks' position from the pixels, as tega eval's use
// of it (the same box for render and truth) needs.
#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>

#include "tega/core/error.h"
#include "tega/tools/detected_landmarks.h"
#include "tega/landmarks/landmarks.h"
#include "test_support.h"

namespace {

using namespace tega;
using namespace tega::tools;

constexpr int kPatternSize = 96;

struct Wave {
  double fx, fy, phase;
};

// A bright face-sized blob carrying a smooth texture, centred at (48, 48) +
// shift: a function of the position, so that any sub-pixel shift is exact.
at::Tensor face_pattern(const Eigen::Vector2d& shift) {
  static const std::vector<Wave> waves = [] {
    std::mt19937 random(11);
    std::uniform_real_distribution<double> frequency(-0.45, 0.45), phase(0, 2 * M_PI);
    std::vector<Wave> out(6);
    for (Wave& w : out) w = {frequency(random), frequency(random), phase(random)};
    return out;
  }();
  const at::Tensor x = at::arange(kPatternSize, at::kDouble).view({1, -1}) - (48 + shift.x());
  const at::Tensor y = at::arange(kPatternSize, at::kDouble).view({-1, 1}) - (48 + shift.y());
  at::Tensor texture = at::zeros({kPatternSize, kPatternSize}, at::kDouble);
  for (const Wave& w : waves)
    texture = texture + at::sin(w.fx * x + w.fy * y + w.phase) / static_cast<double>(waves.size());
  const at::Tensor face = at::exp(-(x.square() + y.square()) / (2 * 22.0 * 22.0));
  return (0.1 + 0.8 * face * (0.5 + 0.5 * texture)).to(at::kFloat).expand({3, kPatternSize, kPatternSize});
}

Image8 pattern_image(const at::Tensor& rgb) {
  const at::Tensor pixels = rgb.mul(255).round().permute({1, 2, 0}).to(at::kByte).contiguous();
  Image8 image(kPatternSize, kPatternSize, 3);
  std::copy_n(pixels.data_ptr<uint8_t>(), image.pixels.size(), image.pixels.begin());
  return image;
}

// The 68 landmarks of the unshifted pattern, scattered over the face.
const std::vector<Eigen::Vector2d>& pattern_landmarks() {
  static const std::vector<Eigen::Vector2d> points = [] {
    std::mt19937 random(5);
    std::uniform_real_distribution<double> offset(-20, 20);
    std::vector<Eigen::Vector2d> out;
    for (int i = 0; i < tega::landmarks::kLandmarkCount; ++i) out.emplace_back(48 + offset(random), 48 + offset(random));
    return out;
  }();
  return points;
}

// What tega eval gives the detector: the true landmarks' box, grown.
Eigen::AlignedBox2d pattern_box() {
  std::vector<std::optional<Eigen::Vector2d>> landmarks(pattern_landmarks().begin(), pattern_landmarks().end());
  return *landmark_detection_box(landmarks);
}

const std::filesystem::path& pattern_predictor() {
  static const test::TempDir dir;
  static const std::filesystem::path file = [] {
    std::mt19937 random(9);
    std::uniform_real_distribution<double> shift(-7, 7);
    std::vector<tega::landmarks::LandmarkSample> samples;
    for (int i = 0; i < 60; ++i) {
      const Eigen::Vector2d moved(shift(random), shift(random));
      tega::landmarks::LandmarkSample sample{pattern_image(face_pattern(moved)), pattern_box(), {}};
      for (const Eigen::Vector2d& p : pattern_landmarks()) sample.landmarks.push_back(p + moved);
      samples.push_back(std::move(sample));
    }
    tega::landmarks::LandmarkTrainingOptions options;
    options.cascade_depth = 8;
    options.trees_per_cascade_level = 50;
    options.oversampling = 10;
    options.add_mirrored_samples = false;  // the pattern has no mirror symmetry
    options.threads = 2;
    tega::landmarks::train_landmark_predictor(samples, options, dir / "pattern.dat");
    return dir / "pattern.dat";
  }();
  return file;
}

TEST(DetectedLandmarks, ZeroForIdenticalImagesAndTheShiftOfAShiftedRender) {
  const LandmarkPredictor predictor = load_landmark_predictor(pattern_predictor());
  const Eigen::AlignedBox2d box = pattern_box();
  // The truth at a shift that no training sample had.
  const Eigen::Vector2d truth_shift(1.3, -0.6);
  const at::Tensor truth = face_pattern(truth_shift);
  EXPECT_EQ(detected_landmark_error_px(predictor, truth, truth, box), 0.0);
  for (const double pixels : {3.0, 6.0}) {
    const at::Tensor render = face_pattern(truth_shift + Eigen::Vector2d(pixels, 0));
    const double error = detected_landmark_error_px(predictor, render, truth, box);
    std::cout << "render shifted by " << pixels << " px: landmark_px " << error << "\n";
    EXPECT_NEAR(error, pixels, 0.25 * pixels);
  }
  const at::Tensor diagonal = face_pattern(truth_shift + Eigen::Vector2d(-2.4, 1.8));  // 3 px
  EXPECT_NEAR(detected_landmark_error_px(predictor, diagonal, truth, box), 3.0, 0.75);
}

TEST(DetectedLandmarks, AMissingPredictorIsAnErrorNamingIt) {
  const test::TempDir dir;
  try {
    load_landmark_predictor(dir / "missing.dat");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.dat"), std::string::npos) << e.what();
  }
}

}  // namespace
