#pragma once
// Reading a Multiface capture (docs/multiface.md):
//
//   CAPTURE/
//     KRT                                    cameras, translations in millimetres
//     frame_list.txt                         "<EXP> <frame>" per line
//     images/<EXP>/<camera>/<frame>.png      1334 x 2048 RGB, distorted as the lens saw it
//     tracked_mesh/<EXP>/<frame>.bin         float32 7306 x 3, head space, millimetres
//     tracked_mesh/<EXP>/<frame>.obj         the same mesh with the topology and UVs
//     tracked_mesh/<EXP>/<frame>_transform.txt   3x4 head pose, head -> world, millimetres
//
// Everything read here is converted to metres.

#include <filesystem>
#include <string>
#include <vector>

#include "tega/core/geometry.h"
#include "tega/core/mesh.h"

namespace tega::ingest {

inline constexpr double kMetresPerMillimetre = 0.001;

struct MultifaceFrame {
  std::string sequence;  // expression sequence, e.g. E057_Cheeks_Puffed
  std::string frame;     // frame number as written, e.g. 021897
  // The dataset's frame id: "<EXP>_<frame>".
  std::string id() const { return sequence + "_" + frame; }
};

struct MultifaceCapture {
  std::filesystem::path root;

  std::filesystem::path krt() const { return root / "KRT"; }
  std::filesystem::path frame_list() const { return root / "frame_list.txt"; }
  std::filesystem::path image(const std::string& camera, const MultifaceFrame& f) const {
    return root / "images" / f.sequence / camera / (f.frame + ".png");
  }
  std::filesystem::path mesh_bin(const MultifaceFrame& f) const {
    return root / "tracked_mesh" / f.sequence / (f.frame + ".bin");
  }
  std::filesystem::path mesh_obj(const MultifaceFrame& f) const {
    return root / "tracked_mesh" / f.sequence / (f.frame + ".obj");
  }
  std::filesystem::path transform(const MultifaceFrame& f) const {
    return root / "tracked_mesh" / f.sequence / (f.frame + "_transform.txt");
  }
};

// The lines of frame_list.txt in file order. Throws tega::Error naming the
// file and line for a line that is not two words, and for an empty list.
std::vector<MultifaceFrame> read_frame_list(const std::filesystem::path& file);

// A <frame>_transform.txt: 3 rows of 4 numbers [R | t] (a 4th row 0 0 0 1 is
// allowed), head (mesh) space to world, t in millimetres; returned in metres.
// Throws tega::Error naming the file when it is malformed or R is not a rotation.
RigidTransform read_head_transform(const std::filesystem::path& file);

// The tracked mesh of a frame in head space, metres: the .bin when present,
// else the .obj's positions. Throws tega::Error naming the file when neither
// exists or the vertex count differs from `expected_vertices`.
Vertices read_tracked_vertices(const MultifaceCapture& capture, const MultifaceFrame& frame, int expected_vertices);

}  // namespace tega::ingest
