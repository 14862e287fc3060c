#pragma once
// The CPU pipeline: the same stages and math as the CUDA kernels, run on
// host pointers with at::parallel_for. Templated on the scalar so that the
// tests can check gradients in double precision.

#include "pipeline.h"

#include <vector>

namespace tega::splat::cpu {

template <typename T>
void project(const RasterInputs<T>& in, const ProjectedBuffers<T>& out);

// Bins the projected Gaussians into tiles, front to back within a tile.
// Fills ranges [num_tiles, 2] and returns the id list.
template <typename T>
std::vector<int32_t> bin(const RasterInputs<T>& in, const ProjectedBuffers<T>& projected, int32_t* ranges);

template <typename T>
void render_forward(const RasterInputs<T>& in, const Splat2D<T>* splats, const TileBins& bins,
                    const ImageBuffers<T>& image);

// Writes d loss / d splat for every projected Gaussian ([C * N]).
template <typename T>
void render_backward(const RasterInputs<T>& in, const Splat2D<T>* splats, const TileBins& bins,
                     const ImageBuffers<T>& image, const ImageGradients<T>& grads, Splat2D<T>* splat_grads);

// color_jacobians: what project() kept (null unless the colours are SH).
template <typename T>
void project_backward(const RasterInputs<T>& in, const int32_t* radii, const Splat2D<T>* splat_grads,
                      const ColorJacobian<T>* color_jacobians, const InputGradients<T>& out);

}  // namespace tega::splat::cpu
