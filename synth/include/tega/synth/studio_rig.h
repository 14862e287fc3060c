#pragma once
// The virtual studio's camera rig: cameras spread evenly over a spherical cap
// in front of the face (a Fibonacci spiral starting at the frontal camera),
// all aimed at the world origin, where the head's pivot sits. Each lens gets
// its own small variation of distortion and principal point, as real lenses
// do; the variation depends on the camera's index only, so every capture of
// the same studio options has the same rig.

#include "tega/core/rig.h"
#include "tega/synth/options.h"

namespace tega::synth {

// Camera names are cam00, cam01, ... (three digits from 100 cameras on).
Rig make_studio_rig(const StudioOptions& options);

}  // namespace tega::synth
