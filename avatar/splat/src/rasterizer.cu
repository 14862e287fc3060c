// CUDA kernels of the tile rasterizer. The per-Gaussian and per-pixel math
// comes from gaussian_math.h / pipeline.h, shared with the CPU path.

#include "cuda_rasterizer.h"

#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>

#include <climits>
#include <stdexcept>
#include <string>

namespace tega::splat::cuda {
namespace {

void check(cudaError_t status, const char* what) {
  if (status != cudaSuccess) throw std::runtime_error(std::string("tega splat: ") + what + ": " + cudaGetErrorString(status));
}
#define TEGA_CUDA_CHECK(expr) check((expr), #expr)
#define TEGA_CHECK_LAUNCH(kernel) check(cudaGetLastError(), "launching " #kernel)

constexpr int kThreads = 256;
static_assert(kTileSize * kTileSize == kThreads, "forward blending: one thread per pixel of a tile");
// The backward blending gives each thread two pixels of a tile, so that a
// splat read from shared memory and each warp reduction serve 64 pixels.
constexpr int kRenderThreads = 128;
constexpr int kWarpRows = 4;  // a warp covers a 16 x 4 block of its tile
static_assert(kTileSize * kTileSize == 2 * kRenderThreads, "two pixels per thread");
static_assert(kTileSize * kWarpRows == 64 && kTileSize * kTileSize / 64 == kRenderThreads / 32,
              "warps of 64 pixels tile the tile");
constexpr unsigned kFullWarp = 0xffffffffu;

unsigned grid_for(int64_t n) { return unsigned((n + kThreads - 1) / kThreads); }

// Bits needed to hold values in [0, count).
int bits_for(int64_t count) {
  int bits = 0;
  while (bits < 63 && (int64_t(1) << bits) < count) ++bits;
  return bits;
}

__global__ void project_kernel(RasterInputs<float> in, ProjectedBuffers<float> out) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= in.num_projected()) return;
  const int64_t n = in.num_gaussians;
  Splat2D<float> splat{};
  TileRect rect;
  out.radii[i] = project_one(in, int32_t(i / n), i % n, splat, rect);
  out.splats[i] = splat;
  out.rects[i] = rect;
}

// Key: camera in the high word, depth's bits (positive floats sort as
// integers) in the low word. Culled Gaussians touch no tile; their key is
// irrelevant.
__global__ void depth_keys_kernel(RasterInputs<float> in, ProjectedBuffers<float> projected, uint64_t* keys,
                                  int32_t* ids) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= in.num_projected()) return;
  const uint64_t camera = uint64_t(i / in.num_gaussians);
  const uint32_t depth_bits = projected.radii[i] > 0 ? __float_as_uint(projected.splats[i].depth) : 0xffffffffu;
  keys[i] = (camera << 32) | depth_bits;
  ids[i] = int32_t(i);
}

__global__ void tile_counts_kernel(int64_t count, const int32_t* ids, const TileRect* rects, int64_t* counts) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < count) counts[i] = rects[ids[i]].count();
}

// Writes each Gaussian's slots: the key of each tile of its rectangle that
// its ellipse may touch, or `culled` (past every tile: sorted to the end and
// never read) for the others.
__global__ void emit_intersections_kernel(RasterInputs<float> in, const Splat2D<float>* splats, const TileRect* rects,
                                          DepthOrder order, uint32_t* tile_keys, int32_t* gaussian_ids) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= in.num_projected()) return;
  const int32_t id = order.ids[i];
  const TileRect r = rects[id];
  if (r.count() == 0) return;
  int64_t slot = order.tile_offsets[i] - r.count();
  const ImageGeometry g = in.geometry;
  const uint32_t base = uint32_t(id / in.num_gaussians) * uint32_t(g.tiles_x * g.tiles_y);
  const uint32_t culled = uint32_t(in.num_tiles());
  const Splat2D<float> sp = splats[id];
  const float level = splat_level(sp);
  for (int32_t ty = r.y0; ty < r.y1; ++ty)
    for (int32_t tx = r.x0; tx < r.x1; ++tx, ++slot) {
      tile_keys[slot] = splat_may_touch_tile(sp, level, g, tx, ty) ? base + uint32_t(ty * g.tiles_x + tx) : culled;
      gaussian_ids[slot] = id;
    }
}

