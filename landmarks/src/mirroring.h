#pragma once
// A face sample seen in a mirror: what a camera on the other side of the face
// would see of a left-right symmetric face.

#include "tega/landmarks/landmarks.h"

namespace tega::landmarks {

// The image flipped left to right, its box likewise, and the landmarks moved
// and renumbered so that each keeps its meaning (the subject's left eye
// corner of the mirrored image is the mirror of the right one).
LandmarkSample mirrored(const LandmarkSample& sample);

}  // namespace tega::landmarks
