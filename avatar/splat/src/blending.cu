// CUDA kernels of the per-tile blending, forward and backward. They compute
// what blend_forward / blend_backward (gaussian_math.h) compute on the CPU,
// in a form that costs fewer instructions per pixel and splat, the unit
// both kernels are bound by (docs/rasterizer.md, "Blending on CUDA").

#include "cuda_check.h"
#include "cuda_rasterizer.h"

namespace tega::splat::cuda {
namespace {

constexpr int kForwardThreads = kTileSize * kTileSize;  // one pixel each
// The backward pass gives each thread two pixels, so that a splat read from
// shared memory and each warp reduction serve 64 pixels. (Four pixels a
// thread halve the reductions but cost more than they save: fewer resident
// warps, and a warp's block of 128 pixels touches more splats.)
constexpr int kPixelsPerThread = 2;
constexpr int kBackwardThreads = kTileSize * kTileSize / kPixelsPerThread;
constexpr unsigned kFullWarp = 0xffffffffu;
constexpr float kLog2e = 1.4426950408889634f;
constexpr float kLn2 = 0.6931471805599453f;

// A splat as the blending loops read it: the Gaussian is 2^p with
//   p = a dx² + b dx dy + c dy²,  (a, b, c) = -log2(e) (½ conic_a, conic_b, ½ conic_c),
// so one ex2 instruction evaluates it, and the kMinAlpha test becomes
// p ≥ cutoff = log2(kMinAlpha / opacity), made before the exponential: most
// splats of a tile miss most of its pixels. Both kernels evaluate p with
// blend_exponent(), so the backward pass skips exactly what the forward
// pass skipped.
struct alignas(16) BlendSplat {
  float u, v, a, b;
  float c, opacity, cutoff, depth;
  float red, green, blue, unused;
};

__device__ __forceinline__ Splat2D<float> load_splat(const Splat2D<float>* src) {
  const float4* s = reinterpret_cast<const float4*>(src);
  Splat2D<float> sp;
  float4* d = reinterpret_cast<float4*>(&sp);
  d[0] = __ldg(s);
  d[1] = __ldg(s + 1);
  d[2] = __ldg(s + 2);
  return sp;
}

__device__ __forceinline__ BlendSplat blend_splat(const Splat2D<float>& sp) {
  return {sp.u,
          sp.v,
          -0.5f * kLog2e * sp.conic_a,
          -kLog2e * sp.conic_b,
          -0.5f * kLog2e * sp.conic_c,
          sp.opacity,
          log2f(float(kMinAlpha) / sp.opacity),
          sp.depth,
          sp.red,
          sp.green,
          sp.blue,
          0.0f};
}

__device__ __forceinline__ float exp2_approx(float x) {
  float y;
  asm("ex2.approx.ftz.f32 %0, %1;" : "=f"(y) : "f"(x));
  return y;
}

// p of the splat at offset (dx, dy) from its mean; a_dx_b_dy = a dx + b dy and
// c_dy = c dy are kept for the backward pass.
struct Exponent {
  float p, a_dx_b_dy, c_dy;
};
__device__ __forceinline__ Exponent blend_exponent(const BlendSplat& s, float dx, float dy) {
  Exponent e;
  e.a_dx_b_dy = fmaf(s.a, dx, s.b * dy);
  e.c_dy = s.c * dy;
  e.p = fmaf(dx, e.a_dx_b_dy, e.c_dy * dy);
  return e;
}

// Whether the splat may reach a pixel of a warp's block of pixels: `cols` x
// `rows` from (x0, y0), clipped to the image (the ellipse test that bins
// splats to tiles, at the size of the block a warp blends).
__device__ __forceinline__ bool block_may_touch(const Splat2D<float>& sp, const ImageGeometry& g, int32_t x0,
                                                int32_t y0, int32_t cols, int32_t rows) {
  if (x0 >= g.width || y0 >= g.height) return false;
  const int32_t x1 = min(x0 + cols - 1, g.width - 1), y1 = min(y0 + rows - 1, g.height - 1);
  return splat_may_touch(sp, splat_level(sp), float(x0), float(y0), float(x1), float(y1));
}

__device__ __forceinline__ int64_t block_tile(const ImageGeometry& g) {
  return (int64_t(blockIdx.z) * g.tiles_y + blockIdx.y) * g.tiles_x + blockIdx.x;
}

// Each warp blends an 8x4 block of its tile, a pixel per lane (of the
// shapes of 32 pixels, the squarest touches the fewest splats: a splat is
// evaluated at all of a warp's pixels once it touches one). Each warp walks
// the tile's list on its own, 32 entries at a time: it loads them, keeps
// those its block may use, and stops when its pixels are done. Warps never
// wait for each other (with a batch shared by the block, a fifth of the time
// went to barriers: the warps' work differs).
constexpr int kForwardCols = 8, kForwardRows = 4;
static_assert(kForwardCols * kForwardRows == 32 && kTileSize % kForwardCols == 0 &&
                  kForwardThreads / 32 == (kTileSize / kForwardCols) * (kTileSize / kForwardRows),
              "the warps' blocks must tile a tile");

__global__ void __launch_bounds__(kForwardThreads) render_forward_kernel(RasterInputs<float> in,
                                                                         const Splat2D<float>* splats, TileBins bins,
                                                                         ImageBuffers<float> image) {
  constexpr int kWarps = kForwardThreads / 32, kBlocksAcross = kTileSize / kForwardCols;
  __shared__ BlendSplat batches[kWarps][32];
  const ImageGeometry g = in.geometry;
  const int64_t tile = block_tile(g);
  const unsigned lane = threadIdx.x % 32, warp = threadIdx.x / 32;
  BlendSplat* batch = batches[warp];
  const int32_t block_x0 = int32_t(blockIdx.x) * kTileSize + kForwardCols * int32_t(warp % kBlocksAcross);
  const int32_t block_y0 = int32_t(blockIdx.y) * kTileSize + kForwardRows * int32_t(warp / kBlocksAcross);
  const int32_t x = block_x0 + int32_t(lane % kForwardCols), y = block_y0 + int32_t(lane / kForwardCols);
  const bool inside = x < g.width && y < g.height;
  const float px = float(x), py = float(y);
  const int32_t begin = bins.ranges[2 * tile], end = bins.ranges[2 * tile + 1];

  float transmittance = 1.0f, red = 0.0f, green = 0.0f, blue = 0.0f, depth = 0.0f;
  int32_t last = 0;
  bool done = !inside;
  for (int32_t start = begin; start < end && !__all_sync(kFullWarp, done); start += 32) {
    const int32_t k = start + int32_t(lane);
    bool used = false;
    if (k < end) {
      const Splat2D<float> sp = load_splat(splats + bins.gaussian_ids[k]);
      used = block_may_touch(sp, g, block_x0, block_y0, kForwardCols, kForwardRows);
      if (used) batch[lane] = blend_splat(sp);
    }
    uint32_t pending = __ballot_sync(kFullWarp, used);
    __syncwarp();
    while (pending) {
      const int32_t j = __ffs(pending) - 1;
      pending &= pending - 1;
      if (done) continue;
      const BlendSplat s = batch[j];
      const Exponent e = blend_exponent(s, px - s.u, py - s.v);
      if (e.p < s.cutoff) continue;
      const float alpha = fminf(float(kMaxAlpha), s.opacity * exp2_approx(e.p));
      const float next = transmittance * (1.0f - alpha);
      if (next < float(kMinTransmittance)) {
        done = true;
        continue;
      }
      const float w = alpha * transmittance;
      red = fmaf(w, s.red, red);
      green = fmaf(w, s.green, green);
      blue = fmaf(w, s.blue, blue);
      depth = fmaf(w, s.depth, depth);
      transmittance = next;
      last = start - begin + j + 1;
    }
    __syncwarp();  // the batch is read before the next round overwrites it
  }
  if (!inside) return;
  const int64_t pixel = (int64_t(blockIdx.z) * g.height + y) * g.width + x;
  const float* bg = in.background;
  image.rgb[3 * pixel] = red + transmittance * bg[0];
  image.rgb[3 * pixel + 1] = green + transmittance * bg[1];
  image.rgb[3 * pixel + 2] = blue + transmittance * bg[2];
  image.alpha[pixel] = 1.0f - transmittance;
  image.depth[pixel] = expected_depth(depth, 1.0f - transmittance);
  image.final_transmittance[pixel] = transmittance;
  image.last[pixel] = last;
}

// One pixel of the backward walk, back to front (PixelBackward's fields, with
// the final-transmittance term folded into one number). The depth fields are
// used only when the loss depends on the depth image.
struct PixelState {
  float grad_rgb[3], grad_depth;
  float final_term;  // T_final (dL/dalpha_out - background · dL/drgb)
  float transmittance;
  float behind_rgb[3], behind_depth;
};

// Gradient fields of one splat summed over a thread's pixels, in
// warp_reduce_scatter's order. The shape terms are in the units that cost
// least per pixel; kFieldScale turns the warp's totals into d loss / d field.
enum Field { kU, kV, kOpacity, kDepth, kConicA, kConicB, kConicC, kRed, kGreen, kBlue, kFields };
__device__ constexpr float kFieldScale[kFields] = {-kLn2, -kLn2, 1.0f, 1.0f, -0.5f, -1.0f, -0.5f, 1.0f, 1.0f, 1.0f};
// Offset of each field in a Splat2D (which has a gap after conic_c).
__device__ __forceinline__ int splat_field_offset(int field) { return field < kRed ? field : field + 1; }

// Adds splat s's gradient at one pixel to `grad` and steps the pixel's state
// to the splat's front. False when the pixel skipped the splat.
template <bool kWithDepth>
__device__ __forceinline__ bool blend_backward_pixel(PixelState& st, const BlendSplat& s, float px, float py,
                                                     float (&grad)[kFields]) {
  const float dx = px - s.u, dy = py - s.v;
  const Exponent e = blend_exponent(s, dx, dy);
  if (e.p < s.cutoff) return false;
  const float gaussian = exp2_approx(e.p);
  const float raw_alpha = s.opacity * gaussian;
  const float alpha = fminf(float(kMaxAlpha), raw_alpha);
  const float inv_one_minus = __fdividef(1.0f, 1.0f - alpha);
  st.transmittance *= inv_one_minus;  // T in front of this splat
  const float t = st.transmittance, w = alpha * t;
  grad[kRed] = fmaf(w, st.grad_rgb[0], grad[kRed]);
  grad[kGreen] = fmaf(w, st.grad_rgb[1], grad[kGreen]);
  grad[kBlue] = fmaf(w, st.grad_rgb[2], grad[kBlue]);
  const float d_red = s.red - st.behind_rgb[0], d_green = s.green - st.behind_rgb[1];
  const float d_blue = s.blue - st.behind_rgb[2];
  float grad_alpha = d_red * st.grad_rgb[0];
  grad_alpha = fmaf(d_green, st.grad_rgb[1], grad_alpha);
  grad_alpha = fmaf(d_blue, st.grad_rgb[2], grad_alpha);
  if constexpr (kWithDepth) {
    const float d_depth = s.depth - st.behind_depth;
    grad[kDepth] = fmaf(w, st.grad_depth, grad[kDepth]);
    grad_alpha = fmaf(d_depth, st.grad_depth, grad_alpha);
    st.behind_depth = fmaf(alpha, d_depth, st.behind_depth);
  }
  grad_alpha = fmaf(grad_alpha, t, st.final_term * inv_one_minus);
  st.behind_rgb[0] = fmaf(alpha, d_red, st.behind_rgb[0]);
  st.behind_rgb[1] = fmaf(alpha, d_green, st.behind_rgb[1]);
  st.behind_rgb[2] = fmaf(alpha, d_blue, st.behind_rgb[2]);
  if (raw_alpha > float(kMaxAlpha)) return true;  // clamped: no gradient to opacity or shape
  grad[kOpacity] = fmaf(gaussian, grad_alpha, grad[kOpacity]);
  // d loss / d power, power = p ln 2 the natural exponent; its derivatives
  // w.r.t. (u, v) are -ln2 (2a dx + b dy, b dx + 2c dy) and w.r.t. the conic
  // -(½ dx², dx dy, ½ dy²): the constant factors wait for kFieldScale.
  const float grad_power = raw_alpha * grad_alpha;
  grad[kU] = fmaf(grad_power, fmaf(s.a, dx, e.a_dx_b_dy), grad[kU]);
  grad[kV] = fmaf(grad_power, fmaf(s.b, dx, 2.0f * e.c_dy), grad[kV]);
  const float grad_power_dx = grad_power * dx;
  grad[kConicA] = fmaf(grad_power_dx, dx, grad[kConicA]);
  grad[kConicB] = fmaf(grad_power_dx, dy, grad[kConicB]);
  grad[kConicC] = fmaf(grad_power * dy, dy, grad[kConicC]);
  return true;
}

// The field whose warp total warp_reduce_scatter leaves in this lane, or -1.
// Lanes 2i and 2i + 1 hold the same.
__device__ __forceinline__ int reduced_field(unsigned lane) {
  const int index_b = ((lane & 4) ? 2 : 0) + ((lane & 2) ? 1 : 0);
  const int index_a = ((lane & 8) ? 3 : 0) + index_b;
  return index_b < 3 && index_a < 5 ? ((lane & 16) ? 5 : 0) + index_a : -1;
}

// One step of the recursive halving: of the N values a lane carries, the
// lanes with bit `offset` set keep the upper half (entries (N+1)/2 + i, 0
// where N is odd) and the others the lower, each adding its partner's copy of
// the half it keeps.
template <int N>
__device__ __forceinline__ void halve(const float (&in)[N], float (&out)[(N + 1) / 2], int offset) {
  constexpr int kHalf = (N + 1) / 2;
  const bool upper_half = threadIdx.x & offset;
#pragma unroll
  for (int i = 0; i < kHalf; ++i) {
    const float upper = i + kHalf < N ? in[i + kHalf] : 0.0f;
    const float send = upper_half ? in[i] : upper, keep = upper_half ? upper : in[i];
    out[i] = keep + __shfl_xor_sync(kFullWarp, send, offset);
  }
}

// Sums the ten fields over the warp by recursive halving: at each step a
// lane keeps half of the values it carries and swaps the other half with
// its partner, 12 shuffles in all (a shuffle tree per field takes 50).
// Returns the total of field reduced_field(lane).
__device__ __forceinline__ float warp_reduce_scatter(const float (&v)[kFields]) {
  float a[5], b[3], c[2], total[1];
  halve(v, a, 16);  // fields 5·h16 + i
  halve(a, b, 8);   // entries 3·h8 + i of a (the sixth is empty)
  halve(b, c, 4);   // entries 2·h4 + i of b (the fourth is empty)
  halve(c, total, 2);
  return total[0] + __shfl_xor_sync(kFullWarp, total[0], 1);
}

// Each warp blends an 8x8 block of its tile (the squarest of 64 pixels, as in
// the forward pass); lane l takes column l % 8 of the block's rows l / 8 and
// l / 8 + 4. Like the forward pass, each warp walks the list on its own, from
// the last entry its pixels blended. kWithDepth: the loss depends on the
// depth image.
constexpr int kBackwardCols = 8, kBackwardRows = 8;
static_assert(kBackwardCols * kBackwardRows == 32 * kPixelsPerThread && kTileSize % kBackwardCols == 0 &&
                  kBackwardThreads / 32 == (kTileSize / kBackwardCols) * (kTileSize / kBackwardRows),
              "the warps' blocks must tile a tile");

template <bool kWithDepth>
__global__ void __launch_bounds__(kBackwardThreads) render_backward_kernel(RasterInputs<float> in,
                                                                           const Splat2D<float>* splats,
                                                                           TileBins bins, ImageBuffers<float> image,
                                                                           ImageGradients<float> grads,
                                                                           Splat2D<float>* splat_grads) {
  constexpr int kWarps = kBackwardThreads / 32, kBlocksAcross = kTileSize / kBackwardCols;
  constexpr int kRowStep = 32 / kBackwardCols;  // rows between a thread's pixels
  __shared__ BlendSplat batches[kWarps][32];
  __shared__ int32_t batch_ids[kWarps][32];
  const ImageGeometry g = in.geometry;
  const int64_t tile = block_tile(g);
  const int32_t begin = bins.ranges[2 * tile];
  const unsigned lane = threadIdx.x % 32, warp = threadIdx.x / 32;
  BlendSplat* batch = batches[warp];
  int32_t* ids = batch_ids[warp];
  const int32_t block_x0 = int32_t(blockIdx.x) * kTileSize + kBackwardCols * int32_t(warp % kBlocksAcross);
  const int32_t block_y0 = int32_t(blockIdx.y) * kTileSize + kBackwardRows * int32_t(warp / kBlocksAcross);
  const int32_t x = block_x0 + int32_t(lane % kBackwardCols);
  const float px = float(x);
  const float* bg = in.background;

  PixelState st[kPixelsPerThread];
  float py[kPixelsPerThread];
  int32_t last[kPixelsPerThread];
  int32_t thread_last = 0;
#pragma unroll
  for (int p = 0; p < kPixelsPerThread; ++p) {
    const int32_t y = block_y0 + int32_t(lane / kBackwardCols) + kRowStep * p;
    py[p] = float(y);
    float grad_alpha_out = 0.0f, final_transmittance = 0.0f;
    st[p] = {};
    last[p] = 0;
    if (x < g.width && y < g.height) {
      const int64_t pixel = (int64_t(blockIdx.z) * g.height + y) * g.width + x;
      for (int ch = 0; ch < 3; ++ch) st[p].grad_rgb[ch] = grads.rgb[3 * pixel + ch];
      grad_alpha_out = grads.alpha[pixel];
      final_transmittance = image.final_transmittance[pixel];
      if constexpr (kWithDepth)
        st[p].grad_depth =
            expected_depth_backward(grads.depth[pixel], image.depth[pixel], 1.0f - final_transmittance, grad_alpha_out);
      last[p] = image.last[pixel];
    }
    const float background_dot = bg[0] * st[p].grad_rgb[0] + bg[1] * st[p].grad_rgb[1] + bg[2] * st[p].grad_rgb[2];
    st[p].final_term = final_transmittance * (grad_alpha_out - background_dot);
    st[p].transmittance = final_transmittance;
    thread_last = max(thread_last, last[p]);
  }
  const int field = reduced_field(lane);
  const bool writes = field >= 0 && (lane & 1) == 0 && (kWithDepth || field != kDepth);
  const int field_offset = writes ? splat_field_offset(field) : 0;
  const float field_scale = writes ? kFieldScale[field] : 0.0f;
  const int32_t warp_last = int32_t(__reduce_max_sync(kFullWarp, unsigned(thread_last)));

  // Back to front: lane l loads entry stop - 1 - l, so batch[j] is entry
  // stop - 1 - j of the tile.
  for (int32_t stop = begin + warp_last; stop > begin; stop -= 32) {
    const int32_t k = stop - 1 - int32_t(lane);
    bool used = false;
    if (k >= begin) {
      const int32_t id = bins.gaussian_ids[k];
      const Splat2D<float> sp = load_splat(splats + id);
      used = block_may_touch(sp, g, block_x0, block_y0, kBackwardCols, kBackwardRows);
      if (used) {
        batch[lane] = blend_splat(sp);
        ids[lane] = id;
      }
    }
    uint32_t pending = __ballot_sync(kFullWarp, used);
    __syncwarp();
    while (pending) {
      const int32_t j = __ffs(pending) - 1;
      pending &= pending - 1;
      const int32_t index_in_tile = stop - 1 - j - begin;
      const BlendSplat s = batch[j];
      float grad[kFields] = {};
      bool contributed = false;
#pragma unroll
      for (int p = 0; p < kPixelsPerThread; ++p)
        if (index_in_tile < last[p]) contributed |= blend_backward_pixel<kWithDepth>(st[p], s, px, py[p], grad);
      if (!__any_sync(kFullWarp, contributed)) continue;
      const float total = warp_reduce_scatter(grad);
      if (writes) atomicAdd(reinterpret_cast<float*>(&splat_grads[ids[j]]) + field_offset, total * field_scale);
    }
    __syncwarp();  // the batch is read before the next round overwrites it
  }
}

}  // namespace

void render_forward(const RasterInputs<float>& in, const Splat2D<float>* splats, const TileBins& bins,
                    const ImageBuffers<float>& image, cudaStream_t stream) {
  if (in.num_pixels() == 0) return;
  const dim3 grid(in.geometry.tiles_x, in.geometry.tiles_y, in.num_cameras);
  render_forward_kernel<<<grid, kForwardThreads, 0, stream>>>(in, splats, bins, image);
  TEGA_CHECK_LAUNCH(render_forward_kernel);
}

void render_backward(const RasterInputs<float>& in, const Splat2D<float>* splats, const TileBins& bins,
                     const ImageBuffers<float>& image, const ImageGradients<float>& grads,
                     Splat2D<float>* splat_grads, cudaStream_t stream) {
  if (in.num_pixels() == 0) return;
  const dim3 grid(in.geometry.tiles_x, in.geometry.tiles_y, in.num_cameras);
  if (grads.depth) {
    render_backward_kernel<true><<<grid, kBackwardThreads, 0, stream>>>(in, splats, bins, image, grads, splat_grads);
  } else {
    render_backward_kernel<false><<<grid, kBackwardThreads, 0, stream>>>(in, splats, bins, image, grads, splat_grads);
  }
  TEGA_CHECK_LAUNCH(render_backward_kernel);
}

}  // namespace tega::splat::cuda
