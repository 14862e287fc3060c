#pragma once
// Adaptive density control of 3D Gaussian Splatting, performed in UVD space
// (TeGA §3.8): thresholds use screen-space gradients and world sizes, while
// clones copy uvd and splits sample children from N(μ_uvd, Σ_uvd). Every new
// uv is projected back onto the valid UV domain (in the triangle and rigged
// bindings children inherit their parent's triangle instead; rigged ones are
// sampled in its local frame, as GaussianAvatars does), and the optimizer's
// moments follow the rows.

#include <ATen/ATen.h>

#include "tega/trainer/adam.h"
#include "tega/trainer/gaussians.h"
#include "tega/trainer/options.h"
#include "tega/uvd/uv_lookup.h"

namespace tega::trainer {

struct DensifyStats {
  at::Tensor gradient_norm_sum;  // [N] Σ |dL/dmean2D| over the views that saw each Gaussian
  at::Tensor visible_count;      // [N] int32: views that saw it
  at::Tensor world_std;          // [N] largest world std at the last step (metres)

  void reset(int64_t n, const at::Device& device);
};

struct DensifyResult {
  int64_t cloned = 0, split = 0, pruned = 0;
};

// One densification: clone small Gaussians with large mean gradients, split
// large ones into two children (std / 1.6), prune transparent and huge ones,
// and never exceed options.max_gaussians (highest gradients win). Leaves the
// Gaussians in gaussian_order for latent textures of side `latent_side`.
DensifyResult densify(Gaussians& gaussians, Adam& adam, const DensifyStats& stats, const DensifyOptions& options,
                      const uvd::UvTriangleLookup& lookup, int64_t latent_side, at::Generator& generator);

// Caps every opacity at 0.01 (3DGS's periodic reset) and clears its moments.
void reset_opacity(Gaussians& gaussians, Adam& adam);

// Keeps every world standard deviation within [min_std, max_std]:
// world std along axis k = exp(log_scale_k) * world_std_per_scale_k.
void clamp_world_size(Gaussians& gaussians, const at::Tensor& world_std_per_scale, double min_std, double max_std);

}  // namespace tega::trainer
