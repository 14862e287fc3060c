#include "tega/tools/landmarks.h"
#include <ATen/core/grad_mode.h>

#include <cmath>
#include <limits>

#include "tega/core/error.h"
#include "tega/uvd/uvd_map.h"

namespace tega::tools {

LandmarkProbe::LandmarkProbe(const Dataset& dataset, const trainer::AvatarModel& model)
    : vertices_(dataset.landmark_vertices) {
  const Mesh& mesh = model.uv_layout();
  const at::Device device = model.device();
  at::Tensor uvd = at::zeros({static_cast<int64_t>(vertices_.size()), 3}, at::kFloat);
  for (size_t l = 0; l < vertices_.size(); ++l) {
    const int32_t vertex = vertices_[l];
    if (vertex < 0 || vertex >= mesh.num_vertices())
      throw Error(dataset.root / "dataset.json", "landmark vertex " + std::to_string(vertex) + " is out of range");
    // A seam vertex has several uvs; each maps to the same point at d = 0.
    bool found = false;
    for (int f = 0; f < mesh.num_faces() && !found && mesh.has_uvs(); ++f)
      for (int k = 0; k < 3 && !found; ++k)
        if (mesh.faces(f, k) == vertex) {
          uvd[l][0] = mesh.uvs(mesh.uv_faces(f, k), 0);
          uvd[l][1] = mesh.uvs(mesh.uv_faces(f, k), 1);
          found = true;
        }
    if (!found)
      throw Error(dataset.root / "dataset.json", "landmark vertex " + std::to_string(vertex) + " has no uv");
  }
  uvd_ = uvd.to(device);
  eyeball_ = at::zeros({mesh.num_faces()}, at::kBool);
  for (int32_t f : dataset.eyeball_faces) eyeball_[f] = true;
  eyeball_ = eyeball_.to(device);
}

at::Tensor LandmarkProbe::reference(const Vertices& world_vertices) const {
  at::Tensor out = at::empty({static_cast<int64_t>(vertices_.size()), 3}, at::kDouble);
  for (size_t l = 0; l < vertices_.size(); ++l)
    for (int k = 0; k < 3; ++k) out[l][k] = static_cast<double>(world_vertices(vertices_[l], k));
  return out;
}

at::Tensor LandmarkProbe::avatar(trainer::AvatarModel& model, const trainer::FrameInput& frame,
                                 const trainer::Phase& phase) const {
  at::NoGradGuard no_grad;
  const uvd::UvdMapping mapping = uvd::uvd_to_world(uvd_, frame.mesh, model.lookup());
  at::Tensor points = mapping.xyz;
  if (phase.deformation) {
    const nn::Latents latents = model.network->encode(frame.displacement_texture);
    const nn::FieldWithJacobian field = model.network->deform(uvd_, latents, /*with_jacobian=*/false);
    const at::Tensor movable = eyeball_.index_select(0, mapping.triangle).logical_not().to(points.dtype());
    points = points + field.value.matmul(frame.head_rotation.t()) * movable.unsqueeze(1);
  }
  return points.to(at::kCPU, at::kDouble);
}

double landmark_drift_px(const at::Tensor& reference, const at::Tensor& avatar, const Camera& camera) {
  const std::vector<std::optional<Eigen::Vector2d>> a = project_landmarks(reference, camera),
                                                    b = project_landmarks(avatar, camera);
  double sum = 0;
  int64_t count = 0;
  for (size_t l = 0; l < a.size(); ++l) {
    if (!a[l] || !b[l]) continue;
    sum += (*a[l] - *b[l]).norm();
    ++count;
  }
  return count > 0 ? sum / count : std::numeric_limits<double>::quiet_NaN();
}

std::vector<std::optional<Eigen::Vector2d>> project_landmarks(const at::Tensor& points, const Camera& camera) {
  const at::Tensor p = points.to(at::kCPU, at::kDouble).contiguous();
  const double* xyz = p.data_ptr<double>();
  std::vector<std::optional<Eigen::Vector2d>> pixels;
  for (int64_t l = 0; l < p.size(0); ++l)
    pixels.push_back(camera.project(Eigen::Map<const Eigen::Vector3d>(xyz + 3 * l)));
  return pixels;
}

}  // namespace tega::tools
