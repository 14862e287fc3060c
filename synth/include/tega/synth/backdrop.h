#pragma once
// The studio backdrop: a large sphere around the rig with a textured
// cyclorama (fabric weave, panel seams, tape marks, a darker floor), so that
// the clean plate has structure for matting and background subtraction. It
// is static and unaffected by the head (no shadows), so the clean plate is
// exactly the background of every take, up to sensor noise.

#include <cstdint>

#include "tega/core/camera.h"
#include "tega/core/image.h"

namespace tega::synth {

class Backdrop {
 public:
  explicit Backdrop(uint64_t seed);
  Eigen::Vector3f colour(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const;
  // What the camera sees of the backdrop at each pixel centre, in [0, 1].
  ImageF render(const Camera& camera) const;

 private:
  uint64_t seed_;
};

}  // namespace tega::synth
