#pragma once
// The CUDA pipeline (float). Kernels take raw device pointers; the torch glue
// (rasterize_cuda.cpp) allocates every buffer through the caching allocator,
// temporaries through a Workspace.

#include "pipeline.h"

#include <cuda_runtime_api.h>

#include <cstddef>

namespace tega::splat::cuda {

// Device memory for temporaries that live until the Workspace is dropped.
class Workspace {
 public:
  virtual void* allocate(std::size_t bytes) = 0;

 protected:
  ~Workspace() = default;
};

// The depth sort's keys and values, [2 * C * N] each: project() fills the
// first halves, sort_by_depth() sorts into the second.
struct DepthKeys {
  uint64_t* keys = nullptr;
  int32_t* ids = nullptr;
};

// Fills the projected buffers ([C * N] each) and the depth sort's keys.
// `in` holds device pointers, cameras included.
DepthKeys project(const RasterInputs<float>& in, const ProjectedBuffers<float>& out, Workspace& workspace,
                  cudaStream_t stream);

// Front-to-back order of the projected Gaussians and the running total of
// the tiles each touches, in that order.
struct DepthOrder {
  const int32_t* ids = nullptr;          // [C * N]
  const int64_t* tile_offsets = nullptr; // [C * N], inclusive prefix sum
  int64_t total = 0;                     // number of tile-Gaussian intersections
};

// Sorts by (camera, depth) and counts the intersections (one host sync).
DepthOrder sort_by_depth(const RasterInputs<float>& in, const ProjectedBuffers<float>& projected,
                         const DepthKeys& depth_keys, Workspace& workspace, cudaStream_t stream);

// Writes `order.total` ids sorted by tile, front to back within a tile, and
// each tile's range ([num_tiles, 2]).
void bin(const RasterInputs<float>& in, const ProjectedBuffers<float>& projected, const DepthOrder& order,
         int32_t* gaussian_ids, int32_t* ranges, Workspace& workspace, cudaStream_t stream);

void render_forward(const RasterInputs<float>& in, const Splat2D<float>* splats, const TileBins& bins,
                    const ImageBuffers<float>& image, cudaStream_t stream);

// Adds d loss / d splat into splat_grads ([C * N], zeroed by the caller).
void render_backward(const RasterInputs<float>& in, const Splat2D<float>* splats, const TileBins& bins,
                     const ImageBuffers<float>& image, const ImageGradients<float>& grads,
                     Splat2D<float>* splat_grads, cudaStream_t stream);

// Adds d loss / d background = Σ_pixels T_final d loss / d rgb into
// grad_background ([3], zeroed by the caller).
void background_backward(const RasterInputs<float>& in, const float* final_transmittance, const float* grad_rgb,
                         float* grad_background, cudaStream_t stream);

// color_jacobians: what project() kept (null unless the colours are SH).
void project_backward(const RasterInputs<float>& in, const int32_t* radii, const Splat2D<float>* splat_grads,
                      const ColorJacobian<float>* color_jacobians, const InputGradients<float>& out,
                      cudaStream_t stream);

}  // namespace tega::splat::cuda
