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
//
// Pixel positions: COLMAP's MVS (patch_match_stereo, stereo_fusion) puts
// depth-map pixel (col, row) on the ray through image coordinate (col, row) of
// its own convention, whose pixel centres sit at +0.5: half a pixel up and
// left of the pixel's centre. tega's maps hold the ray through the centre.
// Maps are stored as they are, so the two differ by that half pixel (about
// 0.5 mm at 2 m from a 1000-pixel focal length), as COLMAP's maps do from its
// own images.
//
// sparse/points3D.txt holds tie points derived from the depth maps (pixels
// on a coarse grid of each view that other views see at a consistent depth):
// COLMAP's stereo_fusion only fuses views that share sparse points.
// read_dense_workspace reads text models only (COLMAP's image_undistorter
// writes binary ones: `colmap model_converter --output_type TXT`). Views are
// named by their image file without its extension (colmap_camera_name);
// depth maps read from COLMAP have cost 0 where they have a depth (COLMAP
// stores no cost; its geometric maps are already filtered).

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

// fused.ply: binary little-endian x y z nx ny nz (float) red green blue (uchar),
// COLMAP's layout (a cloud without colours is written black). The reader
// takes any binary little-endian PLY whose first element is the vertices.
void write_point_cloud_ply(const OrientedPointCloud& cloud, const std::filesystem::path& file);  // atomic
OrientedPointCloud read_point_cloud_ply(const std::filesystem::path& file);

}  // namespace tega::mvs
