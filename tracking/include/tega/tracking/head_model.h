#pragma once
// The head model a tracker fits: a linear blendshape model in ICT-FaceKit's
// directory layout plus the vertex sets tracking needs. The sets come from
// the model directory's `vertex_indices.json` (ICT-FaceKit's own file; keys
// below), so any model laid out the same way can be tracked.

#include <filesystem>
#include <vector>

#include "tega/core/blendshape.h"

namespace tega::tracking {

struct HeadModel {
  std::filesystem::path directory;
  BlendshapeModel shapes;               // metres, head space
  std::vector<int> fit_vertices;        // skin that meets the scanned surface ("idx_to_fitting_verts")
  std::vector<int> landmark_vertices;   // 68 Multi-PIE landmarks in dlib's order, or empty ("idx_to_landmark_verts")
  std::vector<int> eyeball_vertices;    // move with the head only ("eyeball_vertex_ranges", or ICT's)
  std::vector<int> skin_vertices;       // take per-vertex corrections: the fit vertices and the skin around them
                                        // ("skin_vertex_ranges", or ICT's face, head and neck)
  // Fit vertices that no expression moves by more than a millimetre: they
  // alone fix the head pose, so a jaw that opens does not tilt the head.
  std::vector<int> pose_vertices;

  // Every n-th fit vertex.
  std::vector<int> fit_vertices_every(int step) const;

  int num_vertices() const { return shapes.num_vertices(); }
};

// Reads MODEL_DIR (BlendshapeModel::load_directory plus vertex_indices.json).
// Throws tega::Error naming the file for a missing or inconsistent index set,
// or shapes whose vertex counts differ.
HeadModel load_head_model(const std::filesystem::path& directory, double metres_per_unit);

}  // namespace tega::tracking
