#pragma once
// The fine mesh the studio renders, made from the coarse (tracked, template
// topology) mesh of a frame: midpoint subdivision with Phong tessellation, so
// the surface is smooth rather than faceted, then displaced into the skin by
// the expression wrinkles. The coarse mesh does not contain the wrinkles;
// that is the dynamic detail a method has to learn.

#include <array>
#include <vector>

#include "tega/synth/head.h"

namespace tega::synth {

// Every fine vertex is a fixed blend of up to three coarse vertices of one
// coarse triangle (weights sum to 1), since subdivision only takes midpoints.
struct Subdivision {
  Mesh fine;  // topology and UVs of the fine mesh; positions at the blend of the neutral
              // mesh; triangle_polygon = the coarse triangle each fine triangle lies in
  std::vector<std::array<int32_t, 3>> source;
  std::vector<std::array<float, 3>> weight;
};

Subdivision subdivide(const Mesh& coarse, int levels);

// Area-weighted unit vertex normals of positions over faces.
Vertices vertex_normals(const Vertices& positions, const Triangles& faces);

struct FineFrame {
  Vertices positions;          // same space as the coarse input
  Vertices normals;            // of the displaced surface (wrinkles shade)
  std::vector<float> shading;  // crease darkening multiplier per vertex, in (0, 1]
};

struct WrinkleSettings {
  int subdivisions = 2;
  double depth_m = 0.0012;
  double darkening = 0.5;
};

class FineMeshMaker {
 public:
  FineMeshMaker(const Head& head, const WrinkleSettings& settings);

  // `coarse`: posed vertices of the head model (any rigid frame: head space or
  // world), `expression`: the model's expression coefficients.
  FineFrame make(const Vertices& coarse, const std::vector<float>& expression) const;

  const Mesh& fine_topology() const { return subdivision_.fine; }
  // How each fine vertex blends the coarse ones.
  const Subdivision& subdivision() const { return subdivision_; }
  // Per fine triangle: 0 skin, 1 left eyeball, 2 right eyeball.
  const std::vector<int8_t>& fine_triangle_eye() const { return fine_triangle_eye_; }
  // The wrinkle regions whose drivers the model has, and how strongly those
  // drivers act in an expression, in [0, 1].
  const std::vector<std::string>& region_names() const { return region_names_; }
  std::vector<double> region_activations(const std::vector<float>& expression) const;

 private:
  struct RegionWeights {
    std::vector<int32_t> drivers;  // expression indices present in the model
    std::vector<int32_t> vertices;
    std::vector<float> depth, darkening;  // window x profile x scales, per listed vertex
  };

  const Head& head_;
  WrinkleSettings settings_;
  Subdivision subdivision_;
  std::vector<int8_t> fine_triangle_eye_;
  std::vector<RegionWeights> regions_;
  std::vector<std::string> region_names_;
};

}  // namespace tega::synth