__global__ void tile_ranges_kernel(int64_t count, uint32_t culled, const uint32_t* sorted_keys, int32_t* ranges) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= count) return;
  const uint32_t key = sorted_keys[i];
  if (key == culled) return;
  if (i == 0 || sorted_keys[i - 1] != key) ranges[2 * int64_t(key)] = int32_t(i);
  if (i == count - 1 || sorted_keys[i + 1] != key) ranges[2 * int64_t(key) + 1] = int32_t(i + 1);
}

struct TilePixel {
  int64_t tile, pixel;
  int32_t px, py;
  bool inside;
};

__device__ TilePixel tile_pixel(const ImageGeometry& g) {
  TilePixel t;
  const int32_t camera = blockIdx.z;
  t.tile = (int64_t(camera) * g.tiles_y + blockIdx.y) * g.tiles_x + blockIdx.x;
  t.px = int32_t(blockIdx.x) * kTileSize + int32_t(threadIdx.x % kTileSize);
  t.py = int32_t(blockIdx.y) * kTileSize + int32_t(threadIdx.x / kTileSize);
  t.inside = t.px < g.width && t.py < g.height;
  t.pixel = (int64_t(camera) * g.height + t.py) * g.width + t.px;
  return t;
}

// Copies a splat with three 16-byte loads.
__device__ __forceinline__ void copy_splat(Splat2D<float>& dst, const Splat2D<float>& src) {
  const float4* s = reinterpret_cast<const float4*>(&src);
  float4* d = reinterpret_cast<float4*>(&dst);
  d[0] = s[0];
  d[1] = s[1];
  d[2] = s[2];
}

__global__ void __launch_bounds__(kThreads) render_forward_kernel(RasterInputs<float> in,
                                                                  const Splat2D<float>* splats, TileBins bins,
                                                                  ImageBuffers<float> image) {
  __shared__ Splat2D<float> batch[kThreads];
  const ImageGeometry g = in.geometry;
  const TilePixel tp = tile_pixel(g);
  const int32_t begin = bins.ranges[2 * tp.tile], end = bins.ranges[2 * tp.tile + 1];
  PixelAccumulator<float> acc;
  acc.done = !tp.inside;
  const float px = float(tp.px), py = float(tp.py);
  for (int32_t start = begin; start < end; start += kThreads) {
    // Also the barrier that lets this round overwrite the previous batch.
    if (__syncthreads_count(acc.done) == kThreads) break;
    const int32_t k = start + int32_t(threadIdx.x);
    if (k < end) copy_splat(batch[threadIdx.x], splats[bins.gaussian_ids[k]]);
    __syncthreads();
    const int32_t count = min(kThreads, end - start);
    for (int32_t j = 0; j < count && !acc.done; ++j) blend_forward(acc, batch[j], px, py, start - begin + j);
  }
  if (!tp.inside) return;
  const float* bg = in.background;
  for (int ch = 0; ch < 3; ++ch) image.rgb[3 * tp.pixel + ch] = acc.rgb[ch] + acc.transmittance * bg[ch];
  image.alpha[tp.pixel] = 1.0f - acc.transmittance;
  image.depth[tp.pixel] = acc.depth;
  image.final_transmittance[tp.pixel] = acc.transmittance;
  image.last[tp.pixel] = acc.last;
}

// A thread's two pixels: column lane % 16, rows 4w + lane / 16 and two
// below, for warp w.
struct TilePixels {
  int64_t tile;
  int64_t pixel[2];
  float px, py[2];
  bool inside[2];
};

__device__ TilePixels tile_pixels(const ImageGeometry& g) {
  TilePixels t;
  const int32_t camera = blockIdx.z;
  const int32_t lane = int32_t(threadIdx.x % 32), warp = int32_t(threadIdx.x / 32);
  t.tile = (int64_t(camera) * g.tiles_y + blockIdx.y) * g.tiles_x + blockIdx.x;
  const int32_t x = int32_t(blockIdx.x) * kTileSize + lane % kTileSize;
  t.px = float(x);
  for (int k = 0; k < 2; ++k) {
    const int32_t y = int32_t(blockIdx.y) * kTileSize + kWarpRows * warp + lane / kTileSize + 2 * k;
    t.py[k] = float(y);
    t.inside[k] = x < g.width && y < g.height;
    t.pixel[k] = (int64_t(camera) * g.height + y) * g.width + x;
  }
  return t;
}

