// CUDA kernels of the tile rasterizer's per-Gaussian stages (projection,
// depth order, binning, projection backward); the blending is in
// blending.cu. The math comes from gaussian_math.h / pipeline.h, shared with
// the CPU path.

#include "cuda_check.h"
#include "cuda_rasterizer.h"

#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>
#include <thrust/iterator/transform_iterator.h>

#include <algorithm>
#include <climits>
#include <stdexcept>

namespace tega::splat::cuda {
namespace {

constexpr int kThreads = 256;
unsigned grid_for(int64_t n, int threads = kThreads) { return unsigned((n + threads - 1) / threads); }
constexpr int kProjectBackwardThreads = 128;

// Bits needed to hold values in [0, count).
int bits_for(int64_t count) {
  int bits = 0;
  while (bits < 63 && (int64_t(1) << bits) < count) ++bits;
  return bits;
}

// Also writes the depth sort's key: the camera in the high word, the depth's
// bits (positive floats sort as integers) in the low word; culled Gaussians
// touch no tile, their key is irrelevant.
__global__ void project_kernel(RasterInputs<float> in, ProjectedBuffers<float> out, DepthKeys depth_keys) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= in.num_projected()) return;
  const int64_t n = in.num_gaussians, g = i % n;
  const int32_t camera = int32_t(i / n);
  Splat2D<float> splat{};
  TileRect rect;
  ColorJacobian<float> jacobian;
  const float* sh_row = in.colors + int64_t(3) * in.sh_coefficients * g;
  const int32_t radius = project_one(in, camera, g, sh_row, splat, rect, &jacobian);
  out.radii[i] = radius;
  out.splats[i] = splat;
  out.rects[i] = rect;
  if (out.color_jacobians && radius > 0) out.color_jacobians[i] = jacobian;  // the backward pass reads no other
  depth_keys.keys[i] = (uint64_t(camera) << 32) | (radius > 0 ? __float_as_uint(splat.depth) : 0xffffffffu);
  depth_keys.ids[i] = int32_t(i);
}

// The number of tiles of a projected Gaussian's rectangle, read by the scan
// of sort_by_depth through an iterator (no array of counts).
struct RectTileCount {
  const TileRect* rects;
  __device__ int64_t operator()(int32_t id) const { return rects[id].count(); }
};

// Writes each Gaussian's slots: the key of each tile of its rectangle that
// its ellipse may touch, or `culled` (past every tile: sorted to the end and
// never read) for the others. A warp takes 32 consecutive Gaussians of the
// depth order, whose slots are consecutive too, and writes them a slot per
// lane: the stores are coalesced and a Gaussian with many tiles does not
// hold up its warp (one thread per Gaussian took four times as long).
__global__ void __launch_bounds__(kThreads) emit_intersections_kernel(RasterInputs<float> in,
                                                                      const Splat2D<float>* splats,
                                                                      const TileRect* rects, DepthOrder order,
                                                                      uint32_t* tile_keys, int32_t* gaussian_ids) {
  struct Owner {
    Splat2D<float> splat;
    TileRect rect;
    int64_t first_slot;
    int32_t id;
  };
  __shared__ Owner owners[kThreads];
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  const unsigned lane = threadIdx.x % 32;
  Owner* warp_owners = owners + (threadIdx.x - lane);
  const int64_t count = in.num_projected();
  if (i - lane >= count) return;  // the whole warp is past the end
  int64_t end_slot = 0;
  Owner& mine = warp_owners[lane];
  if (i < count) {
    mine.id = order.ids[i];
    mine.rect = rects[mine.id];
    end_slot = order.tile_offsets[i];
    mine.first_slot = end_slot - mine.rect.count();
    if (mine.rect.count() > 0) mine.splat = splats[mine.id];
  } else {
    mine.first_slot = LLONG_MAX;  // never an owner
  }
  int64_t warp_end = end_slot;  // the offsets grow along the order: the last valid lane holds the end
  for (int offset = 16; offset > 0; offset /= 2)
    warp_end = max(warp_end, __shfl_xor_sync(0xffffffffu, warp_end, offset));
  const int64_t warp_begin = __shfl_sync(0xffffffffu, mine.first_slot, 0);
  __syncwarp();

  const ImageGeometry g = in.geometry;
  const uint32_t tiles_per_camera = uint32_t(g.tiles_x * g.tiles_y), culled = uint32_t(in.num_tiles());
  for (int64_t slot = warp_begin + lane; slot < warp_end; slot += 32) {
    // The owner is the last lane whose first slot is at or before this one
    // (lanes with no tiles share their successor's first slot).
    int owner = 0;
    for (int step = 16; step > 0; step /= 2)
      if (warp_owners[owner + step].first_slot <= slot) owner += step;
    const Owner& o = warp_owners[owner];
    const int32_t local = int32_t(slot - o.first_slot), width = o.rect.x1 - o.rect.x0;
    const int32_t ty = o.rect.y0 + local / width, tx = o.rect.x0 + local % width;
    const bool touches = splat_may_touch_tile(o.splat, splat_level(o.splat), g, tx, ty);
    const uint32_t camera = uint32_t(o.id / in.num_gaussians);
    tile_keys[slot] = touches ? camera * tiles_per_camera + uint32_t(ty * g.tiles_x + tx) : culled;
    gaussian_ids[slot] = o.id;
  }
}

