#pragma once
// Skin gloss that follows the expression: a factor on the skin's specular
// strength and Blinn-Phong exponent together (a normalised lobe's peak grows
// with its exponent, so a glossier surface gives a brighter, tighter
// highlight and a more matte one a dimmer, broader one). Per fine vertex:
//
//   gloss = area_ratio^stretch_exponent * crease_shading^crease_matte
//           * (1 + wet_lips * lips * jawOpen),  clamped to [0.1, 10]
//
// area_ratio: the coarse mesh's area around the vertex against the neutral
// pose's (rigid motion leaves it 1). Stretched skin flattens its fine relief
// and shines more; compressed skin, and the bottom of a crease above all,
// bunches up and turns matte; the lips are wet once the mouth opens.
// docs/virtual-studio.md#expression-dependent-appearance

#include <vector>

#include "tega/synth/fine_mesh.h"
#include "tega/synth/options.h"

namespace tega::synth {

class SkinGloss {
 public:
  SkinGloss(const Head& head, const FineMeshMaker& maker, const ExpressionSpecularOptions& options);

  // `coarse`: the frame's coarse mesh (any rigid frame), `expression`: its
  // coefficients, `fine`: the fine mesh made from them. Empty when the
  // options are all off.
  std::vector<float> per_vertex(const Vertices& coarse, const std::vector<float>& expression,
                                const FineFrame& fine) const;

 private:
  // Per coarse vertex: the area of its skin (non-eyeball) triangles, divided by 3.
  std::vector<double> skin_area(const Vertices& coarse) const;

  const Head& head_;
  const FineMeshMaker& maker_;
  ExpressionSpecularOptions options_;
  std::vector<double> neutral_area_;  // per coarse vertex
  std::vector<float> lips_;           // lip_weight per fine vertex
  int jaw_open_ = -1;                 // expression index; -1: the model has none
};

}  // namespace tega::synth
