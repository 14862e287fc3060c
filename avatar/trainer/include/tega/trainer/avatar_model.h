#pragma once
// The TeGA avatar: canonical UVD Gaussians, the expression network and the
// template they live on. pose() turns them into world-space Gaussians for one
// frame and camera (§3.3-3.5):
//
//   xyz = F(uvd) + R_head D(uvd; f_uv)          J = J_F + R_head J_D
//   Σ_xyz = (J R_q S)(J R_q S)ᵀ                  colour = SH(view) · S(uvd; f_uv^S)
//
// D is learned in head space and rotated by the frame's head pose, so that a
// rigid head motion does not have to be learned by the field. Eyeball
// Gaussians (by the triangle they map through) are not deformed.
// Rigged Gaussians (the GaussianAvatars baseline) map through their
// triangle's frame instead of F (uvd/triangle_rig.h), with J = k R.

#include <ATen/ATen.h>

#include <Eigen/Core>

#include "tega/core/dataset.h"
#include "tega/nn/expression_network.h"
#include "tega/nn/uv_raster.h"
#include "tega/trainer/checkpoint.h"
#include "tega/trainer/gaussians.h"
#include "tega/trainer/options.h"
#include "tega/uvd/uvd_map.h"

namespace tega::trainer {

// What one frame contributes, computed once per frame and cached.
struct FrameInput {
  uvd::PosedMesh mesh;              // world-space vertices and normals
  at::Tensor head_rotation;         // [3,3] head -> world
  at::Tensor displacement_texture;  // [3,T,T] head-space displacement from the template
};

// Which parts of the model are active at an iteration.
struct Phase {
  bool deformation = false;
  bool shading = false;
  int sh_degree = 0;
};

struct PosedGaussians {
  at::Tensor means;        // [N,3] world
  at::Tensor covariances;  // [N,6] packed xx, xy, xz, yy, yz, zz
  at::Tensor sh;           // [N,(sh_degree+1)²,3] SH coefficients with the shading folded in
  int sh_degree = 0;       // the degree they hold (the rasterizer's setting)
  at::Tensor opacities;    // [N] in (0,1)
  // [N] the dynamic shading S > 0 folded into `sh`, undefined when the phase
  // has no shading; tega serve streams it apart from the static coefficients.
  at::Tensor shading;
  at::Tensor world_std_per_scale;  // [N,3] world std per unit of exp(log_scale) (no grad)
  nn::Latents latents;     // this frame's latents (undefined when the field is off)
  // The longest Δμ applied, as [5] double (no grad): its length (metres), the
  // Gaussian's index, its triangle and its canonical u, v; undefined when the
  // field is off. A run that rolls back names that Gaussian.
  at::Tensor largest_deformation;
};

class AvatarModel {
 public:
  AvatarModel(const Dataset& dataset, const TrainOptions& options, const at::Device& device);

  FrameInput frame_input(const Vertices& world_vertices, const RigidTransform& head_to_world) const;
  PosedGaussians pose(const FrameInput& frame, const Phase& phase);

  Gaussians gaussians;
  nn::ExpressionNetwork network{nullptr};

  // The template's UVs as the Gaussians and the networks use them: the
  // eyeballs laid apart from the face where they share its UV tile, and a
  // multi-tile layout packed into the unit square (uvd/uv_layout.h).
  const Mesh& uv_layout() const { return uv_layout_; }
  const uvd::UvTriangleLookup& lookup() const { return lookup_; }
  double metres_per_uv() const { return metres_per_uv_; }
  // Mean scale k (metres) of the template's active triangles: metres per
  // unit of a rigged Gaussian's local coordinates, on average.
  double mean_triangle_scale() const { return mean_triangle_scale_; }
  const at::Device& device() const { return device_; }

 private:
  at::Device device_;
  Mesh uv_layout_;
  uvd::UvTriangleLookup lookup_;
  at::Tensor eyeball_face_mask_;  // [F] bool; before uv_rasterizer_, which is built from it
  nn::UvRasterizer uv_rasterizer_;
  at::Tensor template_vertices_;  // [V,3] head space
  double metres_per_uv_ = 1.0;
  double mean_triangle_scale_ = 1.0;
};

// sqrt(world area / UV area) of a mesh's triangles: metres per unit of uv.
double metres_per_uv(const Mesh& mesh);

// Throws tega::Error naming `file` when the checkpoint's TeGA Gaussians were
// trained in an earlier layout than model.uv_layout() (no kUvLayoutMetadataKey)
// and that layout differs from the template's own UVs; rigged Gaussians live
// in their triangles' frames and pass.
void check_uv_layout(const Checkpoint& checkpoint, const std::filesystem::path& file, const AvatarModel& model,
                     const Mesh& template_mesh, bool rigged);

}  // namespace tega::trainer
