#pragma once
// A tracked subject and its takes on disk (docs/layouts.md#tracked-meshes),
// read and written without the head model: `tega track` writes it, the virtual
// studio writes its truth in it, and later stages (mattes, datasets) read it.
//   TRACKED/identity.json + identity_neutral.obj   the subject
//   TRACKED/<take>/<frame:06d>.bin                 tracked mesh, world space, the model's topology
//   TRACKED/<take>/<frame:06d>.json                status, pose, expression by name, residuals
//   TRACKED/<take>/track.json                      the take's summary, written last

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tega/core/geometry.h"
#include "tega/core/mesh.h"

namespace tega {

struct TrackedSubject {
  std::filesystem::path model;          // the head model's directory it was fitted with
  Mesh neutral;                         // identity_neutral.obj: head space, the model's topology and UVs
  std::vector<int> eyeball_vertices;    // move rigidly with the head
  std::vector<int> landmark_vertices;   // 68 Multi-PIE landmarks, or empty
  std::map<std::string, double> identity;           // the model's identity coefficients by name
  std::map<std::string, double> open_eyes_covered;  // per eye: how much of it the fitted lids cover, or empty
};

struct TrackedFrame {
  int frame = 0;
  std::string status;                   // tracked | failed | skipped
  std::string reason;                   // why not tracked
  RigidTransform head_to_world;         // tracked and failed frames
  std::map<std::string, double> expression;
  std::filesystem::path mesh;           // <frame>.bin (world space), tracked frames only
  // How well the fit matches its data, as the tracker words it (an object;
  // tracked and failed frames), and whether it was fitted from scratch.
  nlohmann::json residuals;
  bool fitted_afresh = false;

  bool tracked() const { return status == "tracked"; }
};

// A subject file (TRACKED/identity.json, or one given to reuse) and the
// neutral mesh it names. Throws tega::Error naming the file when one is
// missing or damaged.
TrackedSubject read_tracked_subject_file(const std::filesystem::path& file);
// TRACKED/identity.json, saying that `tracked` is no tracking when it is missing.
TrackedSubject read_tracked_subject(const std::filesystem::path& tracked);
// `file` and the neutral mesh beside it (<stem>_neutral.obj), each atomically.
void write_tracked_subject(const TrackedSubject& subject, const std::filesystem::path& file);

// One frame's record, TRACKED/<take>/<frame:06d>.json. Throws tega::Error
// naming the file when it is damaged.
TrackedFrame read_tracked_frame(const std::filesystem::path& record);
// The record's file and the mesh file of `frame` in a take's folder.
std::filesystem::path tracked_frame_file(const std::filesystem::path& take_dir, int frame, const char* extension);
// The frame's mesh (when given: <frame>.bin, which the record then names)
// first and its record last, each atomically: a frame with a record is whole.
void write_tracked_frame(const std::filesystem::path& take_dir, const TrackedFrame& frame, const Vertices* mesh);

// Every frame of TRACKED/<take>/ that has a record, in frame order. Throws
// tega::Error naming the file when the take was not tracked to its end
// (no track.json) or a record is damaged.
std::vector<TrackedFrame> read_tracked_take(const std::filesystem::path& tracked, const std::string& take);

}  // namespace tega
