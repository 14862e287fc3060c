// load_landmark_predictor where the build has dlib: tracking's detector.
#include <memory>

#include "tega/tools/detected_landmarks.h"
#include "tega/landmarks/landmarks.h"

namespace tega::tools {

LandmarkPredictor load_landmark_predictor(const std::filesystem::path& file) {
  const auto detector = std::make_shared<const tega::landmarks::LandmarkDetector>(file);
  return [detector](const Image8& image, const Eigen::AlignedBox2d& box) {
    // With a box the detector always places the landmarks.
    return detector->detect(image, box).value();
  };
}

}  // namespace tega::tools
