#pragma once
// 2D facial landmarks from a user-supplied dlib 68-point shape predictor
// (the Multi-PIE markup of dlib's shape_predictor_68_face_landmarks.dat, or
// one trained with train_landmark_predictor). No landmark model ships with
// tega: tracking works without one, and uses one when it is configured.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "tega/core/image.h"
#include "tega/core/landmark_box.h"

namespace tega::landmarks {

constexpr int kLandmarkCount = 68;

// A face's bounding box in pixels: min = top-left, max = bottom-right.
using FaceBox = Eigen::AlignedBox2d;

// The box tega's predictors are trained on and given: tega::grown_landmark_box
// (tega/core/landmark_box.h).

class LandmarkDetector {
 public:
  // Throws tega::Error naming the file when it is missing or not a dlib
  // shape predictor with 68 parts.
  explicit LandmarkDetector(const std::filesystem::path& model);
  ~LandmarkDetector();
  LandmarkDetector(const LandmarkDetector&) = delete;
  LandmarkDetector& operator=(const LandmarkDetector&) = delete;

  // The 68 landmarks (pixels, dlib's order) of the face in `box`, or, with
  // no box, of the largest face dlib's frontal face detector finds (nullopt
  // when it finds none). `image`: 8-bit RGB or grey. Thread-safe.
  std::optional<std::vector<Eigen::Vector2d>> detect(const Image8& image, const std::optional<FaceBox>& box) const;

 private:
  struct Model;
  std::unique_ptr<Model> model_;
};

// One training image: a face, its box and its 68 landmarks (pixels). A
// landmark with a NaN coordinate is unknown (hidden): training skips it. Boxes
// should be drawn the way detect() will be given them (or, for detect()
// without a box, the way dlib's frontal face detector draws them).
struct LandmarkSample {
  Image8 image;
  FaceBox box;
  std::vector<Eigen::Vector2d> landmarks;
};

// dlib's shape_predictor_trainer settings (Kazemi and Sullivan's ensemble of
// regression trees), plus mirroring.
struct LandmarkTrainingOptions {
  int cascade_depth = 10;
  int tree_depth = 4;
  int trees_per_cascade_level = 200;
  int oversampling = 20;  // random initial shapes per sample
  double nu = 0.1;        // shrinkage (learning rate) of each tree
  // Adds every sample mirrored left to right (landmarks renumbered by the
  // 68-point markup's symmetry): twice the views for the same renders.
  bool add_mirrored_samples = true;
  int threads = 0;  // 0: one per hardware thread
  // dlib prints the trees fitted so far and the time left to stdout.
  bool print_progress = false;

  template <class V>
  void visit(V& v) {
    v("cascade_depth", cascade_depth, "Cascade levels, each refining the shape the one before left.");
    v("tree_depth", tree_depth, "Depth of every regression tree (2^depth leaves).");
    v("trees_per_cascade_level", trees_per_cascade_level, "Regression trees fitted at each cascade level.");
    v("oversampling", oversampling, "Random initial shapes per training sample.");
    v("nu", nu, "Shrinkage (learning rate) of each tree, in (0, 1].");
    v("add_mirrored_samples", add_mirrored_samples,
      "Also train on every sample mirrored left to right (landmarks renumbered by the markup's symmetry).");
    v("threads", threads, "Worker threads (0: one per hardware thread).");
  }
};

// Trains a dlib shape predictor (dlib's shape_predictor_trainer) on the
// samples and writes it to `out` (atomically) in the format
// LandmarkDetector reads. Throws tega::Error naming `out` for samples without
// 68 landmarks or with an empty box or image, a landmark unknown in every
// sample, or options out of range.
void train_landmark_predictor(const std::vector<LandmarkSample>& samples, const LandmarkTrainingOptions& options,
                              const std::filesystem::path& out);

}  // namespace tega::landmarks
