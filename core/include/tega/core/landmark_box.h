#pragma once
// The face box tega's 68-point landmark predictors are trained on and given,
// by tracking/ and by tega eval's landmark error alike: a predictor learns
// its box's framing, so training, detection and evaluation must agree.

#include <Eigen/Geometry>

namespace tega {

// The landmarks' own bounding box (pixels) grown by 7.5 % of its size on each
// side (15 % in all).
inline Eigen::AlignedBox2d grown_landmark_box(const Eigen::AlignedBox2d& landmarks) {
  const Eigen::Vector2d margin = 0.075 * landmarks.sizes();
  return Eigen::AlignedBox2d(landmarks.min() - margin, landmarks.max() + margin);
}

}  // namespace tega
