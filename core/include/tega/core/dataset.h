#pragma once
// A subject dataset in tega's native layout: what the avatar trainer reads.
// `tega synth` and `tega ingest multiface` write it; docs/layouts.md#dataset
// documents it:
//
//   DATASET/
//     dataset.json                 this manifest (frames, split, paths)
//     rig.json                     the rig (tega rig file, metres)
//     template.obj                 template topology with UVs, neutral, head space
//     meshes/<frame>.bin           tracked mesh per frame: float32 V x 3, world space
//     images/<camera>/<frame>.png  RGBA, 8-bit, alpha = matte, the camera's size,
//                                  undistorted (the rig's cameras have no distortion)

#include <filesystem>
#include <string>
#include <vector>

#include "tega/core/geometry.h"
#include "tega/core/mesh.h"
#include "tega/core/rig.h"

namespace tega {

struct DatasetFrame {
  std::string id;                // unique; names the mesh and image files
  std::string sequence;          // expression sequence (take) it was sampled from
  RigidTransform head_to_world;  // rigid head pose of this frame
};

// An image a producer left out: missing from the capture or unreadable. The
// manifest records it (`missing_images`); training, evaluation and
// validation skip it (docs/layouts.md#missing-images).
struct MissingImage {
  std::string camera;
  std::string frame;   // a frame of Dataset::frames
  std::string reason;  // what was wrong, naming the capture's file
};

// A sampled frame left out as a whole: too few of its cameras had a usable
// image (`dropped_frames`). It is in no split and has no files.
struct DroppedFrame {
  std::string frame;
  std::string reason;
};

struct DatasetSplit {
  std::vector<std::string> frames;
  std::vector<std::string> cameras;
};

struct Dataset {
  std::filesystem::path root;
  Rig rig;
  Mesh template_mesh;                      // neutral, head space, with UVs
  std::vector<int32_t> eyeball_faces;      // triangles of template_mesh on the eyeballs
  std::vector<int32_t> landmark_vertices;  // optional (e.g. 68 Multi-PIE landmarks)
  std::vector<DatasetFrame> frames;
  DatasetSplit train, test;  // test: held-out frames and held-out cameras
  std::string image_extension = ".png";  // or ".zst": raw pixels in zstd (image.h)
  std::vector<MissingImage> missing_images;
  std::vector<DroppedFrame> dropped_frames;

  std::filesystem::path mesh_path(const std::string& frame_id) const;
  std::filesystem::path image_path(const std::string& camera, const std::string& frame_id) const;
  // False for an image recorded in missing_images: its file does not exist.
  bool has_image(const std::string& camera, const std::string& frame_id) const;
  const DatasetFrame& frame(const std::string& frame_id) const;  // throws tega::Error
  Vertices load_mesh(const std::string& frame_id) const;          // checks the vertex count
};

// Reads dataset.json, the rig and the template. Throws tega::Error naming the
// file for anything malformed or inconsistent in them (a missing image of an
// unknown frame or camera, or recorded twice; a dropped frame that is in
// `frames`).
Dataset read_dataset(const std::filesystem::path& root);

// Checks everything training relies on before it starts: distortion-free
// cameras (images are undistorted), every split frame
// and camera exists, every image of a split frame x camera exists with the
// camera's size and 4 channels unless missing_images records it, every mesh
// has the template's vertex count. Throws tega::Error naming the first
// offending file.
void validate_dataset(const Dataset& dataset);

// Writes dataset.json, rig.json and template.obj into dataset.root (each
// atomically). Meshes and images are written by the producer beforehand,
// at mesh_path() and image_path().
void write_dataset_manifest(const Dataset& dataset);

// Choosing a dataset's frames and held-out cameras, the same way for every
// producer (tega synth, tega ingest multiface, tega dataset build).

// Indices of `count` of `total` items spread evenly (the middle of each of
// `count` equal parts), ascending; all of them when count is 0 or not
// smaller than total. The paper samples 400 frames this way over a
// subject's takes.
std::vector<size_t> evenly_spaced_indices(size_t total, int count);

// `count` of the rig's cameras spread over its layout rather than bunched
// together (every (n / count)-th, from the last), clamped to 1 .. n - 1, or
// the only camera of a one-camera rig: the held-out views of a test split.
std::vector<std::string> spread_test_cameras(const Rig& rig, int count);

}  // namespace tega
