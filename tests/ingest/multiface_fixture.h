#pragma once
// A tiny capture in Multiface's exact layout (docs/multiface.md), generated
// with known geometry so that ingest can be checked against ground truth:
// an ellipsoid head with a checker texture in UV, three expression
// sequences, a rig of 9 cameras (7 in a ring in front of the face, one behind
// the head, one above it) with lens distortion, KRT and meshes in
// millimetres. The world is turned and shifted away from the head's axes so
// that no code can rely on them. Never real Multiface files.

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "tega/core/image.h"
#include "tega/core/mesh.h"
#include "tega/core/rig.h"
#include "tega/ingest/multiface_capture.h"

namespace tega::test {

struct MultifaceFixtureOptions {
  int width = 168;  // Multiface's 1334 x 2048 portrait, about an eighth
  int height = 256;
  int frames_per_sequence = 3;
  bool distortion = true;
};

struct MultifaceFixture {
  std::filesystem::path root;
  Rig rig;                                    // metres, with the distortion written to the KRT
  Mesh head;                                  // topology, UVs; the neutral in head space, metres
  std::vector<ingest::MultifaceFrame> frames; // frame_list.txt order
  std::map<std::string, Vertices> head_space; // by frame id: tracked mesh, head space, metres
  std::map<std::string, RigidTransform> poses;// by frame id: head -> world, metres
  std::vector<std::string> ring;              // the frontal cameras, from the subject's right to left
  std::string behind, above;                  // the cameras the default selection must drop

  static constexpr const char* kNeutral = "E001_Neutral_Eyes_Open";
  static constexpr const char* kTrainExpression = "E057_Cheeks_Puffed";
  static constexpr const char* kTestExpression = "EXP_ROM07_Facial_Expressions";

  // The frame's world-space mesh.
  Vertices world(const std::string& frame_id) const;
  // RGB image of the frame through `camera` (its distortion included).
  Image8 render(const Camera& camera, const std::string& frame_id) const;
  // 255 where the frame's mesh covers the pixel, seen through `camera`.
  Image8 coverage(const Camera& camera, const std::string& frame_id) const;
};

MultifaceFixture write_multiface_fixture(const std::filesystem::path& root, const MultifaceFixtureOptions& options = {});

}  // namespace tega::test
