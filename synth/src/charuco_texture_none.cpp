// Built without OpenCV: the calibration take cannot be rendered.

#include "tega/core/error.h"
#include "tega/synth/charuco_board.h"

namespace tega::synth {

bool charuco_texture_available() { return false; }

ImageF charuco_texture(const CharucoBoardSpec&) {
  throw Error("this build of tega has no OpenCV: the ChArUco calibration take is not available");
}

}  // namespace tega::synth
