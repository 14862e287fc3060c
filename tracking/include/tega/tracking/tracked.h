#pragma once
// Reading what `tega track` wrote (docs/layouts.md#tracked-meshes) without the
// head model: what later stages (mattes, datasets) need of a tracked subject
// and its takes.

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "tega/core/geometry.h"
#include "tega/core/mesh.h"

namespace tega::tracking {

struct TrackedSubject {
  std::filesystem::path model;          // the head model's directory it was fitted with
  Mesh neutral;                         // identity_neutral.obj: head space, the model's topology and UVs
  std::vector<int> eyeball_vertices;    // move rigidly with the head
  std::vector<int> landmark_vertices;   // 68 Multi-PIE landmarks, or empty
};

struct TrackedFrame {
  int frame = 0;
  std::string status;                   // tracked | failed | skipped
  std::string reason;                   // why not tracked
  RigidTransform head_to_world;         // tracked and failed frames
  std::map<std::string, double> expression;
  std::filesystem::path mesh;           // <frame>.bin (world space), tracked frames only

  bool tracked() const { return status == "tracked"; }
};

// TRACKED/identity.json and its neutral mesh. Throws tega::Error naming the
// file when one is missing or damaged.
TrackedSubject read_tracked_subject(const std::filesystem::path& tracked);

// One frame's record, TRACKED/<take>/<frame:06d>.json. Throws tega::Error
// naming the file when it is damaged.
TrackedFrame read_tracked_frame(const std::filesystem::path& record);

// Every frame of TRACKED/<take>/ that has a record, in frame order. Throws
// tega::Error naming the file when the take was not tracked to its end
// (no track.json) or a record is damaged.
std::vector<TrackedFrame> read_tracked_take(const std::filesystem::path& tracked, const std::string& take);

}  // namespace tega::tracking
