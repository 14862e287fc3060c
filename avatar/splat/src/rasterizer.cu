// CUDA kernels of the tile rasterizer's per-Gaussian stages (projection,
// depth order, binning, projection backward); the blending is in
// blending.cu. The math comes from gaussian_math.h / pipeline.h, shared with
// the CPU path.

#include "cuda_check.h"
#include "cuda_rasterizer.h"

#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>

#include <climits>
#include <stdexcept>

namespace tega::splat::cuda {
namespace {

constexpr int kThreads = 256;
unsigned grid_for(int64_t n, int threads = kThreads) { return unsigned((n + threads - 1) / threads); }
// project_backward_kernel needs over 100 registers a thread (the projection's
// and the SH's derivatives): small blocks waste none of a multiprocessor's
// register file, and nine of them (18 warps) fit its shared memory.
constexpr int kProjectBackwardThreads = 64;
constexpr int kProjectBackwardBlocks = 9;

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

__global__ void tile_ranges_kernel(int64_t count, uint32_t culled, const uint32_t* sorted_keys, int32_t* ranges) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= count) return;
  const uint32_t key = sorted_keys[i];
  if (key == culled) return;
  if (i == 0 || sorted_keys[i - 1] != key) ranges[2 * int64_t(key)] = int32_t(i);
  if (i == count - 1 || sorted_keys[i + 1] != key) ranges[2 * int64_t(key) + 1] = int32_t(i + 1);
}

// SH rows go through shared memory: a thread's row is 3K consecutive floats,
// so reading and writing them in place would touch a cache line per thread
// and value. The block moves its rows with coalesced accesses instead; rows
// are padded to an odd stride so that the threads' accesses hit distinct banks.
__global__ void __launch_bounds__(kProjectBackwardThreads, kProjectBackwardBlocks)
    project_backward_kernel(RasterInputs<float> in, const int32_t* radii, const Splat2D<float>* splat_grads,
                            InputGradients<float> out) {
  extern __shared__ float sh_rows[];  // [2][blockDim.x][stride]: coefficients, then their gradients
  const int64_t first = int64_t(blockIdx.x) * blockDim.x, g = first + threadIdx.x;
  const int32_t row = 3 * in.sh_coefficients, stride = row | 1;
  const int32_t count = int32_t(min(int64_t(blockDim.x), in.num_gaussians - first)) * row;
  float* sh = sh_rows + threadIdx.x * stride;
  float* grad_sh = sh + blockDim.x * stride;
  for (int32_t e = threadIdx.x; e < count; e += blockDim.x)
    sh_rows[e / row * stride + e % row] = in.colors[first * row + e];
  __syncthreads();
  if (g < in.num_gaussians) project_backward_one(in, radii, splat_grads, g, sh, grad_sh, out);
  __syncthreads();
  for (int32_t e = threadIdx.x; e < count; e += blockDim.x)
    out.colors[first * row + e] = sh_rows[(blockDim.x + e / row) * stride + e % row];
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

void project_backward(const RasterInputs<float>& in, const int32_t* radii, const Splat2D<float>* splat_grads,
                      const InputGradients<float>& out, cudaStream_t stream) {
  if (in.num_gaussians == 0) return;
  const int32_t sh_stride = in.sh_coefficients > 0 ? (3 * in.sh_coefficients) | 1 : 0;
  const std::size_t shared_bytes = 2 * kProjectBackwardThreads * sh_stride * sizeof(float);
  project_backward_kernel<<<grid_for(in.num_gaussians, kProjectBackwardThreads), kProjectBackwardThreads,
                            shared_bytes, stream>>>(in, radii, splat_grads, out);
  TEGA_CHECK_LAUNCH(project_backward_kernel);
}

}  // namespace tega::splat::cuda
