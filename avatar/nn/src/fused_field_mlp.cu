// The field MLP as two kernels on the tensor cores (mma.sync m16n8k16,
// bfloat16 inputs, float32 accumulators).
//
// Forward: each warp takes 16 points through the three layers with their
// activations and the three tangent columns in registers. A layer's float
// accumulators, laid out as mma's C fragment, are exactly the A fragments of
// the next layer once packed to bfloat16, so nothing but the weights touches
// shared memory, and only the outputs reach global memory.
//
// Backward: each warp recomputes its 16 points' forward and pushes the output
// gradients back through the layers (SiLU's second derivative carries the
// tangents' gradients into the pre-activations'), writing the inputs'
// gradients. The weight gradients are sums over millions of points of outer
// products: the kernel writes each layer's inputs and pre-activation
// gradients in bfloat16, and cuBLAS reduces them (fused_field_mlp.cpp). Kept
// in the kernel instead, as block-wide tiles in shared memory, they left room
// for one block of 4 warps per multiprocessor, and the kernel was bound by
// latency (twice as slow as the composed path).
//
// Fragment layouts (PTX ISA, mma.m16n8k16 with .bf16), g = lane / 4, t = lane % 4:
//   A (16×16, row-major): r0 (g, 2t..2t+1), r1 (g+8, 2t..), r2 (g, 2t+8..), r3 (g+8, 2t+8..)
//   B (16×8, k × n):      b0 (k 2t..2t+1, n g), b1 (k 2t+8.., n g)
//   C (16×8, float):      v0 v1 (g, 2t..2t+1), v2 v3 (g+8, 2t..2t+1)
// Weights are kept row-major as [out][in] bfloat16, which is B's layout for a
// forward product (n = out, consecutive k = in); backward products read them
// transposed, two scalars a register.

#include <cuda_bf16.h>

#include <algorithm>

#include "fused_field_mlp_kernels.h"
#include "tega/core/cuda_check.h"

