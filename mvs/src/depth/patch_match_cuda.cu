// The CUDA path: one thread per pixel of a colour, the per-pixel math of the
// CPU path (patch_match_math.h). Images of every view stay on the GPU for the
// whole call; depth maps of a geometric pass's sources are uploaded per view.

#include <cuda_runtime_api.h>

#include <memory>
#include <string>

#include "patch_match_backend.h"
#include "tega/core/cuda_check.h"
#include "tega/core/error.h"

namespace tega::mvs {

bool cuda_device_available() {
  int count = 0;
  // cudaFree(nullptr) creates the context: a GPU that cannot run kernels is not available.
  return cudaGetDeviceCount(&count) == cudaSuccess && count > 0 && cudaFree(nullptr) == cudaSuccess;
}

namespace detail {
namespace {

constexpr const char* kOp = "mvs patch match";

struct Sources {
  SourceView view[kMaxSources];
};

__global__ void initialise_kernel(ReferenceView ref, Sources sources, Parameters p, PixelStates s) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= ref.image.width || y >= ref.image.height) return;
  initialise_pixel(ref, sources.view, p, s, x, y);
}

__global__ void sweep_kernel(ReferenceView ref, Sources sources, Parameters p, PixelStates s, int colour) {
  const int half = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
  const int x = 2 * half + ((y + colour) & 1);
  if (x >= ref.image.width || y >= ref.image.height) return;
  update_pixel(ref, sources.view, p, s, x, y);
}

template <class T>
struct DeviceArray {
  T* data = nullptr;
  size_t size = 0;
  DeviceArray() = default;
  explicit DeviceArray(size_t n) : size(n) { check_cuda(cudaMalloc(&data, n * sizeof(T)), kOp, "cudaMalloc"); }
  DeviceArray(const DeviceArray&) = delete;
  DeviceArray& operator=(const DeviceArray&) = delete;
  DeviceArray(DeviceArray&& o) noexcept : data(o.data), size(o.size) { o.data = nullptr; }
  ~DeviceArray() { cudaFree(data); }
  void upload(const T* host) {
    check_cuda(cudaMemcpy(data, host, size * sizeof(T), cudaMemcpyHostToDevice), kOp, "upload");
  }
  void download(T* host) const {
    check_cuda(cudaMemcpy(host, data, size * sizeof(T), cudaMemcpyDeviceToHost), kOp, "download");
  }
};

class CudaBackend final : public PatchMatchBackend {
 public:
  explicit CudaBackend(const std::vector<StereoView>& views) : views_(views) {
    if (!cuda_device_available()) throw Error("mvs: no CUDA device is available; use --device cpu");
    for (const auto& view : views) {
      images_.emplace_back(view.grey.pixels.size());
      images_.back().upload(view.grey.pixels.data());
      masks_.emplace_back(view.mask.size());
      if (!view.mask.empty()) masks_.back().upload(view.mask.data());
    }
  }

  DepthMap run(const ViewTask& task, Parameters params, const std::vector<DepthMap>& previous, int first_iteration,
               int sweeps) override {
    const StereoView& view = views_[task.reference];
    const int width = view.camera.width, height = view.camera.height;
    const size_t pixels = size_t(width) * height;
    ReferenceView ref = reference_geometry(view.camera);
    ref.image = {images_[task.reference].data, width, height};
    ref.mask = view.mask.empty() ? nullptr : masks_[task.reference].data;

    Sources sources{};
    std::vector<DeviceArray<float>> source_depths;
    source_depths.reserve(task.sources.size());
    for (size_t k = 0; k < task.sources.size(); ++k) {
      const int s = task.sources[k];
      sources.view[k] = source_geometry(view.camera, views_[s].camera);
      sources.view[k].image = {images_[s].data, views_[s].camera.width, views_[s].camera.height};
      if (params.geometric && !previous[s].depth.empty()) {
        source_depths.emplace_back(previous[s].depth.size());
        source_depths.back().upload(previous[s].depth.data());
        sources.view[k].depth = source_depths.back().data;
      }
    }

    DepthMap map = params.geometric ? previous[task.reference] : DepthMap(width, height);
    DeviceArray<float> depth(pixels), normals(3 * pixels), cost(pixels);
    if (params.geometric) {
      depth.upload(map.depth.data());
      normals.upload(map.normals.data());
      cost.upload(map.cost.data());
    }
    const PixelStates states{depth.data, normals.data, cost.data};
    const dim3 block(16, 8);
    if (!params.geometric) {
      const dim3 grid((width + block.x - 1) / block.x, (height + block.y - 1) / block.y);
      initialise_kernel<<<grid, block>>>(ref, sources, params, states);
      check_launch(kOp, "initialise_kernel");
    }
    const int half_width = (width + 1) / 2;
    const dim3 grid((half_width + block.x - 1) / block.x, (height + block.y - 1) / block.y);
    for (int sweep = 0; sweep < sweeps; ++sweep) {
      params.iteration = first_iteration + sweep;
      for (int colour = 0; colour < 2; ++colour) {
        sweep_kernel<<<grid, block>>>(ref, sources, params, states, colour);
        check_launch(kOp, "sweep_kernel");
      }
    }
    depth.download(map.depth.data());
    normals.download(map.normals.data());
    cost.download(map.cost.data());
    return map;
  }

 private:
  const std::vector<StereoView>& views_;
  std::vector<DeviceArray<float>> images_;
  std::vector<DeviceArray<uint8_t>> masks_;
};

}  // namespace

std::unique_ptr<PatchMatchBackend> make_cuda_backend(const std::vector<StereoView>& views) {
  return std::make_unique<CudaBackend>(views);
}

}  // namespace detail
}  // namespace tega::mvs