// Tile t's run in the tile-sorted keys begins at the first key >= t: a
// binary search per tile boundary (a few tens of thousands of searches)
// rather than a pass over tens of millions of keys. Boundary num_tiles is
// the first culled key, the end of the last tile.
__global__ void tile_ranges_kernel(int64_t num_tiles, int64_t count, const uint32_t* sorted_keys, int32_t* ranges) {
  const int64_t tile = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (tile > num_tiles) return;
  int64_t low = 0, high = count;
  while (low < high) {
    const int64_t middle = (low + high) / 2;
    if (sorted_keys[middle] < uint64_t(tile)) {
      low = middle + 1;
    } else {
      high = middle;
    }
  }
  if (tile < num_tiles) ranges[2 * tile] = int32_t(low);
  if (tile > 0) ranges[2 * tile - 1] = int32_t(low);
}

// A thread per Gaussian. Its SH gradient row (3K consecutive floats) leaves
// through shared memory: stored in place, each store instruction of a warp
// would touch 32 cache lines. A warp stages its 32 rows instead and stores
// them with coalesced accesses; rows are padded to an odd stride so that the
// lanes' writes hit distinct banks.
__global__ void __launch_bounds__(kProjectBackwardThreads)
    project_backward_kernel(RasterInputs<float> in, const int32_t* radii, const Splat2D<float>* splat_grads,
                            const ColorJacobian<float>* color_jacobians, InputGradients<float> out) {
  extern __shared__ float staged_rows[];  // [blockDim.x][stride]
  const int32_t lane = int32_t(threadIdx.x % 32);
  const int64_t g = int64_t(blockIdx.x) * blockDim.x + threadIdx.x, warp_first = g - lane;
  if (warp_first >= in.num_gaussians) return;
  const int32_t row = 3 * in.sh_coefficients, stride = row | 1;
  float* warp_rows = staged_rows + (threadIdx.x - lane) * stride;
  if (g < in.num_gaussians)
    project_backward_one(in, radii, splat_grads, color_jacobians, g, warp_rows + lane * stride, out);
  if (row == 0) return;
  __syncwarp();
  const int32_t count = int32_t(min(int64_t(32), in.num_gaussians - warp_first)) * row;
  float* dst = out.colors + warp_first * row;
  int32_t r = lane / row, col = lane % row;  // element e of the warp's rows is (e / row, e % row)
  for (int32_t e = lane; e < count; e += 32) {
    dst[e] = warp_rows[r * stride + col];
    for (col += 32; col >= row; col -= row) ++r;
  }
}

// A grid-stride sum: per thread, then per warp and block, then one atomic
// per block and channel.
__global__ void __launch_bounds__(kThreads) background_backward_kernel(int64_t pixels, const float* final_transmittance,
                                                                       const float* grad_rgb, float* grad_background) {
  float sum[3] = {0.0f, 0.0f, 0.0f};
  for (int64_t p = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; p < pixels; p += int64_t(gridDim.x) * blockDim.x) {
    const float t = final_transmittance[p];
    for (int ch = 0; ch < 3; ++ch) sum[ch] = fmaf(t, grad_rgb[3 * p + ch], sum[ch]);
  }
  __shared__ float warp_sums[kThreads / 32][3];
  const unsigned lane = threadIdx.x % 32, warp = threadIdx.x / 32;
  for (int ch = 0; ch < 3; ++ch) {
    for (int offset = 16; offset > 0; offset /= 2) sum[ch] += __shfl_xor_sync(0xffffffffu, sum[ch], offset);
    if (lane == 0) warp_sums[warp][ch] = sum[ch];
  }
  __syncthreads();
  if (threadIdx.x < 3) {
    float total = 0.0f;
    for (int w = 0; w < kThreads / 32; ++w) total += warp_sums[w][threadIdx.x];
    atomicAdd(grad_background + threadIdx.x, total);
  }
}

}  // namespace

