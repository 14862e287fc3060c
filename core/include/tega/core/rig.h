#pragma once
// A calibrated multi-camera rig and its file formats:
//  - our own JSON rig file (docs/layouts.md#rig-file), in metres;
//  - COLMAP text models (cameras.txt + images.txt);
//  - Multiface "KRT" files (translations in millimetres).
// Every reader throws tega::Error naming the file and the problem.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "tega/core/camera.h"

namespace tega {

struct Rig {
  std::vector<Camera> cameras;

  // Throws tega::Error when no camera has this name.
  const Camera& camera(std::string_view name) const;
  bool contains(std::string_view name) const;
  std::vector<std::string> camera_names() const;
};

Rig read_rig_json(const std::filesystem::path& file);
void write_rig_json(const Rig& rig, const std::filesystem::path& file);  // atomic

// COLMAP text model in `directory` (cameras.txt, images.txt, empty points3D.txt).
// Camera model OPENCV when k3 == 0, FULL_OPENCV otherwise; PINHOLE for no
// distortion. `metres_per_unit` converts COLMAP's translations to metres.
Rig read_colmap_text(const std::filesystem::path& directory, double metres_per_unit = 1.0);
void write_colmap_text(const Rig& rig, const std::filesystem::path& directory,
                       double metres_per_unit = 1.0);

// Multiface KRT: per camera 9 lines (name; 3 lines of K; 1 line of 5
// distortion values; 3 lines of [R|t] world->camera, t in millimetres) and a
// blank line. KRT holds no image size, so every camera gets width x height.
Rig read_krt(const std::filesystem::path& file, int width, int height);
void write_krt(const Rig& rig, const std::filesystem::path& file);

}  // namespace tega
