#pragma once
// COLMAP's dense workspace (the output of `colmap image_undistorter` and the
// input and output of `patch_match_stereo`, `stereo_fusion`,
// `poisson_mesher`), so that users can run COLMAP's dense tools on tega's
// depth maps and tega's fusion and meshing on COLMAP's:
//
//   WORKSPACE/
//     images/<camera>.png                  undistorted images
//     sparse/cameras.txt, images.txt, points3D.txt   the undistorted (PINHOLE) rig
//     stereo/depth_maps/<camera>.png.<type>.bin      depth, float32 (type: photometric | geometric)
//     stereo/normal_maps/<camera>.png.<type>.bin     normals, float32 x 3
//     stereo/patch-match.cfg, stereo/fusion.cfg      the source views of each view
//     fused.ply                            the fused oriented, coloured point cloud
//
// COLMAP's array files are a text header "width&height&channels&" followed by
// float32 values, channel after channel (planar), each row-major.

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "tega/core/image.h"
#include "tega/core/rig.h"
#include "tega/mvs/depth_map.h"
#include "tega/mvs/point_cloud.h"

namespace tega::mvs {

struct DenseWorkspace {
  Rig rig;                                  // undistorted cameras (zero distortion)
  std::map<std::string, Image8> images;     // camera -> undistorted RGB image
  std::map<std::string, DepthMap> depth_maps;  // camera -> depth + normals (cost not stored)
  std::map<std::string, std::vector<std::string>> source_views;  // camera -> its source views
  std::optional<OrientedPointCloud> fused;
};

// Writes (atomically, file by file) what `workspace` holds. `type` names the
// depth maps: "geometric" (the default, as COLMAP's fusion reads them) or
// "photometric".
void write_dense_workspace(const DenseWorkspace& workspace, const std::filesystem::path& directory,
                           const std::string& type = "geometric");
// Reads a workspace written by tega or by COLMAP: the sparse model, the
// images, and the depth/normal maps of `type` where present (views without
// them are left out of depth_maps). Throws tega::Error naming the file.
DenseWorkspace read_dense_workspace(const std::filesystem::path& directory, const std::string& type = "geometric");

// One COLMAP array file.
void write_colmap_array(const std::filesystem::path& file, int width, int height, int channels,
                        const std::vector<float>& interleaved);  // atomic
std::vector<float> read_colmap_array(const std::filesystem::path& file, int& width, int& height, int& channels);

// fused.ply: binary little-endian x y z nx ny nz (float) red green blue (uchar), COLMAP's layout.
void write_point_cloud_ply(const OrientedPointCloud& cloud, const std::filesystem::path& file);  // atomic
OrientedPointCloud read_point_cloud_ply(const std::filesystem::path& file);

}  // namespace tega::mvs
