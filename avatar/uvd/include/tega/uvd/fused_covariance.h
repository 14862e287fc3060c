#pragma once
// World covariances of the optimised uvd Gaussians as one fused op (forward
// and backward: CPU loops in float and double, CUDA kernels), equal to the
// composition of covariance.h's tensor ops
//   M = J · rotation_from_quaternion(q) · diag(exp(log_scale)),  pack_symmetric(M Mᵀ)
// without its dozens of [N,3,3] intermediates (docs/uvd-rigging.md#performance).

#include <ATen/core/Tensor.h>

namespace tega::uvd {

struct PackedCovariance {
  at::Tensor covariance;     // [N,6] xx, xy, xz, yy, yz, zz
  at::Tensor std_per_scale;  // [N,3] |column k of J R|: world std per unit of exp(log_scale_k); no gradient
};

// jacobian [N,3,3] (J_F: ∂xyz/∂uvd), quaternion [N,4] (w, x, y, z; normalised
// here), log_scale [N,3], all of one dtype and device. Differentiable w.r.t.
// all three.
PackedCovariance world_covariance_packed(const at::Tensor& jacobian, const at::Tensor& quaternion,
                                         const at::Tensor& log_scale);

}  // namespace tega::uvd
