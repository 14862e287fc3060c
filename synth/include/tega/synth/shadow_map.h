#pragma once
// A shadow map of a mesh from a directional light, for self-shadowing: the
// depth of the mesh's light-facing surface as the light sees it, rendered by
// the studio's rasterizer (render_depth) through a pinhole camera far out
// along the light's direction, framing the mesh's bounding sphere. From 50 m
// the rays across a head differ from parallel by under 0.3 degrees.
//
// visibility() filters the map to a soft edge (percentage-closer filtering:
// a fixed grid of taps, each a bilinear blend of four depth comparisons) and
// compares every texel against the receiver's tangent plane rather than its
// single depth, so tilted surfaces do not shadow themselves (acne) and the
// constant bias stays at one texel. Everything is deterministic.

#include <Eigen/Core>

#include "tega/core/camera.h"
#include "tega/core/image.h"
#include "tega/core/mesh.h"

namespace tega::synth {

class ShadowMap {
 public:
  // `towards_light`: unit vector towards the light, same space as `positions`.
  // `size`: texels per side; `softness_m`: radius of the filtered edge, metres
  // (at least one texel is used).
  ShadowMap(const Vertices& positions, const Triangles& faces, const Eigen::Vector3f& towards_light, int size,
            double softness_m);

  // Fraction of the light that reaches `point` on a surface with unit
  // `normal` (same space as the mesh), in [0, 1]; 1 off the map.
  float visibility(const Eigen::Vector3f& point, const Eigen::Vector3f& normal) const;

  double texel_m() const { return texel_m_; }

 private:
  Camera camera_;
  ImageF depth_;  // camera z, metres; 0 where the mesh is absent
  Eigen::Matrix3d rotation_;
  Eigen::Vector3d translation_;
  double texel_m_ = 0;     // texel width at the mesh's centre, metres
  int taps_ = 2;           // filter taps along each axis
  double tap_spacing_ = 1;  // texels between neighbouring taps
};

}  // namespace tega::synth
