#pragma once
// World covariances of uvd Gaussians: Σ_xyz = J_F Σ_uvd J_Fᵀ (TeGA eq. 2).
// Σ_uvd comes either as scale + rotation (the optimised parameters; the
// product is then formed as (J R S)(J R S)ᵀ, symmetric PSD by construction)
// or as a full matrix / its 6 unique entries. All differentiable tensor ops.
// Packed symmetric order: xx, xy, xz, yy, yz, zz.

#include <ATen/ATen.h>

namespace tega::uvd {

// Unit quaternions [N,4] as (w, x, y, z), normalised here -> rotations [N,3,3].
at::Tensor rotation_from_quaternion(const at::Tensor& quaternion);
// R diag(scale)² Rᵀ from scale [N,3] (standard deviations along the axes) and quaternion [N,4].
at::Tensor covariance_from_scale_rotation(const at::Tensor& scale, const at::Tensor& quaternion);

// jacobian [N,3,3]; covariance_uvd [N,3,3] (symmetric) -> [N,3,3], exactly symmetric.
at::Tensor world_covariance(const at::Tensor& jacobian, const at::Tensor& covariance_uvd);
// jacobian [N,3,3]; scale [N,3], quaternion [N,4] -> [N,3,3], symmetric PSD.
at::Tensor world_covariance(const at::Tensor& jacobian, const at::Tensor& scale, const at::Tensor& quaternion);

at::Tensor pack_symmetric(const at::Tensor& matrix);    // [N,3,3] -> [N,6]
at::Tensor unpack_symmetric(const at::Tensor& packed);  // [N,6] -> [N,3,3]

// a [N,i,k] · b [N,k,j] -> [N,i,j] for millions of tiny matrices, as a
// broadcast product and a sum: a batched GEMM (bmm) spends a whole tile on
// each 3x3 matrix, which measured ~50x slower on an H100 for 4M of them.
at::Tensor batched_matmul(const at::Tensor& a, const at::Tensor& b);

}  // namespace tega::uvd
