#pragma once
// Which views to match against which, and at what depths: from the rig alone.

#include <optional>
#include <vector>

#include "tega/core/camera.h"

namespace tega::mvs {

// The point nearest to every camera's optical axis (least squares): where a
// studio rig's cameras aim. nullopt when the axes are (near) parallel, as in a
// rectified stereo pair, or it lies behind most cameras.
std::optional<Eigen::Vector3d> rig_focus_point(const std::vector<Camera>& cameras);

// For each camera, up to `count` others ranked by the triangulation angle
// their centres make at `subject` (best near 15 degrees; under 2 or over 60
// degrees never) and by how similarly they face it.
std::vector<std::vector<int>> select_source_views(const std::vector<Camera>& cameras, const Eigen::Vector3d& subject,
                                                  int count);

// Same without a subject point: ranked by the angle between optical axes.
std::vector<std::vector<int>> select_source_views_by_axes(const std::vector<Camera>& cameras, int count);

}  // namespace tega::mvs
