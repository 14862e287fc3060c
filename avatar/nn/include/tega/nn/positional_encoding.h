#pragma once
// The sinusoidal positional encoding of uvd that conditions TeGA's field MLPs
// (field_mlp.h), and the fused op that computes it together with its
// derivatives in the layout the first layer's matrix products read.

#include <ATen/core/Tensor.h>
#include <c10/core/ScalarType.h>

#include <cstdint>

namespace tega::nn {

// PE(uvd) = [x, sin(2^k π x), cos(2^k π x)] for k = 0..frequencies-1, where
// x = (u, v, depth_scale·d) with d in metres. depth_scale maps d to units
// comparable with uv (the layout fills the unit square, so 1 unit of u spans
// some tenths of a metre of the head: the default 3 makes 1 unit of scaled
// d ≈ 0.33 m).
//
// Channel 3f + a is feature f (x, then sin and cos per octave) of axis a, so
// every channel depends on one axis only: its derivative is a single number,
// and axis_derivatives() holds [3, N, features()] of them instead of a mostly
// zero [N, 3, channels()] Jacobian.
//
// encode() and axis_derivatives() are the plain tensor-op definitions;
// encode_positions() below computes the same in one pass.
struct PositionalEncoding {
  int64_t frequencies = 6;
  double depth_scale = 3.0;

  int64_t features() const { return 1 + 2 * frequencies; }
  int64_t channels() const { return 3 * features(); }
  at::Tensor encode(const at::Tensor& uvd) const;  // [N,3] → [N,channels()]
  // ∂ channel (3f + a) / ∂ uvd_a as [3 (a), N, features() (f)].
  at::Tensor axis_derivatives(const at::Tensor& uvd) const;
};

// Rows of the fused op's outputs are padded with zero columns to a multiple
// of 8 elements: cuBLAS runs its fast kernels only on matrices whose rows
// start 16-byte aligned (with 39 encoding channels, every product of the
// first layer fell back to its slowest kernels).
constexpr int64_t kRowAlignment = 8;
inline int64_t aligned_width(int64_t width) { return (width + kRowAlignment - 1) / kRowAlignment * kRowAlignment; }

struct EncodedPositions {
  at::Tensor encoding;     // [N, aligned_width(channels())], columns past channels() zero
  at::Tensor derivatives;  // [3, N, aligned_width(features())], columns past features() zero; or undefined
};

// encode() and, with `with_derivatives`, axis_derivatives() of uvd ([N,3],
// float32 or float64, on the CPU or a GPU) as one op, stored as `type`
// (uvd's dtype, or bfloat16 on CUDA). The math runs in uvd's dtype; autograd
// differentiates both outputs w.r.t. uvd (first order).
EncodedPositions encode_positions(const PositionalEncoding& encoding, const at::Tensor& uvd, at::ScalarType type,
                                  bool with_derivatives);

}  // namespace tega::nn
