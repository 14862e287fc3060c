#pragma once
// Options of a small virtual-studio capture for stage tests: `cameras` at
// width x height, `frames` frames of the `expressions` take and the clean
// plate, no calibration take, every frame in the dataset's train split.
// Header-only: test executables that link tega_synth include it.

#include "tega/synth/options.h"

namespace tega::test {

inline synth::Options small_studio(int cameras, int width, int height, int frames) {
  synth::Options o;
  o.studio.cameras = cameras;
  o.studio.width = width;
  o.studio.height = height;
  o.frames = frames;
  o.calibration_frames = 0;
  o.takes = {"expressions"};
  o.test_takes = {};
  o.test_cameras = 1;
  return o;
}

}  // namespace tega::test
