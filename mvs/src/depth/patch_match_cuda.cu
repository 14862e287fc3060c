// The CUDA path: one thread per pixel of a colour, the per-pixel math of the
// CPU path (patch_match_math.h). Images and estimates of every view stay on
// the GPU for the whole call: passes hand maps on there, and only the final
// ones (and a coarse level's) come back.

#include <cuda_runtime_api.h>

#include <memory>
#include <utility>
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
  DeviceArray(DeviceArray&& o) noexcept : data(o.data), size(o.size) {
    o.data = nullptr;
    o.size = 0;
  }
  DeviceArray& operator=(DeviceArray&& o) noexcept {
    std::swap(data, o.data);
    std::swap(size, o.size);
    return *this;
  }
  ~DeviceArray() { cudaFree(data); }
  void upload(const T* host) {
    check_cuda(cudaMemcpy(data, host, size * sizeof(T), cudaMemcpyHostToDevice), kOp, "upload");
  }
  void download(T* host) const {
    check_cuda(cudaMemcpy(host, data, size * sizeof(T), cudaMemcpyDeviceToHost), kOp, "download");
  }
};

// One view's estimate on the GPU.
struct DeviceEstimate {
  DeviceArray<float> depth, normals, cost;
  DeviceEstimate() = default;
  explicit DeviceEstimate(size_t pixels) : depth(pixels), normals(3 * pixels), cost(pixels) {}
  bool empty() const { return depth.size == 0; }
  PixelStates states() const { return {depth.data, normals.data, cost.data}; }
  void copy_from(const DeviceEstimate& o) {
    check_cuda(cudaMemcpy(depth.data, o.depth.data, depth.size * sizeof(float), cudaMemcpyDeviceToDevice), kOp, "copy");
    check_cuda(cudaMemcpy(normals.data, o.normals.data, normals.size * sizeof(float), cudaMemcpyDeviceToDevice), kOp,
               "copy");
    check_cuda(cudaMemcpy(cost.data, o.cost.data, cost.size * sizeof(float), cudaMemcpyDeviceToDevice), kOp, "copy");
  }
};

class CudaBackend final : public PatchMatchBackend {
 public:
  explicit CudaBackend(const std::vector<StereoView>& views)
      : views_(views), current_(views.size()), next_(views.size()) {
    if (!cuda_device_available()) throw Error("mvs: no CUDA device is available; use --device cpu");
    for (const auto& view : views) {
      images_.emplace_back(view.grey.pixels.size());
      images_.back().upload(view.grey.pixels.data());
      masks_.emplace_back(view.mask.size());
      if (!view.mask.empty()) masks_.back().upload(view.mask.data());
    }
  }

  void finish_pass() override {
    for (size_t v = 0; v < next_.size(); ++v)
      if (!next_[v].empty()) std::swap(current_[v], next_[v]);
  }

  void set_estimate(int view, const DepthMap& map) override {
    DeviceEstimate& e = current_[size_t(view)];
    if (e.empty()) e = DeviceEstimate(map.depth.size());
    e.depth.upload(map.depth.data());
    e.normals.upload(map.normals.data());
    e.cost.upload(map.cost.data());
  }

  DepthMap estimate(int view) const override {
    const DeviceEstimate& e = current_[size_t(view)];
    if (e.empty()) return {};
    DepthMap map(views_[size_t(view)].camera.width, views_[size_t(view)].camera.height);
    e.depth.download(map.depth.data());
    e.normals.download(map.normals.data());
    e.cost.download(map.cost.data());
    return map;
  }

  void run(const ViewTask& task, Parameters params, int first_iteration, int sweeps) override {
    const StereoView& view = views_[task.reference];
    const int width = view.camera.width, height = view.camera.height;
    ReferenceView ref = reference_geometry(view.camera);
    ref.image = {images_[task.reference].data, width, height};
    ref.mask = view.mask.empty() ? nullptr : masks_[task.reference].data;

    Sources sources{};
    for (size_t k = 0; k < task.sources.size(); ++k) {
      const int s = task.sources[k];
      sources.view[k] = source_geometry(view.camera, views_[s].camera);
      sources.view[k].image = {images_[s].data, views_[s].camera.width, views_[s].camera.height};
      // A source without an estimate adds the same penalty to every hypothesis.
      if (params.geometric && !current_[s].empty()) sources.view[k].depth = current_[s].depth.data;
    }

    DeviceEstimate& next = next_[task.reference];
    if (next.empty()) next = DeviceEstimate(size_t(width) * height);
    if (params.geometric) next.copy_from(current_[task.reference]);
    const PixelStates states = next.states();
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
  }

 private:
  const std::vector<StereoView>& views_;
  std::vector<DeviceArray<float>> images_;
  std::vector<DeviceArray<uint8_t>> masks_;
  std::vector<DeviceEstimate> current_, next_;  // by view; empty where a view has no estimate (yet)
};

}  // namespace

std::unique_ptr<PatchMatchBackend> make_cuda_backend(const std::vector<StereoView>& views) {
  return std::make_unique<CudaBackend>(views);
}

}  // namespace detail
}  // namespace tega::mvs