// Sums the ten gradient fields of a splat over the warp by recursive
// halving: at each step a lane keeps half of the values it carries and
// swaps the other half with its partner, 12 shuffles in all (a shuffle tree
// per field takes 50). On return `total` holds the warp's sum of field
// number `field` (u, v, opacity, depth, conic a, b, c, red, green, blue);
// field is -1 where the lane holds none. Lanes 2i and 2i + 1 hold the same.
__device__ __forceinline__ int warp_reduce_scatter(const Splat2D<float>& grad, float& total) {
  const unsigned lane = threadIdx.x % 32;
  const float v[10] = {grad.u,       grad.v,       grad.opacity, grad.depth, grad.conic_a,
                       grad.conic_b, grad.conic_c, grad.red,     grad.green, grad.blue};
  const bool h16 = lane & 16, h8 = lane & 8, h4 = lane & 4, h2 = lane & 2;
  float a[5];  // fields 5·h16 + i
#pragma unroll
  for (int i = 0; i < 5; ++i) {
    const float send = h16 ? v[i] : v[i + 5], keep = h16 ? v[i + 5] : v[i];
    a[i] = keep + __shfl_xor_sync(kFullWarp, send, 16);
  }
  float b[3];  // entries 3·h8 + i of a (the sixth is empty)
#pragma unroll
  for (int i = 0; i < 3; ++i) {
    const float upper = i + 3 < 5 ? a[i + 3] : 0.0f;
    const float send = h8 ? a[i] : upper, keep = h8 ? upper : a[i];
    b[i] = keep + __shfl_xor_sync(kFullWarp, send, 8);
  }
  float c[2];  // entries 2·h4 + i of b (the fourth is empty)
#pragma unroll
  for (int i = 0; i < 2; ++i) {
    const float upper = i + 2 < 3 ? b[i + 2] : 0.0f;
    const float send = h4 ? b[i] : upper, keep = h4 ? upper : b[i];
    c[i] = keep + __shfl_xor_sync(kFullWarp, send, 4);
  }
  const float send = h2 ? c[0] : c[1], keep = h2 ? c[1] : c[0];
  total = keep + __shfl_xor_sync(kFullWarp, send, 2);
  total += __shfl_xor_sync(kFullWarp, total, 1);
  const int index_b = (h4 ? 2 : 0) + (h2 ? 1 : 0);
  const int index_a = (h8 ? 3 : 0) + index_b;
  return index_b < 3 && index_a < 5 ? (h16 ? 5 : 0) + index_a : -1;
}

// Offset of gradient field number `field` (warp_reduce_scatter's order) in a Splat2D.
__device__ __forceinline__ int splat_field_offset(int field) { return field < 7 ? field : field + 1; }

