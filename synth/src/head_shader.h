#pragma once
// Shades samples of the fine head mesh: skin albedo at the sample's UV,
// darkened by the crease shading of the wrinkles, or the eye's colour by the
// direction from its eyeball's centre; then the studio lighting.

#include <vector>

#include "tega/synth/appearance.h"
#include "tega/synth/fine_mesh.h"
#include "tega/synth/rasterizer.h"

namespace tega::synth {

class HeadShader {
 public:
  HeadShader(const Head& head, const FineMeshMaker& maker, const Appearance& appearance);
  // A surface drawing `frame` (world space); `frame` must outlive it.
  Surface surface(const FineFrame& frame) const;

 private:
  const FineMeshMaker& maker_;
  const Appearance& appearance_;
  std::vector<Eigen::Vector3f> face_points_;      // neutral, face frame units
  std::vector<Eigen::Vector3f> eye_directions_;   // neutral, from the eyeball centre, face frame axes
};

}  // namespace tega::synth
