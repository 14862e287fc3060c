#pragma once
// COLMAP's stereo_fusion fuses a view only with the views that share sparse
// points with it (Model::GetMaxOverlappingImages). A workspace written from
// depth maps has no sparse model, so its points come from the depth maps:
// pixels on a coarse grid of each view, seen consistently by other views.

#include <map>
#include <string>
#include <vector>

#include "tega/core/rig.h"
#include "tega/mvs/depth_map.h"

namespace tega::mvs {

// `rig`'s cameras are undistorted; depth maps may be smaller than their camera.
std::vector<ColmapPoint> tie_points_from_depth_maps(const Rig& rig, const std::map<std::string, DepthMap>& depth_maps);

}  // namespace tega::mvs
