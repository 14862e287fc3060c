#pragma once
// Depth-map fusion: every estimated pixel that enough other views confirm
// (depth, reprojection and normal agree) becomes a point, averaged with its
// confirmations; points are then merged per voxel. The result is an oriented,
// coloured cloud in world space.

#include <vector>

#include "tega/mvs/depth_map.h"
#include "tega/mvs/patch_match.h"
#include "tega/mvs/point_cloud.h"

namespace tega {
class ThreadPool;
}

namespace tega::mvs {

struct FusionOptions {
  int min_consistent_views = 2;       // other views that must confirm a pixel
  float max_depth_error = 0.005f;     // relative depth difference
  float max_reprojection_px = 1.0f;   // forward-backward reprojection in the reference view
  float max_normal_angle_deg = 25.0f;
  double voxel_size_m = 0.0004;       // points within one voxel merge (0: no merging)
  int pixel_step = 1;                 // fuse every pixel_step-th pixel of every pixel_step-th row

  template <class V>
  void visit(V& v) {
    v("min_consistent_views", min_consistent_views, "Other views that must confirm a pixel's depth for it to be kept.");
    v("max_depth_error", max_depth_error, "Largest relative depth difference of a confirmation.");
    v("max_reprojection_px", max_reprojection_px, "Largest forward-backward reprojection error of a confirmation, pixels.");
    v("max_normal_angle_deg", max_normal_angle_deg, "Largest angle between the normals of a confirmation, degrees.");
    v("voxel_size_m", voxel_size_m, "Points within one voxel of this size merge into one (0: keep all), metres.");
    v("pixel_step", pixel_step,
      "Fuse every pixel_step-th pixel and row: at high resolution several pixels fall in one voxel anyway.");
  }
};

// `maps[k]` is the estimate of view `map_views[k]`. Colours come from each
// view's `colour` image where present (RGB, 8-bit), else from its grey image.
// The pixels are fused on `device` (the CPU's `pool`, nullptr: a pool of its
// own; or the GPU, the same points in the same order), the voxels merged on
// the CPU. Device::cuda throws tega::Error without CUDA or a usable GPU.
OrientedPointCloud fuse_depth_maps(const std::vector<StereoView>& views, const std::vector<int>& map_views,
                                   const std::vector<DepthMap>& maps, const FusionOptions& options,
                                   ThreadPool* pool = nullptr, Device device = Device::cpu);

}  // namespace tega::mvs
