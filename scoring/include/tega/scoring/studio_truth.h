#pragma once
// The virtual studio's ground truth for MVS (docs/virtual-studio.md): a
// performance frame's fine mesh (what the cameras saw) and its face region,
// the part the cameras of the frontal cap see and accuracy targets speak of.
//
// The face region starts as a box on the coarse template, in the face frame
// the studio defines (origin between the eyeball centres, lengths in
// interocular distances, +y up, +z out of the face): triangles within 1.1
// to either side, from 1.9 below the eyes to 1.1 above, in front of 0.9
// behind them, facing forward. Each fine triangle belongs to the coarse
// triangle it subdivides (fine_topology.obj holds them in runs, one per
// coarse triangle). Of the box's fine triangles, the region keeps those that
// at least two of the true rig's cameras (the capture's rig.json) see in
// this frame, as stereo needs: the box also holds a closed mouth's teeth and
// socket and the eye sockets behind the eyeballs, which no camera sees.
// Tracked meshes, in the coarse template's topology, are scored on the
// vertices of the coarse triangles most of whose fine triangles the region
// keeps: a tracker is held to the face it can observe.

#include <filesystem>
#include <string>
#include <vector>

#include "tega/core/mesh.h"
#include "tega/core/rig.h"

namespace tega::scoring {

// ground_truth/head/head.json under a truth root.
std::filesystem::path studio_head_json(const std::filesystem::path& truth);

// The model's vertex index of each vertex of the studio's template
// (head.json's source_vertex_runs; the same numbering where it has none).
std::vector<int> studio_model_vertices(const std::filesystem::path& capture);

// Where the studio's ground truth lies: the capture itself, or, for a raw
// capture rendered with truth_apart, CAPTURE.truth/ beside it. Throws
// tega::Error naming ground_truth/head/head.json when neither has it.
std::filesystem::path studio_truth_root(const std::filesystem::path& capture);

// The head model directory the studio rendered (head.json's `source`).
// Throws tega::Error naming head.json for the built-in procedural head, or a
// directory that no longer exists.
std::filesystem::path studio_head_model(const std::filesystem::path& capture);

struct StudioTruth {
  Mesh fine;                     // world space
  std::vector<int> face_region;    // faces of `fine` that two cameras see
  std::vector<int> face_vertices;  // of the coarse template's triangles most of whose fine ones are in face_region
};

// The studio's head and true rig, read once to give the truth of any number
// of frames. Throws tega::Error naming the file when the capture lacks
// ground truth or its rig.json.
class StudioTruthSource {
 public:
  explicit StudioTruthSource(const std::filesystem::path& capture);
  StudioTruth frame(const std::string& take, int frame) const;

 private:
  std::filesystem::path capture_;
  Rig rig_;
  Mesh coarse_, fine_;    // the template and its subdivision (fine_'s positions: the template's)
  int run_ = 0;           // fine triangles per coarse one
  std::vector<int> box_;  // fine triangles of the face box
};

StudioTruth load_studio_truth(const std::filesystem::path& capture, const std::string& take, int frame);

}  // namespace tega::scoring
