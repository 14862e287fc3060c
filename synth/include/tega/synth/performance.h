#pragma once
// Performance scripts: what the virtual subject does during a take. A script
// is a list of expression events (rise, hold, fall) plus a smooth rigid head
// motion. Time is normalised to the take, so every take shows all of its
// events whatever its frame count; blinks hold long enough to be sampled by
// takes of ten frames or more.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "tega/core/geometry.h"

namespace tega::synth {

struct PerformanceFrame {
  double time = 0;  // in [0, 1] over the take
  // ARKit-named coefficients in [0, 1], in the same order in every frame.
  std::vector<std::pair<std::string, float>> expression;
  // Rigid motion about the world origin, applied after the head's pivot is
  // moved there: head_to_world = motion * (I, -pivot).
  RigidTransform motion;
};

std::vector<std::string> performance_script_names();  // expressions, speech, freestyle
bool is_performance_script(const std::string& name);

// Throws tega::Error for an unknown script or frames < 1.
std::vector<PerformanceFrame> perform(const std::string& script, int frames, uint64_t seed);

}  // namespace tega::synth