__global__ void __launch_bounds__(kRenderThreads) render_backward_kernel(RasterInputs<float> in,
                                                                         const Splat2D<float>* splats, TileBins bins,
                                                                         ImageBuffers<float> image,
                                                                         ImageGradients<float> grads,
                                                                         Splat2D<float>* splat_grads) {
  __shared__ Splat2D<float> batch[kRenderThreads];
  __shared__ int32_t batch_ids[kRenderThreads];
  __shared__ int32_t block_last;
  const ImageGeometry g = in.geometry;
  const TilePixels tp = tile_pixels(g);
  const int32_t begin = bins.ranges[2 * tp.tile];
  const float* bg = in.background;

  PixelBackward<float> st[2];
  int32_t last[2] = {0, 0};
  for (int p = 0; p < 2; ++p) {
    if (!tp.inside[p]) continue;
    const int64_t pixel = tp.pixel[p];
    for (int ch = 0; ch < 3; ++ch) st[p].grad_rgb[ch] = grads.rgb[3 * pixel + ch];
    st[p].grad_alpha_out = grads.alpha[pixel];
    st[p].grad_depth = grads.depth[pixel];
    st[p].final_transmittance = image.final_transmittance[pixel];
    st[p].transmittance = st[p].final_transmittance;
    st[p].background_dot = bg[0] * st[p].grad_rgb[0] + bg[1] * st[p].grad_rgb[1] + bg[2] * st[p].grad_rgb[2];
    last[p] = image.last[pixel];
  }
  const int32_t warp_last = __reduce_max_sync(kFullWarp, unsigned(max(last[0], last[1])));
  if (threadIdx.x == 0) block_last = 0;
  __syncthreads();
  if (threadIdx.x % 32 == 0) atomicMax(&block_last, warp_last);
  __syncthreads();

  // Back to front, in batches loaded from the end of the tile's run.
  for (int32_t stop = begin + block_last; stop > begin; stop -= kRenderThreads) {
    const int32_t start = max(begin, stop - kRenderThreads);
    __syncthreads();
    const int32_t k = stop - 1 - int32_t(threadIdx.x);
    if (k >= start) {
      const int32_t id = bins.gaussian_ids[k];
      batch_ids[threadIdx.x] = id;
      copy_splat(batch[threadIdx.x], splats[id]);
    }
    __syncthreads();
    const int32_t count = stop - start;
    // batch[j] is entry stop - 1 - j - begin of the tile; the warp's pixels
    // blended only entries below warp_last.
    for (int32_t j = max(0, stop - begin - warp_last); j < count; ++j) {
      const int32_t index_in_tile = stop - 1 - j - begin;
      Splat2D<float> sp;
      copy_splat(sp, batch[j]);
      Splat2D<float> local{};
      bool contributed = false;
      if (index_in_tile < last[0]) contributed |= blend_backward(st[0], sp, tp.px, tp.py[0], local);
      if (index_in_tile < last[1]) contributed |= blend_backward(st[1], sp, tp.px, tp.py[1], local);
      if (!__any_sync(kFullWarp, contributed)) continue;
      float total;
      const int field = warp_reduce_scatter(local, total);
      if (field >= 0 && (threadIdx.x & 1) == 0)
        atomicAdd(reinterpret_cast<float*>(&splat_grads[batch_ids[j]]) + splat_field_offset(field), total);
    }
  }
}

__global__ void project_backward_kernel(RasterInputs<float> in, const int32_t* radii,
                                        const Splat2D<float>* splat_grads, InputGradients<float> out) {
  const int64_t g = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (g < in.num_gaussians) project_backward_one(in, radii, splat_grads, g, out);
}

}  // namespace

void project(const RasterInputs<float>& in, const ProjectedBuffers<float>& out, cudaStream_t stream) {
  if (in.num_projected() == 0) return;
  project_kernel<<<grid_for(in.num_projected()), kThreads, 0, stream>>>(in, out);
  TEGA_CHECK_LAUNCH(project_kernel);
}

DepthOrder sort_by_depth(const RasterInputs<float>& in, const ProjectedBuffers<float>& projected,
                         Workspace& workspace, cudaStream_t stream) {
  DepthOrder order;
  const int64_t count = in.num_projected();
  if (count == 0) return order;
  if (count > INT_MAX) throw std::runtime_error("tega splat: more than 2^31 projected Gaussians");
  auto* keys = static_cast<uint64_t*>(workspace.allocate(2 * count * sizeof(uint64_t)));
  auto* ids = static_cast<int32_t*>(workspace.allocate(2 * count * sizeof(int32_t)));
  depth_keys_kernel<<<grid_for(count), kThreads, 0, stream>>>(in, projected, keys, ids);
  TEGA_CHECK_LAUNCH(depth_keys_kernel);

  const int end_bit = 32 + bits_for(in.num_cameras);
  std::size_t sort_bytes = 0;
  TEGA_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, sort_bytes, keys, keys + count, ids, ids + count,
                                                  int(count), 0, end_bit, stream));
  void* sort_temp = workspace.allocate(sort_bytes);
  TEGA_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(sort_temp, sort_bytes, keys, keys + count, ids, ids + count,
                                                  int(count), 0, end_bit, stream));
  const int32_t* sorted_ids = ids + count;

  auto* counts = static_cast<int64_t*>(workspace.allocate(2 * count * sizeof(int64_t)));
  tile_counts_kernel<<<grid_for(count), kThreads, 0, stream>>>(count, sorted_ids, projected.rects, counts);
  TEGA_CHECK_LAUNCH(tile_counts_kernel);
  int64_t* offsets = counts + count;
  std::size_t scan_bytes = 0;
  TEGA_CUDA_CHECK(cub::DeviceScan::InclusiveSum(nullptr, scan_bytes, counts, offsets, int(count), stream));
  void* scan_temp = workspace.allocate(scan_bytes);
  TEGA_CUDA_CHECK(cub::DeviceScan::InclusiveSum(scan_temp, scan_bytes, counts, offsets, int(count), stream));

  TEGA_CUDA_CHECK(cudaMemcpyAsync(&order.total, offsets + count - 1, sizeof(int64_t), cudaMemcpyDeviceToHost, stream));
  TEGA_CUDA_CHECK(cudaStreamSynchronize(stream));
  order.ids = sorted_ids;
  order.tile_offsets = offsets;
  return order;
}

