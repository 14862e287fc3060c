#pragma once
// Tracking scored against the virtual studio's ground truth
// (docs/virtual-studio.md): per-vertex error over the face region, head
// rotation error, and how the expression coefficients follow the true ones.
// The studio's head shares the model's vertex numbering below its
// see-through eye overlays (which it removes), where the face lies.

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "tega/core/mesh.h"

namespace tega::tracking {

struct TrackScores {
  int frames = 0;                         // tracked frames scored
  double vertex_median_m = 0, vertex_p95_m = 0;  // over the face region's vertices of every scored frame
  double rotation_median_deg = 0, rotation_max_deg = 0;
  std::map<std::string, double> correlation;  // per true expression that varies: Pearson r over the frames
};

// One tracked frame to score.
struct TrackedFrame {
  int frame = 0;
  Vertices vertices;              // world space, the model's topology
  Eigen::Matrix3d head_rotation;  // of head_to_world
  std::map<std::string, double> expression;
};

TrackScores score_frames(const std::vector<TrackedFrame>& frames, const std::filesystem::path& capture,
                         const std::string& take);

// `tracked_take`: TRACKED/<take> (its tracked frames); `capture`: the studio's capture with ground_truth/.
TrackScores score_against_studio(const std::filesystem::path& tracked_take, const std::filesystem::path& capture,
                                 const std::string& take);

}  // namespace tega::tracking
