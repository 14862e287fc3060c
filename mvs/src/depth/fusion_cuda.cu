// The CUDA path of fusion: one thread per fused pixel (fusion_math.h), then a
// warp per row packing the row's points in order. Every view's depth, normals
// and colours are uploaded once; each reference view's points come back packed.
//
// It runs beside the next frame's depth maps on the same GPU (frame_pipeline.h):
// its own stream and stream-ordered allocations, so that neither waits for the other.

#include <cuda_runtime_api.h>

#include <cstdint>
#include <vector>

#include "fusion_cuda.h"
#include "tega/core/cuda_check.h"
#include "tega/core/error.h"
#include "tega/mvs/patch_match.h"

namespace tega::mvs::detail {
namespace {

constexpr const char* kOp = "mvs fusion";

class Stream {
 public:
  Stream() { check_cuda(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking), kOp, "create a stream"); }
  ~Stream() { cudaStreamDestroy(stream_); }
  Stream(const Stream&) = delete;
  Stream& operator=(const Stream&) = delete;
  operator cudaStream_t() const { return stream_; }
  void synchronize() const { check_cuda(cudaStreamSynchronize(stream_), kOp, "synchronize"); }

 private:
  cudaStream_t stream_ = nullptr;
};

// Freed on the stream (cudaFreeAsync): cudaFree would wait for the whole GPU.
template <class T>
class StreamBuffer {
 public:
  StreamBuffer(size_t count, const Stream& stream) : stream_(stream), count_(count) {
    if (count_ > 0) check_cuda(cudaMallocAsync(reinterpret_cast<void**>(&data_), bytes(), stream_), kOp, "allocate");
  }
  ~StreamBuffer() {
    if (data_) cudaFreeAsync(data_, stream_);
  }
  StreamBuffer(const StreamBuffer&) = delete;
  StreamBuffer& operator=(const StreamBuffer&) = delete;
  StreamBuffer(StreamBuffer&& other) noexcept : stream_(other.stream_), count_(other.count_), data_(other.data_) {
    other.data_ = nullptr;
  }

  T* data() const { return data_; }
  size_t bytes() const { return count_ * sizeof(T); }
  void upload(const T* host) {
    check_cuda(cudaMemcpyAsync(data_, host, bytes(), cudaMemcpyHostToDevice, stream_), kOp, "upload");
  }
  void zero() { check_cuda(cudaMemsetAsync(data_, 0, bytes(), stream_), kOp, "clear"); }
  void download(T* host, size_t count) const {
    check_cuda(cudaMemcpyAsync(host, data_, count * sizeof(T), cudaMemcpyDeviceToHost, stream_), kOp, "download");
  }

 private:
  cudaStream_t stream_;
  size_t count_;
  T* data_ = nullptr;
};

struct Grid {
  int columns, rows;  // the fused pixels of a view: every step-th of every step-th row
};

__global__ void fuse_kernel(const FusionView* views, int view_count, int reference, FusionParameters p, int step,
                            Grid grid, FusedSample* samples, uint8_t* kept, int* row_counts) {
  const int column = blockIdx.x * blockDim.x + threadIdx.x, row = blockIdx.y * blockDim.y + threadIdx.y;
  if (column >= grid.columns || row >= grid.rows) return;
  const long long slot = (long long)row * grid.columns + column;
  const bool fused = fuse_pixel(views, view_count, reference, column * step, row * step, p, samples[slot]);
  kept[slot] = fused;
  if (fused) atomicAdd(&row_counts[row], 1);
}

// One warp per row: each 32 columns' kept samples go to the row's next places, in column order.
__global__ void pack_kernel(const FusedSample* samples, const uint8_t* kept, const int* row_offsets, Grid grid,
                            FusedSample* packed) {
  const int row = blockIdx.x * blockDim.y + threadIdx.y, lane = threadIdx.x;
  if (row >= grid.rows) return;
  int next = row_offsets[row];
  for (int first = 0; first < grid.columns; first += 32) {
    const int column = first + lane;
    const long long slot = (long long)row * grid.columns + column;
    const bool keep = column < grid.columns && kept[slot];
    const unsigned ballot = __ballot_sync(0xffffffffu, keep);
    if (keep) packed[next + __popc(ballot & ((1u << lane) - 1))] = samples[slot];
    next += __popc(ballot);
  }
}

// One view's maps and colours on the GPU.
struct DeviceView {
  StreamBuffer<float> depth, normals, grey;
  StreamBuffer<uint8_t> colour;
};

}  // namespace

