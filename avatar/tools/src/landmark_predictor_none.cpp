// load_landmark_predictor in a build without dlib (no tracking/ folder).
#include "tega/core/error.h"
#include "tega/tools/detected_landmarks.h"

namespace tega::tools {

LandmarkPredictor load_landmark_predictor(const std::filesystem::path& file) {
  throw Error(file, "cannot load the landmark predictor: tega was built without dlib (libdlib-dev), which the landmark "
                    "detector (tracking/'s tega_landmarks) needs; rebuild with dlib or leave out --landmark-predictor");
}

}  // namespace tega::tools
