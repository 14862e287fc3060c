#pragma once
// The head the virtual studio films: a blendshape model (coarse template
// topology with UVs and ARKit-named expressions), which triangles are
// eyeballs, a face frame derived from the eyes, and the expression wrinkles
// that only the fine (rendered) mesh carries.
//
// Head space follows ICT-FaceKit and OBJ habits: metres, +y up, the face
// looks along +z, +x is the subject's left (ARKit's "_L").

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "tega/core/blendshape.h"

namespace tega::synth {

// A frame attached to the eyes, so that face regions can be placed on any
// head: origin between the eyeball centres, axes right (+x, subject's left),
// up, forward; lengths in interocular distances.
struct FaceFrame {
  Eigen::Vector3d eye_left = Eigen::Vector3d::Zero();   // eyeball centres, head space
  Eigen::Vector3d eye_right = Eigen::Vector3d::Zero();
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // columns: right, up, forward
  double interocular = 0.064;

  Eigen::Vector3d to_face(const Eigen::Vector3d& head_point) const {
    return axes.transpose() * (head_point - origin) / interocular;
  }
};

// A patch of the face that forms furrows (or one groove) as its driving
// expressions rise: a Gaussian window, in face-frame units, times a profile
// across the furrows. Displacement points into the skin; the same profile
// darkens the shading (ambient occlusion in the creases).
struct WrinkleRegion {
  std::string name;
  std::vector<std::string> drivers;  // expression names; the largest coefficient drives
  Eigen::Vector2d centre{0, 0};      // face frame (right, up), interocular units
  Eigen::Vector2d sigma{1, 1};       // window extent along the region's own axes
  double angle = 0;                  // radians; the region's axes rotated from the face frame's
  double period = 0;                 // furrow spacing across the region; 0 = one groove
  double groove_width = 0.05;        // for one groove: its half-width
  double depth_scale = 1.0;          // times Options::wrinkle_depth_m
  double darkening_scale = 1.0;      // times Options::crease_darkening
};

struct Head {
  std::string source;  // "procedural" or the model directory
  BlendshapeModel model;
  std::vector<int32_t> eyeball_faces;  // triangles of model.neutral, ascending
  std::vector<int8_t> triangle_eye;    // per triangle: 0 skin, 1 left eyeball, 2 right eyeball
  // Where the studio left parts of the model out: the model file's vertex
  // index of each vertex, as [first, last] runs (empty: the same numbering).
  std::vector<std::pair<int, int>> source_vertex_runs;
  // The 68 Multi-PIE landmark vertices in the studio's numbering, where the
  // model lists them (vertex_indices.json's idx_to_landmark_verts, as
  // ICT-FaceKit does); empty otherwise. The dataset carries them for
  // tega eval's landmark error and close-ups.
  std::vector<int32_t> landmark_vertices;
  FaceFrame frame;
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();  // head-space point placed at the world origin
  std::vector<WrinkleRegion> wrinkles;
};

// The built-in head: a few thousand vertices, a UV seam at the back of the
// head, separate eyeball spheres with their own UV islands, and the
// expressions eyeBlink_L/R, jawOpen, browInnerUp_L/R, browOuterUp_L/R,
// mouthSmile_L/R.
Head make_procedural_head();

// A blendshape model directory (BlendshapeModel::load_directory). Eyeballs
// are the triangles of polygons [eyeball_polygons[0], eyeball_polygons[1]];
// empty means ICT-FaceKit's range, valid only for ICT-FaceKit's topology (for
// which the see-through overlay meshes around the eyes are also removed).
// Throws tega::Error naming the directory when the eyeballs are unknown.
Head load_head(const std::filesystem::path& directory, double metres_per_unit,
               const std::vector<int>& eyeball_polygons);

// Makes the head a particular subject: the model's identity shapes weighted
// by `identity`, plus, when detail_m > 0, a smooth seeded displacement along
// the skin's normals (bumps of a few centimetres, the largest detail_m high)
// that lies outside the model's span. Eyeballs keep their shape. The model's
// neutral becomes the subject's; its shapes stay as they are. Throws
// tega::Error for more coefficients than identity shapes.
void make_subject(Head& head, const std::vector<double>& identity, double detail_m, uint64_t seed);

// Fills triangle_eye, frame, pivot and the default wrinkle regions from the
// model and eyeball_faces.
void finish_head(Head& head);

}  // namespace tega::synth
