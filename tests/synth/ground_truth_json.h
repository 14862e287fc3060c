#pragma once
// Reading the virtual studio's ground-truth JSON files in the synth tests.

#include <nlohmann/json.hpp>

#include "tega/core/json_file.h"
#include "tega/core/rig.h"

namespace tega::synth::test {

// A 3x4 [R | t] written as rows.
inline RigidTransform pose_from_json(const nlohmann::json& rows) {
  Eigen::Matrix<double, 3, 4> m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = rows[r][c];
  return RigidTransform::from_matrix(m);
}

}  // namespace tega::synth::test
