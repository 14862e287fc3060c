#include "tega/trainer/avatar_model.h"

#include <ATen/core/grad_mode.h>
#include <ATen/record_function.h>

#include <cmath>
#include <numeric>

#include "tega/core/error.h"
#include "tega/trainer/spherical_harmonics.h"
#include "tega/uvd/fused_covariance.h"
#include "tega/uvd/triangle_rig.h"
#include "tega/uvd/uv_layout.h"

namespace tega::trainer {

double metres_per_uv(const Mesh& mesh) {
  std::vector<int32_t> faces(mesh.num_faces());
  std::iota(faces.begin(), faces.end(), 0);
  const uvd::SurfaceAreas areas = uvd::surface_areas(mesh, faces);
  if (areas.uv <= 0) throw Error("the template's UV layout has no area");
  return std::sqrt(areas.world / areas.uv);
}

namespace {

// Names a part of pose() in profiler traces (bench/train --trace); backward
// kernels are attributed to it through their forward op.
#define TEGA_TRACE_SCOPE(name) RECORD_FUNCTION("tega::" name, std::vector<c10::IValue>())

at::Tensor to_tensor(const Vertices& v, const at::Device& device) {
  return at::from_blob(const_cast<float*>(v.data()), {v.rows(), 3}, at::kFloat).to(device, /*non_blocking=*/false,
                                                                                    /*copy=*/true);
}

at::Tensor to_tensor(const Eigen::Matrix3d& m, const at::Device& device) {
  const Eigen::Matrix<float, 3, 3, Eigen::RowMajor> f = m.cast<float>();
  return at::from_blob(const_cast<float*>(f.data()), {3, 3}, at::kFloat).to(device, false, true);
}

// [F] bool on the CPU: the eyeballs' triangles.
at::Tensor eyeball_face_mask(const Dataset& dataset) {
  at::Tensor mask = at::zeros({dataset.template_mesh.num_faces()}, at::TensorOptions(at::kBool));
  auto eyeball = mask.accessor<bool, 1>();
  for (const int32_t f : dataset.eyeball_faces) eyeball[f] = true;  // read_dataset checked the range
  return mask;
}

// The triangles the field moves: all but the eyeballs. The displacement
// texture draws only these, since the rigid eyeballs tell nothing of the
// expression and would take texels from it.
std::vector<int32_t> deformable_faces(const at::Tensor& eyeball_face_mask) {
  const at::Tensor faces = eyeball_face_mask.logical_not().nonzero().view(-1).to(at::kInt).contiguous();
  return {faces.data_ptr<int32_t>(), faces.data_ptr<int32_t>() + faces.numel()};
}

// [length, Gaussian, triangle, u, v] of the longest row of `moves` [N,3].
at::Tensor largest(const at::Tensor& moves, const at::Tensor& triangle, const at::Tensor& uvd) {
  const auto [length, index] = moves.norm(2, 1).max(0);
  const at::Tensor row = index.view({1});
  return at::cat({length.view({1}).to(at::kDouble), row.to(at::kDouble), triangle.index_select(0, row).to(at::kDouble),
                  uvd.index_select(0, row).narrow(1, 0, 2).view({2}).to(at::kDouble)});
}

}  // namespace

AvatarModel::AvatarModel(const Dataset& dataset, const TrainOptions& options, const at::Device& device)
    : device_(device),
      uv_layout_(uvd::packed_in_unit_square(uvd::with_part_laid_apart(dataset.template_mesh, dataset.eyeball_faces))),
      lookup_(uvd::UvTriangleLookup(uv_layout_, options.uv_lookup).to(device)),
      eyeball_face_mask_(eyeball_face_mask(dataset)),
      uv_rasterizer_(nn::UvRasterizer(uv_layout_, options.network.texture_size, deformable_faces(eyeball_face_mask_))
                         .to(device)),
      template_vertices_(to_tensor(dataset.template_mesh.positions, device)),
      metres_per_uv_(trainer::metres_per_uv(uv_layout_)) {
  eyeball_face_mask_ = eyeball_face_mask_.to(device);
  network = nn::ExpressionNetwork(options.network);
  network->to(device);
  const at::Tensor active = lookup_.uv_area() > 0;
  const at::Tensor scale = uvd::triangle_frames(template_vertices_, lookup_.faces()).scale;
  mean_triangle_scale_ = scale.index({active}).mean().item<double>();
}

FrameInput AvatarModel::frame_input(const Vertices& world_vertices, const RigidTransform& head_to_world) const {
  at::NoGradGuard no_grad;
  FrameInput frame;
  const at::Tensor world = to_tensor(world_vertices, device_);
  frame.mesh = uvd::pose(lookup_, world);
  frame.head_rotation = to_tensor(head_to_world.R, device_);
  const at::Tensor translation =
      at::tensor({head_to_world.t.x(), head_to_world.t.y(), head_to_world.t.z()}, at::kFloat).to(device_);
  // Row vectors: R^T (x - t) is (x - t) R.
  const at::Tensor head_space = (world - translation).matmul(frame.head_rotation);
  frame.displacement_texture = uv_rasterizer_.rasterize(head_space - template_vertices_);
  return frame;
}

PosedGaussians AvatarModel::pose(const FrameInput& frame, const Phase& phase) {
  PosedGaussians out;
  const Gaussians& g = gaussians;
  at::Tensor means, jacobian, triangle;
  {
    TEGA_TRACE_SCOPE("uvd_to_world");
    uvd::UvdMapping mapping = g.rigged ? uvd::rigged_to_world(g.uvd, g.bound_triangle, frame.mesh, lookup_.faces())
                                       : uvd::uvd_to_world(g.uvd, frame.mesh, lookup_, g.bound_triangle);
    means = std::move(mapping.xyz);
    jacobian = std::move(mapping.jacobian);
    triangle = std::move(mapping.triangle);
  }

  at::Tensor shading;
  if (phase.deformation || phase.shading) {
    TORCH_CHECK(!g.rigged, "rigged Gaussians have no uvd for the networks");
    {
      TEGA_TRACE_SCOPE("encoder");
      out.latents = network->encode(frame.displacement_texture);
    }
    nn::EncodedPositions encoded;
    {
      TEGA_TRACE_SCOPE("positional_encoding");
      encoded = network->encode_positions(g.uvd, /*with_derivatives=*/phase.deformation);
    }
    if (phase.deformation) {
      TEGA_TRACE_SCOPE("deformation_field");
      const nn::FieldWithJacobian field = network->deform(g.uvd, encoded, out.latents, /*with_jacobian=*/true);
      const at::Tensor movable = eyeball_face_mask_.index_select(0, triangle).logical_not().to(means.dtype());
      // Head space -> world: Δ_world = R Δ, J_world = R J (row vectors: Δ Rᵀ).
      const at::Tensor applied = field.value * movable.unsqueeze(1);
      means = means + applied.matmul(frame.head_rotation.t());
      out.largest_deformation = largest(applied.detach(), triangle, g.uvd.detach());
      // R J_D for every Gaussian as one [3N,3]x[3,3] product: (J_Dᵀ Rᵀ)ᵀ.
      const at::Tensor rotated = field.jacobian.transpose(1, 2).reshape({-1, 3}).matmul(frame.head_rotation.t());
      jacobian = jacobian + rotated.view({-1, 3, 3}).transpose(1, 2) * movable.view({-1, 1, 1});
    }
    if (phase.shading) {
      TEGA_TRACE_SCOPE("shading_field");
      shading = network->shade(g.uvd, encoded, out.latents);
    }
  }

  {
    TEGA_TRACE_SCOPE("covariance");
    uvd::PackedCovariance covariance = uvd::world_covariance_packed(jacobian, g.rotation, g.log_scale);
    out.covariances = std::move(covariance.covariance);
    out.world_std_per_scale = std::move(covariance.std_per_scale);
  }
  out.means = means;

  {
    TEGA_TRACE_SCOPE("colors");
    // The shading multiplier S > 0 folds into the SH coefficients (shaded_sh),
    // since S·max(c, 0) = max(S·c, 0). The rasterizer then evaluates the
    // colour per view, with no [N,3] colour pass here.
    const int used = sh_coefficients(phase.sh_degree);
    if (shading.defined()) {
      out.sh = shaded_sh(g.sh_dc, g.sh_rest, shading, used);
      out.shading = shading;
    } else {
      out.sh = used > 1 ? at::cat({g.sh_dc, g.sh_rest.narrow(1, 0, used - 1)}, 1) : g.sh_dc;
    }
    out.sh_degree = phase.sh_degree;
    out.opacities = at::sigmoid(g.opacity_logit);
  }
  return out;
}

void check_uv_layout(const Checkpoint& checkpoint, const std::filesystem::path& file, const AvatarModel& model,
                     const Mesh& template_mesh, bool rigged) {
  const Mesh& layout = model.uv_layout();
  // Eigen's == needs equal sizes; laying a part apart appends UV entries.
  const bool as_the_template = layout.uvs.rows() == template_mesh.uvs.rows() &&
                               layout.uv_faces.rows() == template_mesh.uv_faces.rows() &&
                               layout.uvs == template_mesh.uvs && layout.uv_faces == template_mesh.uv_faces;
  if (rigged || as_the_template || checkpoint.metadata.count(kUvLayoutMetadataKey)) return;
  throw Error(file,
              "was trained in an earlier UV layout of this template (before its overlapping charts were laid apart "
              "one by one and its UV tiles packed into the unit square), where its Gaussians' uv name other points "
              "of the head: retrain the run (docs/uvd-rigging.md#multi-tile-layouts-packed-into-the-unit-square)");
}

}  // namespace tega::trainer
