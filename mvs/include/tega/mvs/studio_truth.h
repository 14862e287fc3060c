#pragma once
// The virtual studio's ground truth for MVS (docs/virtual-studio.md): a
// performance frame's fine mesh (what the cameras saw) and its face region,
// the part every camera of the frontal cap sees and accuracy targets speak of.
//
// The face region is chosen on the coarse template, in the face frame the
// studio defines (origin between the eyeball centres, lengths in
// interocular distances, +y up, +z out of the face): triangles within 1.1
// to either side, from 1.9 below the eyes to 1.1 above, in front of 0.9
// behind them, facing forward. Each fine triangle belongs to the coarse
// triangle it subdivides (fine_topology.obj holds them in runs, one per
// coarse triangle).

#include <filesystem>
#include <string>
#include <vector>

#include "tega/core/mesh.h"

namespace tega::mvs {

struct StudioTruth {
  Mesh fine;                     // world space
  std::vector<int> face_region;  // faces of `fine`
  std::vector<int> face_vertices;  // the same region's vertices of the coarse template (tracked meshes)
};

// Throws tega::Error naming the file when the capture lacks ground truth.
StudioTruth load_studio_truth(const std::filesystem::path& capture, const std::string& take, int frame);

}  // namespace tega::mvs
