#pragma once
// A calibrated multi-camera rig and its file formats (docs/rig-files.md):
//  - our own JSON rig file, in metres;
//  - COLMAP text models (cameras.txt + images.txt);
//  - Multiface "KRT" files (translations in millimetres).
// Every reader throws tega::Error naming the file and the problem; every
// writer writes atomically and refuses a rig that validate() rejects.

#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "tega/core/camera.h"

namespace tega {

struct Rig {
  std::vector<Camera> cameras;

  // Throws tega::Error when no camera has this name.
  const Camera& camera(std::string_view name) const;
  bool contains(std::string_view name) const;
  std::vector<std::string> camera_names() const;

  // Throws tega::Error(source, ...) naming the camera and the field when the
  // rig has no camera or a camera is unusable: an empty name or one with
  // whitespace or a path separator (names are directory names and tokens of
  // the text formats), a duplicate name, a non-positive size or focal length,
  // K not of the form [fx s cx; 0 fy cy; 0 0 1], R not a rotation (to 1e-5),
  // or a non-finite number.
  void validate(const std::filesystem::path& source) const;
};

Rig read_rig_json(const std::filesystem::path& file);
void write_rig_json(const Rig& rig, const std::filesystem::path& file);

// The rigid motion (no scale: a calibration's scale is metric, and an error
// in it is an error) that best carries the centres of `from`'s cameras onto
// those of the same-named cameras of `to`, in least squares. A calibrated
// rig's world is its own choice; this removes that choice before comparing
// what was reconstructed in it with the truth. Throws tega::Error unless at
// least 3 cameras are shared and their centres span a plane.
RigidTransform align_camera_centres(const Rig& from, const Rig& to);

// A point of a COLMAP sparse model. COLMAP's dense tools (stereo_fusion) find
// the views that overlap from the points they share.
struct ColmapPoint {
  Eigen::Vector3d position;                                    // metres
  std::vector<std::pair<int, Eigen::Vector2d>> observations;  // (camera index in the rig, pixel)
};

// COLMAP text model in `directory` (cameras.txt, images.txt, points3D.txt).
// Camera model PINHOLE for no distortion, OPENCV when k3 == 0, FULL_OPENCV
// otherwise; the reader also takes SIMPLE_PINHOLE, SIMPLE_RADIAL and RADIAL.
// An image's NAME is the camera's name followed by `image_name_suffix` (COLMAP
// names images by their file, e.g. "cam00.png"); the reader names each camera
// by colmap_camera_name(NAME). `metres_per_unit` converts COLMAP's
// translations to metres. The reader ignores the sparse points. The writer
// creates `directory` and replaces each of the three files atomically.
Rig read_colmap_text(const std::filesystem::path& directory, double metres_per_unit = 1.0);
void write_colmap_text(const Rig& rig, const std::filesystem::path& directory,
                       double metres_per_unit = 1.0, std::string_view image_name_suffix = "",
                       const std::vector<ColmapPoint>& points = {});
// An image NAME without its image file extension (.png, .jpg, .jpeg, .tif,
// .tiff, .exr, .bmp, any case): "cam00.png" -> "cam00"; other names unchanged.
std::string colmap_camera_name(std::string_view image_name);

// Multiface KRT: per camera 9 lines (name; 3 lines of K; 1 line of 5
// distortion values; 3 lines of [R|t] world->camera, t in millimetres) and a
// blank line. KRT holds no image size, so every camera gets width x height.
Rig read_krt(const std::filesystem::path& file, int width, int height);
void write_krt(const Rig& rig, const std::filesystem::path& file);

}  // namespace tega