namespace tega::nn::fused_field::cuda {
namespace {

constexpr int kAxes = 3;
constexpr int kWarps = 4;
constexpr int kThreads = kWarps * 32;
constexpr int kWarpRows = 16;
constexpr int kHiddenBlocks = kHidden / 8;    // 8-column C tiles of a hidden layer
constexpr int kHiddenSteps = kHidden / 16;    // 16-wide k steps over a hidden layer
constexpr int kHiddenStride = kHidden + 8;    // shared rows padded so fragment loads hit distinct banks
constexpr int kNarrowStride = 16 + 8;         // the same for 16-wide rows
constexpr int kOutputRows = 16;               // the output layer padded to one k step
constexpr int kAccumulatorFloats = kHiddenBlocks * 4 * 32;  // a warp's hidden-width C tiles

using Bits = uint16_t;  // one bfloat16

struct C {
  float v[4];
};
struct A {
  uint32_t r[4];
};

int round_up(int x, int m) { return (x + m - 1) / m * m; }

// Byte offsets into the dynamic shared memory.
struct Layout {
  int encoding_steps_width;  // the encoding's k extent: its width rounded up to 16
  int first_width;           // the first layer's k extent: encoding steps + condition
  int first_stride;          // row stride of the first layer's weight and of its staged inputs
  bool tangents;
  size_t w0, wa, w1, w2, b0, b1, b2;
  size_t scratch;  // the backward kernel's per-warp accumulators (the forward's end)
  size_t end;
};

Layout layout_of(const Shape& s) {
  Layout l;
  l.encoding_steps_width = round_up(s.encoding_width, 16);
  l.first_width = l.encoding_steps_width + s.condition_channels;
  l.first_stride = l.first_width + 8;
  l.tangents = s.derivative_width > 0;
  size_t at = 0;
  const auto take = [&](size_t bytes) {
    const size_t offset = at;
    at += (bytes + 15) / 16 * 16;
    return offset;
  };
  l.w0 = take(sizeof(Bits) * kHidden * l.first_stride);
  l.wa = take(l.tangents ? sizeof(Bits) * kAxes * kHidden * kNarrowStride : 0);
  l.w1 = take(sizeof(Bits) * kHidden * kHiddenStride);
  l.w2 = take(sizeof(Bits) * kOutputRows * kHiddenStride);
  l.b0 = take(sizeof(float) * kHidden);
  l.b1 = take(sizeof(float) * kHidden);
  l.b2 = take(sizeof(float) * kOutputRows);
  l.scratch = take(l.tangents ? sizeof(float) * kWarps * kAccumulatorFloats * 2 : 0);
  l.end = at;
  return l;
}

// --- element math ------------------------------------------------------------

// Fast reciprocal and exponential: x is clamped so that 1 + e^-x stays below
// 2^126, where __fdividef is exact to a few ulp (beyond it returns 0).
__device__ __forceinline__ float sigmoid(float x) {
  return __fdividef(1.0f, 1.0f + __expf(-fminf(fmaxf(x, -80.0f), 80.0f)));
}
__device__ __forceinline__ float silu(float x) { return x * sigmoid(x); }
__device__ __forceinline__ float silu_d1(float x) {
  const float s = sigmoid(x);
  return s * (1.0f + x * (1.0f - s));
}
struct SiluDerivatives {
  float d1, d2;
};
__device__ __forceinline__ SiluDerivatives silu_derivatives(float x) {
  const float s = sigmoid(x);
  return {s * (1.0f + x * (1.0f - s)), s * (1.0f - s) * (2.0f + x * (1.0f - 2.0f * s))};
}

__device__ __forceinline__ Bits bits(float x) { return __bfloat16_as_ushort(__float2bfloat16_rn(x)); }
__device__ __forceinline__ uint32_t pair(Bits lo, Bits hi) { return uint32_t(lo) | (uint32_t(hi) << 16); }
__device__ __forceinline__ uint32_t pack(float lo, float hi) { return pair(bits(lo), bits(hi)); }

__device__ __forceinline__ void mma(C& c, const A& a, uint32_t b0, uint32_t b1) {
  asm volatile(
      "mma.sync.aligned.m16n8k16.row.col.f32.bf16.bf16.f32 {%0,%1,%2,%3}, {%4,%5,%6,%7}, {%8,%9}, "
      "{%0,%1,%2,%3};\n"
      : "+f"(c.v[0]), "+f"(c.v[1]), "+f"(c.v[2]), "+f"(c.v[3])
      : "r"(a.r[0]), "r"(a.r[1]), "r"(a.r[2]), "r"(a.r[3]), "r"(b0), "r"(b1));
}

// --- fragment loads and stores -------------------------------------------------

struct Lane {
  int g, t;
};

__device__ __forceinline__ Lane lane_of() { return {int(threadIdx.x % 32) / 4, int(threadIdx.x % 32) % 4}; }

// B fragments come from shared memory four 8×8 matrices at a time (ldmatrix.x4:
// lanes 8j..8j+7 give the rows of matrix j, 16-byte aligned as the strides and
// offsets are multiples of 8 elements): two fragments (b[0], b[1] and b[2], b[3])
// per instruction instead of four 32-bit loads each.
struct Fragments {
  uint32_t b[4];
};

__device__ __forceinline__ Fragments ldmatrix_x4(const Bits* row) {
  Fragments f;
  const auto address = static_cast<uint32_t>(__cvta_generic_to_shared(row));
  asm volatile("ldmatrix.sync.aligned.m8n8.x4.shared.b16 {%0, %1, %2, %3}, [%4];\n"
               : "=r"(f.b[0]), "=r"(f.b[1]), "=r"(f.b[2]), "=r"(f.b[3])
               : "r"(address));
  return f;
}
__device__ __forceinline__ Fragments ldmatrix_x4_trans(const Bits* row) {
  Fragments f;
  const auto address = static_cast<uint32_t>(__cvta_generic_to_shared(row));
  asm volatile("ldmatrix.sync.aligned.m8n8.x4.trans.shared.b16 {%0, %1, %2, %3}, [%4];\n"
               : "=r"(f.b[0]), "=r"(f.b[1]), "=r"(f.b[2]), "=r"(f.b[3])
               : "r"(address));
  return f;
}

__device__ __forceinline__ int matrix_of_lane() { return int(threadIdx.x % 32) / 8; }

// B[k][n] = w[n][k] for w row-major [n rows][k columns] (a forward product):
// the fragments of n-tiles n0 and n0+8 at k step k0.
__device__ __forceinline__ Fragments b_forward_tiles(const Bits* w, int ld, int n0, int k0) {
  const int m = matrix_of_lane();
  return ldmatrix_x4(w + (n0 + (m / 2) * 8 + int(threadIdx.x % 8)) * ld + k0 + (m % 2) * 8);
}
// The same for one n-tile at k steps k0 and k0+16.
__device__ __forceinline__ Fragments b_forward_steps(const Bits* w, int ld, int n0, int k0) {
  return ldmatrix_x4(w + (n0 + int(threadIdx.x % 8)) * ld + k0 + matrix_of_lane() * 8);
}

// B[k][n] = w[k][n] for w row-major [k rows][n columns] (a backward product),
// loaded transposed: the fragments of n-tiles n0 and n0+8 at k step k0.
__device__ __forceinline__ Fragments b_backward_tiles(const Bits* w, int ld, int n0, int k0) {
  return ldmatrix_x4_trans(w + (k0 + int(threadIdx.x % 16)) * ld + n0 + (matrix_of_lane() / 2) * 8);
}

// Two consecutive bfloat16 of a global row-major matrix, zero past its rows
// or columns (the column pair is either wholly inside or wholly outside, as
// widths are even).
__device__ __forceinline__ uint32_t global_pair(const __nv_bfloat16* m, int64_t rows, int ld, int64_t r, int c) {
  if (r >= rows || c >= ld) return 0;
  return *reinterpret_cast<const uint32_t*>(m + r * ld + c);
}
__device__ __forceinline__ uint32_t global_pair(const float* m, int64_t rows, int ld, int64_t r, int c) {
  if (r >= rows || c >= ld) return 0;
  const float2 v = *reinterpret_cast<const float2*>(m + r * ld + c);
  return pack(v.x, v.y);
}

template <typename T>
__device__ __forceinline__ A global_a(const T* m, int64_t rows, int ld, int64_t r0, int k0, Lane l) {
  const int c = k0 + 2 * l.t;
  const int64_t r = r0 + l.g;
  return {{global_pair(m, rows, ld, r, c), global_pair(m, rows, ld, r + 8, c), global_pair(m, rows, ld, r, c + 8),
           global_pair(m, rows, ld, r + 8, c + 8)}};
}

// The upstream gradient of an output as an A fragment (k = output, ≤ 8), read
// with `stride` between outputs: 1 for the value, 3 for a Jacobian axis.
__device__ __forceinline__ A gradient_a(const float* grad, int64_t points, int outputs, int stride, int axis,
                                        int64_t r0, Lane l) {
  A a{{0, 0, 0, 0}};
  if (!grad) return a;
  const int o = 2 * l.t;
  const auto at = [&](int64_t r, int oo) {
    return r < points && oo < outputs ? grad[(r * outputs + oo) * stride + axis] : 0.0f;
  };
  const int64_t r = r0 + l.g;
  a.r[0] = pack(at(r, o), at(r, o + 1));
  a.r[1] = pack(at(r + 8, o), at(r + 8, o + 1));
  return a;
}

// Packs C tiles 2kb and 2kb+1 of a layer into the next layer's A fragment kb.
template <typename F>
__device__ __forceinline__ A to_a(const C* c, int kb, F&& f) {
  const C& lo = c[2 * kb];
  const C& hi = c[2 * kb + 1];
  return {{pack(f(lo.v[0], 2 * kb, 0), f(lo.v[1], 2 * kb, 1)), pack(f(lo.v[2], 2 * kb, 2), f(lo.v[3], 2 * kb, 3)),
           pack(f(hi.v[0], 2 * kb + 1, 0), f(hi.v[1], 2 * kb + 1, 1)),
           pack(f(hi.v[2], 2 * kb + 1, 2), f(hi.v[3], 2 * kb + 1, 3))}};
}

// --- layers of one warp's 16 points ------------------------------------------

struct Shared {
  Bits *w0, *wa, *w1, *w2;
  float *b0, *b1, *b2;
};

__device__ Shared shared_weights(char* base, const Layout& lay) {
  return {reinterpret_cast<Bits*>(base + lay.w0),  reinterpret_cast<Bits*>(base + lay.wa),
          reinterpret_cast<Bits*>(base + lay.w1),  reinterpret_cast<Bits*>(base + lay.w2),
          reinterpret_cast<float*>(base + lay.b0), reinterpret_cast<float*>(base + lay.b1),
          reinterpret_cast<float*>(base + lay.b2)};
}

// The weights as bfloat16 rows [out][in] (the first layer's columns
// rearranged to the k steps: encoding, zeros up to a multiple of 16, then the
// condition; the tangents' first layer as one [64][16] matrix per axis), the
// biases in float.
__device__ void load_weights(const Shape& s, const Layout& lay, const Weights& w, const Shared& sh) {
  const int columns = s.encoding_channels + s.condition_channels;
  for (int i = threadIdx.x; i < kHidden * lay.first_width; i += blockDim.x) {
    const int j = i / lay.first_width, k = i % lay.first_width;
    float v = 0.0f;
    if (k < s.encoding_channels)
      v = w.input_weight[j * columns + k];
    else if (k >= lay.encoding_steps_width)
      v = w.input_weight[j * columns + s.encoding_channels + k - lay.encoding_steps_width];
    sh.w0[j * lay.first_stride + k] = bits(v);
  }
  if (lay.tangents) {
    for (int i = threadIdx.x; i < kAxes * kHidden * 16; i += blockDim.x) {
      const int axis = i / (kHidden * 16), j = i / 16 % kHidden, f = i % 16;
      const float v = f < s.features ? w.input_weight[j * columns + kAxes * f + axis] : 0.0f;
      sh.wa[(axis * kHidden + j) * kNarrowStride + f] = bits(v);
    }
  }
  for (int i = threadIdx.x; i < kHidden * kHidden; i += blockDim.x)
    sh.w1[i / kHidden * kHiddenStride + i % kHidden] = bits(w.hidden_weight[i]);
  for (int i = threadIdx.x; i < kOutputRows * kHidden; i += blockDim.x) {
    const int o = i / kHidden;
    sh.w2[o * kHiddenStride + i % kHidden] = o < s.outputs ? bits(w.output_weight[i]) : Bits(0);
  }
  for (int i = threadIdx.x; i < kHidden; i += blockDim.x) {
    sh.b0[i] = w.input_bias[i];
    sh.b1[i] = w.hidden_bias[i];
  }
  for (int i = threadIdx.x; i < kOutputRows; i += blockDim.x) sh.b2[i] = i < s.outputs ? w.output_bias[i] : 0.0f;
  __syncthreads();
}

__device__ __forceinline__ void bias_tiles(C* c, int tiles, const float* bias, Lane l) {
  for (int nb = 0; nb < tiles; ++nb) {
    const float lo = bias ? bias[nb * 8 + 2 * l.t] : 0.0f, hi = bias ? bias[nb * 8 + 2 * l.t + 1] : 0.0f;
    c[nb] = {{lo, hi, lo, hi}};
  }
}

// out += a · wᵀ over the hidden width's n-tiles, at k step k0 of w.
__device__ __forceinline__ void forward_tiles(C (&out)[kHiddenBlocks], const A& a, const Bits* w, int ld, int k0) {
#pragma unroll
  for (int nb = 0; nb < kHiddenBlocks; nb += 2) {
    const Fragments f = b_forward_tiles(w, ld, nb * 8, k0);
    mma(out[nb], a, f.b[0], f.b[1]);
    mma(out[nb + 1], a, f.b[2], f.b[3]);
  }
}

// out += g · w over the hidden width's n-tiles, w's rows k0..k0+15 (a backward product).
__device__ __forceinline__ void backward_tiles(C (&out)[kHiddenBlocks], const A& g, const Bits* w, int ld, int k0) {
#pragma unroll
  for (int nb = 0; nb < kHiddenBlocks; nb += 2) {
    const Fragments f = b_backward_tiles(w, ld, nb * 8, k0);
    mma(out[nb], g, f.b[0], f.b[1]);
    mma(out[nb + 1], g, f.b[2], f.b[3]);
  }
}

// Pre-activations of the first layer, [E, condition]·W0ᵀ + b0.
__device__ void first_layer(C (&z)[kHiddenBlocks], const Shape& s, const Layout& lay, const Shared& sh,
                            const Inputs& in, int64_t r0, Lane l) {
  bias_tiles(z, kHiddenBlocks, sh.b0, l);
  for (int k0 = 0; k0 < lay.encoding_steps_width; k0 += 16) {
    const A a = global_a(in.encoding, s.points, s.encoding_width, r0, k0, l);
    forward_tiles(z, a, sh.w0, lay.first_stride, k0);
  }
  for (int k0 = 0; k0 < s.condition_channels; k0 += 16) {
    const A a = global_a(in.condition, s.points, s.condition_channels, r0, k0, l);
    forward_tiles(z, a, sh.w0, lay.first_stride, lay.encoding_steps_width + k0);
  }
}

__device__ __forceinline__ A derivative_a(const Shape& s, const Inputs& in, int axis, int64_t r0, Lane l) {
  return global_a(in.derivatives + int64_t(axis) * s.points * s.derivative_width, s.points, s.derivative_width, r0, 0,
                  l);
}

// The first layer's tangent along one axis: derivatives · W_axisᵀ.
__device__ void first_tangent(C (&t)[kHiddenBlocks], const Shape& s, const Shared& sh, const Inputs& in, int axis,
                              int64_t r0, Lane l) {
  bias_tiles(t, kHiddenBlocks, nullptr, l);
  const A a = derivative_a(s, in, axis, r0, l);
  forward_tiles(t, a, sh.wa + axis * kHidden * kNarrowStride, kNarrowStride, 0);
}

// A hidden layer's product x·W1ᵀ (+ b1 when given) from A fragments.
__device__ void hidden_layer(C (&out)[kHiddenBlocks], const A (&x)[kHiddenSteps], const Shared& sh, const float* bias,
                             Lane l) {
  bias_tiles(out, kHiddenBlocks, bias, l);
#pragma unroll
  for (int kb = 0; kb < kHiddenSteps; ++kb) forward_tiles(out, x[kb], sh.w1, kHiddenStride, kb * 16);
}

// The output layer's product x·W2ᵀ (+ b2 when given): one 8-column tile.
__device__ C output_layer(const A (&x)[kHiddenSteps], const Shared& sh, const float* bias, Lane l) {
  C y;
  bias_tiles(&y, 1, bias, l);
#pragma unroll
  for (int kb = 0; kb < kHiddenSteps; kb += 2) {
    const Fragments f = b_forward_steps(sh.w2, kHiddenStride, 0, kb * 16);
    mma(y, x[kb], f.b[0], f.b[1]);
    mma(y, x[kb + 1], f.b[2], f.b[3]);
  }
  return y;
}

// g·W for an upstream gradient g [16 × 16] (k = outputs) and the output
// layer's W [outputs × 64]: the gradient of the last hidden activations.
__device__ void output_backward(C (&out)[kHiddenBlocks], const A& g, const Shared& sh, Lane l) {
  bias_tiles(out, kHiddenBlocks, nullptr, l);
  backward_tiles(out, g, sh.w2, kHiddenStride, 0);
}

// Writes C tile rows r0+g and r0+g+8, columns c and c+1, where they exist.
template <typename Write>
__device__ __forceinline__ void for_tile(const C& c, int64_t r0, int column0, Lane l, Write&& write) {
  const int column = column0 + 2 * l.t;
  write(r0 + l.g, column, c.v[0], c.v[1]);
  write(r0 + l.g + 8, column, c.v[2], c.v[3]);
}

// --- forward -----------------------------------------------------------------

// Compiled apart with and without the tangents, so that a field without them
// (shading) gets registers for its own path: more warps a multiprocessor.
template <bool Tangents>
__global__ void __launch_bounds__(kThreads, Tangents ? 3 : 4)
    fused_field_forward(Shape s, Layout lay, Weights w, Inputs in, float* __restrict__ value,
                        float* __restrict__ jacobian) {
  extern __shared__ uint4 shared_memory[];
  const Shared sh = shared_weights(reinterpret_cast<char*>(shared_memory), lay);
  load_weights(s, lay, w, sh);
  const Lane l = lane_of();
  const int warp = threadIdx.x / 32;
  const int64_t chunks = (s.points + kWarpRows - 1) / kWarpRows;
  const auto write_outputs = [&](const C& y, int64_t r0, float* out, int stride, int axis) {
    for_tile(y, r0, 0, l, [&](int64_t r, int o, float lo, float hi) {
      if (r >= s.points) return;
      if (o < s.outputs) out[(r * s.outputs + o) * stride + axis] = lo;
      if (o + 1 < s.outputs) out[(r * s.outputs + o + 1) * stride + axis] = hi;
    });
  };
  for (int64_t chunk = int64_t(blockIdx.x) * kWarps + warp; chunk < chunks; chunk += int64_t(gridDim.x) * kWarps) {
    const int64_t r0 = chunk * kWarpRows;
    C z[kHiddenBlocks];
    first_layer(z, s, lay, sh, in, r0, l);
    A h0[kHiddenSteps];
    for (int kb = 0; kb < kHiddenSteps; ++kb) h0[kb] = to_a(z, kb, [](float x, int, int) { return silu(x); });
    C d0[kHiddenBlocks];  // silu'(z0)
    for (int nb = 0; nb < kHiddenBlocks; ++nb)
      for (int i = 0; i < 4; ++i) d0[nb].v[i] = silu_d1(z[nb].v[i]);
    hidden_layer(z, h0, sh, sh.b1, l);
    A h1[kHiddenSteps];
    for (int kb = 0; kb < kHiddenSteps; ++kb) h1[kb] = to_a(z, kb, [](float x, int, int) { return silu(x); });
    write_outputs(output_layer(h1, sh, sh.b2, l), r0, value, 1, 0);
    if constexpr (Tangents) {
      C d1[kHiddenBlocks];  // silu'(z1)
      for (int nb = 0; nb < kHiddenBlocks; ++nb)
        for (int i = 0; i < 4; ++i) d1[nb].v[i] = silu_d1(z[nb].v[i]);
      for (int axis = 0; axis < kAxes; ++axis) {
        C t[kHiddenBlocks];
        first_tangent(t, s, sh, in, axis, r0, l);
        A u[kHiddenSteps];
        for (int kb = 0; kb < kHiddenSteps; ++kb)
          u[kb] = to_a(t, kb, [&](float x, int nb, int i) { return d0[nb].v[i] * x; });
        hidden_layer(t, u, sh, nullptr, l);
        for (int kb = 0; kb < kHiddenSteps; ++kb)
          u[kb] = to_a(t, kb, [&](float x, int nb, int i) { return d1[nb].v[i] * x; });
        write_outputs(output_layer(u, sh, nullptr, l), r0, jacobian, kAxes, axis);
      }
    }
  }
}

// --- backward ----------------------------------------------------------------

__device__ __forceinline__ void store_rows(__nv_bfloat16* m, int ld, int64_t rows, int64_t r0, int k0, const A& a,
                                           Lane l) {
  const int64_t r = r0 + l.g;
  const int c = k0 + 2 * l.t;
  uint32_t* lo = reinterpret_cast<uint32_t*>(m + r * ld + c);
  uint32_t* hi = reinterpret_cast<uint32_t*>(m + (r + 8) * ld + c);
  if (r < rows) {
    lo[0] = a.r[0];
    if (c + 8 < ld) lo[4] = a.r[2];
  }
  if (r + 8 < rows) {
    hi[0] = a.r[1];
    if (c + 8 < ld) hi[4] = a.r[3];
  }
}

// One hidden-width matrix of C tiles, packed and written as rows of `m`.
__device__ __forceinline__ void store_tiles(__nv_bfloat16* m, int64_t rows, int64_t r0, const A (&a)[kHiddenSteps],
                                            Lane l) {
#pragma unroll
  for (int kb = 0; kb < kHiddenSteps; ++kb) store_rows(m, kHidden, rows, r0, kb * 16, a[kb], l);
}

// Element i of C tile nb, read back from the A fragments it was packed into.
__device__ __forceinline__ float element(const A (&a)[kHiddenSteps], int nb, int i) {
  const uint32_t r = a[nb / 2].r[(nb % 2) * 2 + i / 2];
  return __uint_as_float(i % 2 ? r & 0xffff0000u : r << 16);
}

template <typename F>
__device__ __forceinline__ void pack_tiles(A (&a)[kHiddenSteps], const C (&c)[kHiddenBlocks], F&& f) {
#pragma unroll
  for (int kb = 0; kb < kHiddenSteps; ++kb) a[kb] = to_a(c, kb, f);
}

// g·W1 for a hidden layer's pre-activation gradient g held as A fragments.
__device__ void hidden_backward(C (&out)[kHiddenBlocks], const A (&g)[kHiddenSteps], const Shared& sh, Lane l) {
  bias_tiles(out, kHiddenBlocks, nullptr, l);
#pragma unroll
  for (int kb = 0; kb < kHiddenSteps; ++kb) backward_tiles(out, g[kb], sh.w1, kHiddenStride, kb * 16);
}

// Output tiles n0 and n0+8 of g·W for a gradient g over the hidden width (an input's gradient).
__device__ __forceinline__ void input_tiles(C (&c)[2], const A (&g)[kHiddenSteps], const Bits* w, int ld, int n0) {
  c[0] = c[1] = C{{0, 0, 0, 0}};
#pragma unroll
  for (int kb = 0; kb < kHiddenSteps; ++kb) {
    const Fragments f = b_backward_tiles(w, ld, n0, kb * 16);
    mma(c[0], g[kb], f.b[0], f.b[1]);
    mma(c[1], g[kb], f.b[2], f.b[3]);
  }
}

// Hides a's values from the compiler for what follows, so that values computed
// from them before (SiLU's derivatives: two special-function operations each)
// are not kept in registers to be reused after, nor hoisted out of a loop.
__device__ __forceinline__ void opaque(A (&a)[kHiddenSteps]) {
#pragma unroll
  for (int kb = 0; kb < kHiddenSteps; ++kb)
#pragma unroll
    for (int j = 0; j < 4; ++j) asm volatile("" : "+r"(a[kb].r[j]));
}

// A warp's hidden-width C tiles held in shared memory (element i of tile nb of
// lane j at [nb * 4 + i][j], so that a warp's access hits 32 banks), where
// registers would spill.
struct SharedTiles {
  float* lane;  // this lane's element 0
  __device__ __forceinline__ float& operator()(int nb, int i) const { return lane[(nb * 4 + i) * 32]; }
};

// Each warp takes 16 points: the forward again, then the output gradients
// back to the inputs. What the weight gradients need (each layer's inputs and
// its pre-activations' gradients) is written out in bfloat16 for the matrix
// products that sum them over the points (fused_field_mlp.cpp). Compiled apart
// with and without the tangents, as the forward is. With them it takes 255
// registers (two blocks a multiprocessor) and spills 16 bytes: capped at 168
// for three blocks it spilled ~500 and a training step took longer (H200).
template <bool Tangents>
__global__ void __launch_bounds__(kThreads, Tangents ? 2 : 4)
    fused_field_backward(Shape s, Layout lay, Weights w, Inputs in, const float* __restrict__ grad_value,
                         const float* __restrict__ grad_jacobian, __nv_bfloat16* __restrict__ grad_encoding,
                         __nv_bfloat16* __restrict__ grad_derivatives, float* __restrict__ grad_condition, Products p) {
  extern __shared__ uint4 shared_memory[];
  const Shared sh = shared_weights(reinterpret_cast<char*>(shared_memory), lay);
  load_weights(s, lay, w, sh);
  const Lane l = lane_of();
  const int warp = threadIdx.x / 32;
  const int64_t n = s.points, chunks = (n + kWarpRows - 1) / kWarpRows;
  const auto set = [&](__nv_bfloat16* m, int index, int width) { return m + int64_t(index) * n * width; };
  const auto identity = [](float x, int, int) { return x; };
  // With the tangents, the pre-activation gradients of both layers build up
  // over the axes in shared memory, to leave registers for one axis's work.
  float* const scratch = reinterpret_cast<float*>(reinterpret_cast<char*>(shared_memory) + lay.scratch) +
                         warp * 2 * kAccumulatorFloats + threadIdx.x % 32;
  const SharedTiles gz0_sum{scratch}, gz1_sum{scratch + kAccumulatorFloats};

  for (int64_t chunk = int64_t(blockIdx.x) * kWarps + warp; chunk < chunks; chunk += int64_t(gridDim.x) * kWarps) {
    const int64_t r0 = chunk * kWarpRows;
    // The pre-activations z0, z1 are kept in bfloat16 (as the composed path
    // stores them) for SiLU's derivatives: in float they made the kernel spill.
    A z0[kHiddenSteps], z1[kHiddenSteps], frag[kHiddenSteps];
    C acc[kHiddenBlocks], gz1[kHiddenBlocks];
    first_layer(acc, s, lay, sh, in, r0, l);
    pack_tiles(z0, acc, identity);
    pack_tiles(frag, acc, [](float x, int, int) { return silu(x); });
    store_tiles(p.hidden_inputs, n, r0, frag, l);
    hidden_layer(acc, frag, sh, sh.b1, l);
    pack_tiles(z1, acc, identity);
    pack_tiles(frag, acc, [](float x, int, int) { return silu(x); });
    store_tiles(p.output_inputs, n, r0, frag, l);
    const A gy = gradient_a(grad_value, n, s.outputs, 1, 0, r0, l);
    store_rows(p.output_gradients, kMaxOutputs, n, r0, 0, gy, l);
    output_backward(gz1, gy, sh, l);
#pragma unroll
    for (int nb = 0; nb < kHiddenBlocks; ++nb)
#pragma unroll
      for (int i = 0; i < 4; ++i) gz1[nb].v[i] *= silu_d1(element(z1, nb, i));
    if constexpr (Tangents) {
#pragma unroll
      for (int nb = 0; nb < kHiddenBlocks; ++nb)
#pragma unroll
        for (int i = 0; i < 4; ++i) {
          gz1_sum(nb, i) = gz1[nb].v[i];
          gz0_sum(nb, i) = 0.0f;
        }
      // silu'(z0), packed once for the three axes: computed where it is used,
      // its special functions made the kernel spill.
      A d1z0[kHiddenSteps];
#pragma unroll
      for (int kb = 0; kb < kHiddenSteps; ++kb)
#pragma unroll
        for (int j = 0; j < 4; ++j) {
          const int nb = 2 * kb + j / 2, i = (j % 2) * 2;  // the elements of register j (to_a's order)
          d1z0[kb].r[j] = pack(silu_d1(element(z0, nb, i)), silu_d1(element(z0, nb, i + 1)));
        }
#pragma unroll 1  // one axis at a time: unrolled, the axes' registers overlap and spill
      for (int axis = 0; axis < kAxes; ++axis) {
        C t[kHiddenBlocks], g[kHiddenBlocks];
        opaque(z0);  // SiLU's derivatives kept across the axes made the kernel spill
        opaque(z1);
        first_tangent(t, s, sh, in, axis, r0, l);
        pack_tiles(frag, t, [&](float x, int nb, int i) { return element(d1z0, nb, i) * x; });
        store_tiles(set(p.hidden_inputs, 1 + axis, kHidden), n, r0, frag, l);
        hidden_layer(t, frag, sh, nullptr, l);  // t: the hidden layer's tangent from here on
        const A gj = gradient_a(grad_jacobian, n, s.outputs, kAxes, axis, r0, l);
        store_rows(set(p.output_gradients, 1 + axis, kMaxOutputs), kMaxOutputs, n, r0, 0, gj, l);
        output_backward(g, gj, sh, l);
#pragma unroll
        for (int nb = 0; nb < kHiddenBlocks; ++nb)
#pragma unroll
          for (int i = 0; i < 4; ++i) {
            const SiluDerivatives d = silu_derivatives(element(z1, nb, i));
            gz1_sum(nb, i) += g[nb].v[i] * t[nb].v[i] * d.d2;
            g[nb].v[i] *= d.d1;
            t[nb].v[i] *= d.d1;  // t: the output layer's input along this axis from here on
          }
        pack_tiles(frag, t, identity);
        store_tiles(set(p.output_inputs, 1 + axis, kHidden), n, r0, frag, l);
        pack_tiles(frag, g, identity);
        store_tiles(set(p.hidden_gradients, 1 + axis, kHidden), n, r0, frag, l);
        hidden_backward(g, frag, sh, l);  // g: the first layer's tangent gradient from here on
        first_tangent(t, s, sh, in, axis, r0, l);
#pragma unroll
        for (int nb = 0; nb < kHiddenBlocks; ++nb)
#pragma unroll
          for (int i = 0; i < 4; ++i) {
            const SiluDerivatives d = silu_derivatives(element(z0, nb, i));
            gz0_sum(nb, i) += g[nb].v[i] * t[nb].v[i] * d.d2;
            g[nb].v[i] *= d.d1;
          }
        pack_tiles(frag, g, identity);
        store_tiles(set(p.first_gradients, 1 + axis, kHidden), n, r0, frag, l);
        // The derivatives' gradient: frag · W_axis, 16 columns.
        const Bits* wa = sh.wa + axis * kHidden * kNarrowStride;
        __nv_bfloat16* gd = grad_derivatives + int64_t(axis) * n * s.derivative_width;
        C c[2];
        input_tiles(c, frag, wa, kNarrowStride, 0);
#pragma unroll
        for (int nb = 0; nb < 2; ++nb)
          for_tile(c[nb], r0, nb * 8, l, [&](int64_t r, int f, float lo, float hi) {
            if (r < n && f < s.derivative_width)
              *reinterpret_cast<__nv_bfloat162*>(gd + r * s.derivative_width + f) = __floats2bfloat162_rn(lo, hi);
          });
      }
#pragma unroll
      for (int nb = 0; nb < kHiddenBlocks; ++nb)
#pragma unroll
        for (int i = 0; i < 4; ++i) gz1[nb].v[i] = gz1_sum(nb, i);
    }
    pack_tiles(frag, gz1, identity);
    store_tiles(p.hidden_gradients, n, r0, frag, l);
    hidden_backward(gz1, frag, sh, l);  // gz1: the first hidden activation's gradient from here on
#pragma unroll
    for (int nb = 0; nb < kHiddenBlocks; ++nb)
#pragma unroll
      for (int i = 0; i < 4; ++i)
        acc[nb].v[i] = (Tangents ? gz0_sum(nb, i) : 0.0f) + gz1[nb].v[i] * silu_d1(element(z0, nb, i));
    pack_tiles(frag, acc, identity);
    store_tiles(p.first_gradients, n, r0, frag, l);
    // The encoding's and condition's gradients: frag · W0.
    for (int pair = 0; pair < lay.first_width / 16; ++pair) {  // first_width: a multiple of 16
      C c[2];
      input_tiles(c, frag, sh.w0, lay.first_stride, pair * 16);
      for (int nb = 0; nb < 2; ++nb)
        for_tile(c[nb], r0, pair * 16 + nb * 8, l, [&](int64_t r, int column, float lo, float hi) {
          if (r >= n) return;
          if (column < lay.encoding_steps_width) {
            if (column < s.encoding_width)
              *reinterpret_cast<__nv_bfloat162*>(grad_encoding + r * s.encoding_width + column) =
                  __floats2bfloat162_rn(lo, hi);
          } else {
            *reinterpret_cast<float2*>(grad_condition + r * s.condition_channels + column - lay.encoding_steps_width) =
                make_float2(lo, hi);
          }
        });
    }
  }
}

}  // namespace

size_t shared_bytes(const Shape& shape) { return layout_of(shape).end; }

namespace {

// Enough blocks of 4 warps to fill every multiprocessor a few times over; the
// warps stride over the rest.
unsigned blocks_for(const Shape& shape, int multiprocessors) {
  const int64_t chunks = (shape.points + kWarpRows - 1) / kWarpRows;
  return unsigned(std::min<int64_t>((chunks + kWarps - 1) / kWarps, int64_t(multiprocessors) * 8));
}

}  // namespace

void forward(const Shape& shape, const Weights& weights, const Inputs& inputs, float* value, float* jacobian,
             int multiprocessors, cudaStream_t stream) {
  if (shape.points == 0) return;
  const Layout lay = layout_of(shape);
  const auto kernel = lay.tangents ? fused_field_forward<true> : fused_field_forward<false>;
  check_cuda(cudaFuncSetAttribute(kernel, cudaFuncAttributeMaxDynamicSharedMemorySize, int(lay.scratch)),
             "fused_field_mlp", "setting the forward kernel's shared memory");
  kernel<<<blocks_for(shape, multiprocessors), kThreads, lay.scratch, stream>>>(shape, lay, weights, inputs, value,
                                                                                jacobian);
  check_launch("fused_field_mlp", "fused_field_forward");
}

void backward(const Shape& shape, const Weights& weights, const Inputs& inputs, const float* grad_value,
              const float* grad_jacobian, __nv_bfloat16* grad_encoding, __nv_bfloat16* grad_derivatives,
              float* grad_condition, const Products& products, int multiprocessors, cudaStream_t stream) {
  if (shape.points == 0) return;
  const Layout lay = layout_of(shape);
  const auto kernel = lay.tangents ? fused_field_backward<true> : fused_field_backward<false>;
  check_cuda(cudaFuncSetAttribute(kernel, cudaFuncAttributeMaxDynamicSharedMemorySize, int(lay.end)),
             "fused_field_mlp", "setting the backward kernel's shared memory");
  kernel<<<blocks_for(shape, multiprocessors), kThreads, lay.end, stream>>>(shape, lay, weights, inputs, grad_value,
                                                                            grad_jacobian, grad_encoding,
                                                                            grad_derivatives, grad_condition, products);
  check_launch("fused_field_mlp", "fused_field_backward");
}

}  // namespace tega::nn::fused_field::cuda