DepthKeys project(const RasterInputs<float>& in, const ProjectedBuffers<float>& out, Workspace& workspace,
                  cudaStream_t stream) {
  const int64_t count = in.num_projected();
  if (count == 0) return {};
  if (count > INT_MAX) throw std::runtime_error("tega splat: more than 2^31 projected Gaussians");
  const DepthKeys keys{static_cast<uint64_t*>(workspace.allocate(2 * count * sizeof(uint64_t))),
                       static_cast<int32_t*>(workspace.allocate(2 * count * sizeof(int32_t)))};
  project_kernel<<<grid_for(count), kThreads, 0, stream>>>(in, out, keys);
  TEGA_CHECK_LAUNCH(project_kernel);
  return keys;
}

DepthOrder sort_by_depth(const RasterInputs<float>& in, const ProjectedBuffers<float>& projected,
                         const DepthKeys& depth_keys, Workspace& workspace, cudaStream_t stream) {
  DepthOrder order;
  const int64_t count = in.num_projected();
  if (count == 0) return order;
  uint64_t* keys = depth_keys.keys;
  int32_t* ids = depth_keys.ids;
  const int end_bit = 32 + bits_for(in.num_cameras);
  std::size_t sort_bytes = 0;
  TEGA_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, sort_bytes, keys, keys + count, ids, ids + count,
                                                  int(count), 0, end_bit, stream));
  void* sort_temp = workspace.allocate(sort_bytes);
  TEGA_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(sort_temp, sort_bytes, keys, keys + count, ids, ids + count,
                                                  int(count), 0, end_bit, stream));
  const int32_t* sorted_ids = ids + count;

  const auto counts = thrust::make_transform_iterator(sorted_ids, RectTileCount{projected.rects});
  auto* offsets = static_cast<int64_t*>(workspace.allocate(count * sizeof(int64_t)));
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
  const int64_t total = order.total;
  if (total == 0) {
    TEGA_CUDA_CHECK(cudaMemsetAsync(ranges, 0, 2 * num_tiles * sizeof(int32_t), stream));
    return;
  }
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
  tile_ranges_kernel<<<grid_for(num_tiles + 1), kThreads, 0, stream>>>(num_tiles, total, keys + total, ranges);
  TEGA_CHECK_LAUNCH(tile_ranges_kernel);
}

void project_backward(const RasterInputs<float>& in, const int32_t* radii, const Splat2D<float>* splat_grads,
                      const ColorJacobian<float>* color_jacobians, const InputGradients<float>& out,
                      cudaStream_t stream) {
  if (in.num_gaussians == 0) return;
  const int32_t sh_stride = in.sh_coefficients > 0 ? (3 * in.sh_coefficients) | 1 : 0;
  const std::size_t shared_bytes = kProjectBackwardThreads * sh_stride * sizeof(float);
  project_backward_kernel<<<grid_for(in.num_gaussians, kProjectBackwardThreads), kProjectBackwardThreads,
                            shared_bytes, stream>>>(in, radii, splat_grads, color_jacobians, out);
  TEGA_CHECK_LAUNCH(project_backward_kernel);
}

void background_backward(const RasterInputs<float>& in, const float* final_transmittance, const float* grad_rgb,
                         float* grad_background, cudaStream_t stream) {
  const int64_t pixels = in.num_pixels();
  if (pixels == 0) return;
  constexpr unsigned kMaxBlocks = 1024;  // a few per multiprocessor; each then adds many pixels
  background_backward_kernel<<<std::min(grid_for(pixels), kMaxBlocks), kThreads, 0, stream>>>(
      pixels, final_transmittance, grad_rgb, grad_background);
  TEGA_CHECK_LAUNCH(background_backward_kernel);
}

}  // namespace tega::splat::cuda
