#pragma once
// Procedural appearance of the head: the skin albedo as a function of UV
// (with detail far finer than a texture at the tracked mesh's resolution
// could hold: pores, freckles, stubble and eyebrow hairs) and the eyes'
// colours. Everything is a pure function of its inputs and the seed.

#include <Eigen/Core>
#include <cstdint>

namespace tega::synth {

// How much a point of the neutral face (face frame, interocular units) is
// lip: 1 at the mouth's centre, falling off as a Gaussian.
float lip_weight(const Eigen::Vector3f& face_point);

class Appearance {
 public:
  explicit Appearance(uint64_t seed);

  // `uv`: texture coordinates; `face_point`: the neutral position in the face
  // frame (interocular units), which places the regions (lips, brows, beard).
  Eigen::Vector3f skin(const Eigen::Vector2f& uv, const Eigen::Vector3f& face_point) const;
  // `direction`: unit vector from the eyeball's centre, head space; +z looks ahead.
  Eigen::Vector3f eye(const Eigen::Vector3f& direction) const;

 private:
  uint64_t seed_;
  Eigen::Vector3f skin_tone_, iris_;
};

}  // namespace tega::synth
