#include <dlib/image_processing.h>
#include <dlib/image_processing/frontal_face_detector.h>
#include <dlib/serialize.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "dlib_conversions.h"
#include "tega/core/error.h"
#include "tega/landmarks/landmarks.h"

namespace tega::landmarks {

struct LandmarkDetector::Model {
  dlib::shape_predictor predictor;
};

namespace {

// Built on first use (half a second: dlib decodes it from text), once per
// process, and never scanned with: dlib's detector keeps scratch state of its
// own (operator() is not const), so every detect() scans with a copy, and
// threads neither share one nor wait for each other.
const dlib::frontal_face_detector& face_detector_prototype() {
  static const dlib::frontal_face_detector prototype = dlib::get_frontal_face_detector();
  return prototype;
}

dlib::shape_predictor read_predictor(const std::filesystem::path& file) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error))
    throw Error(file, "landmark model not found (expected a dlib 68-point shape predictor, .dat)");
  dlib::shape_predictor predictor;
  try {
    dlib::deserialize(file.string()) >> predictor;
  } catch (const std::exception& e) {
    throw Error(file, std::string("not a dlib shape predictor: ") + e.what());
  }
  if (predictor.num_parts() != kLandmarkCount)
    throw Error(file, "the shape predictor has " + std::to_string(predictor.num_parts()) + " landmarks, tega needs " +
                          std::to_string(kLandmarkCount) + " (dlib's 68-point Multi-PIE markup)");
  return predictor;
}

std::optional<dlib::rectangle> largest_face(dlib::frontal_face_detector& face_detector,
                                            const dlib::array2d<unsigned char>& grey) {
  const std::vector<dlib::rectangle> faces = face_detector(grey);
  if (faces.empty()) return std::nullopt;
  return *std::max_element(faces.begin(), faces.end(),
                           [](const dlib::rectangle& a, const dlib::rectangle& b) { return a.area() < b.area(); });
}

}  // namespace

LandmarkDetector::LandmarkDetector(const std::filesystem::path& model)
    : model_(std::make_unique<Model>(Model{read_predictor(model)})) {}

LandmarkDetector::~LandmarkDetector() = default;

std::optional<std::vector<Eigen::Vector2d>> LandmarkDetector::detect(const Image8& image,
                                                                     const std::optional<FaceBox>& box) const {
  const dlib::array2d<unsigned char> grey = to_dlib_grey(image);
  std::optional<dlib::rectangle> face;
  if (box) {
    face = to_dlib_rectangle(*box);
  } else {
    dlib::frontal_face_detector face_detector = face_detector_prototype();
    face = largest_face(face_detector, grey);
  }
  if (!face) return std::nullopt;
  return from_dlib_shape(model_->predictor(grey, *face));
}

}  // namespace tega::landmarks
