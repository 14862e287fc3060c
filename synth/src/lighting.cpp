#include "lighting.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace tega::synth {
namespace {

struct Light {
  Eigen::Vector3f direction;  // towards the light, unit
  float intensity;
};

constexpr float kAmbient = 0.28f;
constexpr float kWrap = 0.35f;

const Light kLights[kStudioLights] = {{Eigen::Vector3f(-0.5f, 0.55f, 0.67f).normalized(), 0.6f},
                                      {Eigen::Vector3f(0.75f, 0.1f, 0.65f).normalized(), 0.3f},
                                      {Eigen::Vector3f(0.0f, 1.0f, 0.15f).normalized(), 0.25f}};

}  // namespace

Eigen::Vector3f studio_light_direction(int light) { return kLights[light].direction; }

Eigen::Vector3f lit(const Eigen::Vector3f& albedo, const Eigen::Vector3f& n, const Eigen::Vector3f& to_camera,
                    float specular, float shininess, const std::array<float, kStudioLights>* visibility) {
  float diffuse = kAmbient;
  const Eigen::Vector3f half = (kLights[0].direction + to_camera).normalized();
  const float highlight = specular * std::pow(std::max(0.0f, n.dot(half)), shininess);
  if (!visibility) {
    for (const Light& l : kLights) diffuse += l.intensity * std::max(0.0f, (n.dot(l.direction) + kWrap) / (1 + kWrap));
    return albedo * diffuse + Eigen::Vector3f::Constant(highlight);
  }
  for (int i = 0; i < kStudioLights; ++i) {
    const float cosine = n.dot(kLights[i].direction);
    const float wrapped = std::max(0.0f, (std::min(cosine, 0.0f) + kWrap) / (1 + kWrap));
    const float lambert = std::max(0.0f, cosine) / (1 + kWrap);
    diffuse += kLights[i].intensity * (wrapped + (*visibility)[i] * lambert);
  }
  return albedo * diffuse + Eigen::Vector3f::Constant((*visibility)[0] * highlight);
}

}  // namespace tega::synth