std::vector<FusedSample> fuse_pixels_cuda(const std::vector<FusionView>& views, const FusionParameters& parameters,
                                          int pixel_step) {
  if (!cuda_device_available()) throw Error("mvs: no CUDA device is available for fusion; use --device cpu");
  const Stream stream;
  std::vector<DeviceView> uploaded;
  uploaded.reserve(views.size());
  std::vector<FusionView> on_device = views;
  for (size_t v = 0; v < views.size(); ++v) {
    const FusionView& view = views[v];
    const size_t pixels = size_t(view.width) * view.height;
    DeviceView d{StreamBuffer<float>(pixels, stream), StreamBuffer<float>(3 * pixels, stream),
                 StreamBuffer<float>(view.colour ? 0 : pixels, stream),
                 StreamBuffer<uint8_t>(view.colour ? 3 * pixels : 0, stream)};
    d.depth.upload(view.depth);
    d.normals.upload(view.normals);
    if (view.colour) {
      d.colour.upload(view.colour);
    } else {
      d.grey.upload(view.grey);
    }
    on_device[v].depth = d.depth.data();
    on_device[v].normals = d.normals.data();
    on_device[v].colour = view.colour ? d.colour.data() : nullptr;
    on_device[v].grey = view.colour ? nullptr : d.grey.data();
    uploaded.push_back(std::move(d));
  }
  StreamBuffer<FusionView> device_views(on_device.size(), stream);
  device_views.upload(on_device.data());

  std::vector<FusedSample> points;
  for (size_t r = 0; r < views.size(); ++r) {
    const Grid grid{(views[r].width + pixel_step - 1) / pixel_step, (views[r].height + pixel_step - 1) / pixel_step};
    const size_t slots = size_t(grid.columns) * grid.rows;
    StreamBuffer<FusedSample> samples(slots, stream);
    StreamBuffer<uint8_t> kept(slots, stream);
    StreamBuffer<int> row_counts(size_t(grid.rows), stream);
    row_counts.zero();
    const dim3 block(32, 8), blocks((grid.columns + 31) / 32, (grid.rows + 7) / 8);
    fuse_kernel<<<blocks, block, 0, stream>>>(device_views.data(), int(views.size()), int(r), parameters, pixel_step,
                                              grid, samples.data(), kept.data(), row_counts.data());
    check_launch(kOp, "fuse_kernel");

    std::vector<int> offsets(size_t(grid.rows));
    row_counts.download(offsets.data(), offsets.size());
    stream.synchronize();
    int total = 0;
    for (int& offset : offsets) {
      const int count = offset;
      offset = total;
      total += count;
    }
    if (total == 0) continue;
    StreamBuffer<int> row_offsets(offsets.size(), stream);
    row_offsets.upload(offsets.data());
    StreamBuffer<FusedSample> packed(size_t(total), stream);
    const dim3 warps(32, 8);
    pack_kernel<<<(grid.rows + 7) / 8, warps, 0, stream>>>(samples.data(), kept.data(), row_offsets.data(), grid,
                                                            packed.data());
    check_launch(kOp, "pack_kernel");
    const size_t before = points.size();
    points.resize(before + size_t(total));
    packed.download(points.data() + before, size_t(total));
    stream.synchronize();  // `offsets` and `points` are read by the copies until here
  }
  return points;
}

}  // namespace tega::mvs::detail
