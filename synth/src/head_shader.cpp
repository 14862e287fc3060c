#include "head_shader.h"

#include "lighting.h"

namespace tega::synth {

HeadShader::HeadShader(const Head& head, const FineMeshMaker& maker, const Appearance& appearance,
                       const SelfShadowOptions& shadows, const ExpressionSpecularOptions& specular)
    : maker_(maker), appearance_(appearance), shadows_(shadows), gloss_(head, maker, specular) {
  const Mesh& fine = maker.fine_topology();
  for (int v = 0; v < fine.num_vertices(); ++v) {
    const Eigen::Vector3d p = fine.positions.row(v).cast<double>().transpose();
    face_points_.push_back(head.frame.to_face(p).cast<float>());
    const Eigen::Vector3d& eye =
        (p - head.frame.eye_left).norm() < (p - head.frame.eye_right).norm() ? head.frame.eye_left : head.frame.eye_right;
    eye_directions_.push_back((head.frame.axes.transpose() * (p - eye)).normalized().cast<float>());
  }
}

FrameLighting HeadShader::frame_lighting(const Vertices& coarse, const std::vector<float>& expression,
                                         const FineFrame& frame) const {
  FrameLighting lighting;
  if (shadows_.enabled)
    for (int light = 0; light < kStudioLights; ++light)
      lighting.shadows.emplace_back(frame.positions, maker_.fine_topology().faces, studio_light_direction(light),
                                    shadows_.map_size, shadows_.softness_m);
  lighting.gloss = gloss_.per_vertex(coarse, expression, frame);
  return lighting;
}

Surface HeadShader::surface(const FineFrame& frame, const FrameLighting& lighting) const {
  const Mesh& fine = maker_.fine_topology();
  Surface s;
  s.positions = &frame.positions;
  s.normals = &frame.normals;
  s.faces = &fine.faces;
  s.uvs = fine.has_uvs() ? &fine.uvs : nullptr;
  s.uv_faces = fine.has_uvs() ? &fine.uv_faces : nullptr;
  s.shade = [this, &frame, &fine, &lighting](const SurfaceSample& x) -> Eigen::Vector3f {
    Eigen::Vector3f point = Eigen::Vector3f::Zero();
    const bool eye = maker_.fine_triangle_eye()[x.triangle] != 0;
    const bool glossy = !lighting.gloss.empty();
    float shading = 0, gloss = glossy ? 0.0f : 1.0f;
    for (int k = 0; k < 3; ++k) {
      const int v = fine.faces(x.triangle, k);
      point += x.barycentric[k] * (eye ? eye_directions_[v] : face_points_[v]);
      shading += x.barycentric[k] * frame.shading[v];
      if (glossy) gloss += x.barycentric[k] * lighting.gloss[v];
    }
    std::array<float, kStudioLights> visibility;
    const bool shadowed = !lighting.shadows.empty();
    // A light behind the surface neither lights nor shadows it.
    if (shadowed)
      for (int light = 0; light < kStudioLights; ++light)
        visibility[light] = x.normal.dot(studio_light_direction(light)) > 0
                                ? lighting.shadows[light].visibility(x.position, x.normal)
                                : 0.0f;
    const std::array<float, kStudioLights>* shadow = shadowed ? &visibility : nullptr;
    if (eye) return lit(appearance_.eye(point.normalized()), x.normal, x.to_camera, 0.5f, 60.0f, shadow);
    return lit(appearance_.skin(x.uv, point) * shading, x.normal, x.to_camera, 0.06f * gloss, 20.0f * gloss, shadow);
  };
  return s;
}

}  // namespace tega::synth
