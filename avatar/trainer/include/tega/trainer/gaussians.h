#pragma once
// The canonical Gaussians of TeGA (§3.3), living in the template's UVD space:
// (u, v) on the UV layout, d metres along the interpolated normal. Their
// shape Σ_uvd = R diag(s)² Rᵀ is in uvd units too, so it follows the mesh
// through J Σ_uvd Jᵀ.

#include <ATen/ATen.h>

#include <map>
#include <string>

#include "tega/uvd/uv_lookup.h"

namespace tega::trainer {

struct Gaussians {
  // Optimised leaves (requires_grad), one row per Gaussian.
  at::Tensor uvd;            // [N,3]
  at::Tensor log_scale;      // [N,3] log std along the rotated uvd axes
  at::Tensor rotation;       // [N,4] quaternion (w, x, y, z), unnormalised
  at::Tensor sh_dc;          // [N,1,3]
  at::Tensor sh_rest;        // [N,15,3]
  at::Tensor opacity_logit;  // [N]
  // GaussianAvatars-style binding (ablation): the triangle each Gaussian is
  // bound to, [N] int64; undefined in TeGA's free UVD mode.
  at::Tensor bound_triangle;
  // TeGA's free UVD mode only: the triangle each Gaussian was created on
  // (initialisation or densification), [N] int64, so that how many have
  // since moved onto another triangle can be counted (tega inspect);
  // undefined in the bound modes and in checkpoints from before it existed.
  at::Tensor birth_triangle;
  // GaussianAvatars' rigging (binding: rigged, uvd/triangle_rig.h): `uvd`
  // then holds each Gaussian's local position μ in its bound triangle's
  // frame, and log_scale its local scale, both in units of the triangle's k.
  bool rigged = false;

  int64_t size() const { return uvd.size(0); }

  // The parameters by name, as the optimizer and checkpoints see them.
  static const std::vector<std::string>& parameter_names();
  at::Tensor& parameter(const std::string& name);
  std::map<std::string, at::Tensor> tensors() const;  // parameters + bound_triangle, birth_triangle if any
};

// `count` Gaussians spread uniformly over the valid UV area at d = 0, grey,
// opacity 0.1, isotropic with a world std equal to their mean spacing, in
// uv_order for latent textures of side `latent_side`. `metres_per_uv`
// converts uv lengths to metres on the template.
Gaussians initialise_gaussians(const uvd::UvTriangleLookup& lookup, int64_t count, double metres_per_uv,
                               bool bind_to_triangles, int64_t latent_side, uint64_t seed,
                               const at::TensorOptions& options);

// GaussianAvatars' initialisation: one Gaussian at the centroid of every
// active triangle (nonzero UV area), isotropic with a local std of half the
// triangle's scale k, grey, opacity 0.1, rigged.
Gaussians initialise_rigged_gaussians(const uvd::UvTriangleLookup& lookup, const at::TensorOptions& options);

// The memory order the densifier keeps: uv_order for UVD Gaussians, by bound
// triangle (stable) for rigged ones, whose uvd holds no uv.
at::Tensor gaussian_order(const Gaussians& g, int64_t latent_side);

// The permutation that sorts Gaussians (uv or uvd rows) by the four texels
// they read on a latent texture of side `latent_side` (sample_latent's
// bilinear taps, encoders.h; keyed by the top-left one, rows from the top,
// stable). Gaussians that read the same texels then sit together in memory:
// the latent sampling's backward sums their gradients and adds them to the
// latent's once per run of them, and the per-Gaussian gathers (mesh corners,
// texels) hit cached lines. Unsorted, that backward took ~18 ms per field at
// 4M Gaussians on an H100. Sorted by uv cells half a texel off the taps, it
// still added 3.0 of a Gaussian's 4 taps; in this order 0.13
// (docs/networks-and-losses.md).
at::Tensor uv_order(const at::Tensor& uv, int64_t latent_side);

// Rebuilds from checkpoint tensors; throws tega::Error naming what is missing
// or a triangle index outside [0, triangles) (the template's triangle count).
// `rigged`: the run's binding is rigged (its checkpoint then holds bound_triangle).
Gaussians gaussians_from_tensors(const std::map<std::string, at::Tensor>& tensors, const at::Device& device,
                                 bool rigged, int64_t triangles);

}  // namespace tega::trainer
