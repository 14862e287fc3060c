#pragma once
// The studio's lights: an ambient term plus three soft directional lights
// (key, fill, top) fixed in the world, so shading changes as the head turns.
// Wrapped diffuse (softer than Lambert, as from large area lights) and a
// little Blinn-Phong specular from the key light.

#include <Eigen/Core>
#include <array>

namespace tega::synth {

constexpr int kStudioLights = 3;  // key, fill, top

// Unit vector towards studio light `light` (0 = key), world space.
Eigen::Vector3f studio_light_direction(int light);

// `visibility`: per light, the fraction of it that reaches the point (1 = no
// shadow), or null for an unshadowed studio. A shadow takes the light's
// Lambert part and its specular; the light that wrapped diffuse adds past
// the terminator is not shadowed (it stands for the lights' extent and the
// skin's scattering), so a shadow's edge at the terminator leaves no seam.
Eigen::Vector3f lit(const Eigen::Vector3f& albedo, const Eigen::Vector3f& normal, const Eigen::Vector3f& to_camera,
                    float specular, float shininess, const std::array<float, kStudioLights>* visibility = nullptr);

}  // namespace tega::synth