void bin(const RasterInputs<float>& in, const ProjectedBuffers<float>& projected, const DepthOrder& order,
         int32_t* gaussian_ids, int32_t* ranges, Workspace& workspace, cudaStream_t stream) {
  const int64_t num_tiles = in.num_tiles();
  TEGA_CUDA_CHECK(cudaMemsetAsync(ranges, 0, 2 * num_tiles * sizeof(int32_t), stream));
  const int64_t total = order.total;
  if (total == 0) return;
  if (total > INT_MAX) throw std::runtime_error("tega splat: more than 2^31 tile-Gaussian intersections");
  auto* keys = static_cast<uint32_t*>(workspace.allocate(2 * total * sizeof(uint32_t)));
  auto* unsorted_ids = static_cast<int32_t*>(workspace.allocate(total * sizeof(int32_t)));
  emit_intersections_kernel<<<grid_for(in.num_projected()), kThreads, 0, stream>>>(in, projected.splats,
                                                                                  projected.rects, order, keys,
                                                                                  unsorted_ids);
  TEGA_CHECK_LAUNCH(emit_intersections_kernel);

  // Stable, so the depth order survives inside each tile; only the tile
  // bits (and the culled key, num_tiles) are sorted.
  const int end_bit = bits_for(num_tiles + 1);
  std::size_t sort_bytes = 0;
  TEGA_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, sort_bytes, keys, keys + total, unsorted_ids,
                                                  gaussian_ids, int(total), 0, end_bit, stream));
  void* sort_temp = workspace.allocate(sort_bytes);
  TEGA_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(sort_temp, sort_bytes, keys, keys + total, unsorted_ids,
                                                  gaussian_ids, int(total), 0, end_bit, stream));
  tile_ranges_kernel<<<grid_for(total), kThreads, 0, stream>>>(total, uint32_t(num_tiles), keys + total, ranges);
  TEGA_CHECK_LAUNCH(tile_ranges_kernel);
}

void render_forward(const RasterInputs<float>& in, const Splat2D<float>* splats, const TileBins& bins,
                    const ImageBuffers<float>& image, cudaStream_t stream) {
  if (in.num_pixels() == 0) return;
  const dim3 grid(in.geometry.tiles_x, in.geometry.tiles_y, in.num_cameras);
  render_forward_kernel<<<grid, kThreads, 0, stream>>>(in, splats, bins, image);
  TEGA_CHECK_LAUNCH(render_forward_kernel);
}

void render_backward(const RasterInputs<float>& in, const Splat2D<float>* splats, const TileBins& bins,
                     const ImageBuffers<float>& image, const ImageGradients<float>& grads,
                     Splat2D<float>* splat_grads, cudaStream_t stream) {
  if (in.num_pixels() == 0) return;
  const dim3 grid(in.geometry.tiles_x, in.geometry.tiles_y, in.num_cameras);
  render_backward_kernel<<<grid, kRenderThreads, 0, stream>>>(in, splats, bins, image, grads, splat_grads);
  TEGA_CHECK_LAUNCH(render_backward_kernel);
}

void project_backward(const RasterInputs<float>& in, const int32_t* radii, const Splat2D<float>* splat_grads,
                      const InputGradients<float>& out, cudaStream_t stream) {
  if (in.num_gaussians == 0) return;
  project_backward_kernel<<<grid_for(in.num_gaussians), kThreads, 0, stream>>>(in, radii, splat_grads, out);
  TEGA_CHECK_LAUNCH(project_backward_kernel);
}

}  // namespace tega::splat::cuda
