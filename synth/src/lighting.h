#pragma once
// The studio's lights: an ambient term plus three soft directional lights
// (key, fill, top) fixed in the world, so shading changes as the head turns.
// Wrapped diffuse (softer than Lambert, as from large area lights) and a
// little Blinn-Phong specular from the key light.

#include <Eigen/Core>

namespace tega::synth {

Eigen::Vector3f lit(const Eigen::Vector3f& albedo, const Eigen::Vector3f& normal, const Eigen::Vector3f& to_camera,
                    float specular, float shininess);

}  // namespace tega::synth
