#pragma once
// Shades samples of the fine head mesh: skin albedo at the sample's UV,
// darkened by the crease shading of the wrinkles, or the eye's colour by the
// direction from its eyeball's centre; then the studio lighting, optionally
// shadowed by the head itself and with a skin gloss that follows the
// expression (docs/virtual-studio.md#expression-dependent-appearance).

#include <vector>

#include "tega/synth/appearance.h"
#include "tega/synth/fine_mesh.h"
#include "tega/synth/options.h"
#include "tega/synth/rasterizer.h"
#include "tega/synth/shadow_map.h"
#include "tega/synth/skin_gloss.h"

namespace tega::synth {

// What one frame's expression does to its lighting, shared by every camera.
struct FrameLighting {
  std::vector<ShadowMap> shadows;  // per studio light; empty: no self-shadowing
  std::vector<float> gloss;        // per fine vertex; empty: the skin's constant gloss
};

class HeadShader {
 public:
  HeadShader(const Head& head, const FineMeshMaker& maker, const Appearance& appearance,
             const SelfShadowOptions& shadows, const ExpressionSpecularOptions& specular);
  // The frame's shadow maps and gloss: `coarse` and `expression` made `frame` (all world space).
  FrameLighting frame_lighting(const Vertices& coarse, const std::vector<float>& expression,
                               const FineFrame& frame) const;
  // A surface drawing `frame`; `frame` and `lighting` must outlive it.
  Surface surface(const FineFrame& frame, const FrameLighting& lighting) const;

 private:
  const FineMeshMaker& maker_;
  const Appearance& appearance_;
  SelfShadowOptions shadows_;
  SkinGloss gloss_;
  std::vector<Eigen::Vector3f> face_points_;      // neutral, face frame units
  std::vector<Eigen::Vector3f> eye_directions_;   // neutral, from the eyeball centre, face frame axes
};

}  // namespace tega::synth
