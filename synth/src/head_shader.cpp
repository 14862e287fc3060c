#include "head_shader.h"

#include "lighting.h"

namespace tega::synth {

HeadShader::HeadShader(const Head& head, const FineMeshMaker& maker, const Appearance& appearance)
    : maker_(maker), appearance_(appearance) {
  const Mesh& fine = maker.fine_topology();
  for (int v = 0; v < fine.num_vertices(); ++v) {
    const Eigen::Vector3d p = fine.positions.row(v).cast<double>().transpose();
    face_points_.push_back(head.frame.to_face(p).cast<float>());
    const Eigen::Vector3d& eye =
        (p - head.frame.eye_left).norm() < (p - head.frame.eye_right).norm() ? head.frame.eye_left : head.frame.eye_right;
    eye_directions_.push_back((head.frame.axes.transpose() * (p - eye)).normalized().cast<float>());
  }
}

Surface HeadShader::surface(const FineFrame& frame) const {
  const Mesh& fine = maker_.fine_topology();
  Surface s;
  s.positions = &frame.positions;
  s.normals = &frame.normals;
  s.faces = &fine.faces;
  s.uvs = fine.has_uvs() ? &fine.uvs : nullptr;
  s.uv_faces = fine.has_uvs() ? &fine.uv_faces : nullptr;
  s.shade = [this, &frame, &fine](const SurfaceSample& x) -> Eigen::Vector3f {
    Eigen::Vector3f point = Eigen::Vector3f::Zero();
    float shading = 0;
    const bool eye = maker_.fine_triangle_eye()[x.triangle] != 0;
    for (int k = 0; k < 3; ++k) {
      const int v = fine.faces(x.triangle, k);
      point += x.barycentric[k] * (eye ? eye_directions_[v] : face_points_[v]);
      shading += x.barycentric[k] * frame.shading[v];
    }
    if (eye) return lit(appearance_.eye(point.normalized()), x.normal, x.to_camera, 0.5f, 60.0f);
    return lit(appearance_.skin(x.uv, point) * shading, x.normal, x.to_camera, 0.06f, 20.0f);
  };
  return s;
}

}  // namespace tega::synth
