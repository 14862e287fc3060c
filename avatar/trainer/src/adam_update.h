#pragma once
// Adam's update of one parameter tensor as a single pass over its elements
// (Adam::step): the composed tensor ops took seven passes over every
// Gaussian parameter, 7 ms a step at 4M Gaussians on an H100. CPU (float,
// double) and CUDA share the element math (adam_update_math.h).

#include <ATen/core/Tensor.h>

#include "adam_update_math.h"

namespace tega::trainer::adam_update {

// param, grad, first and second moment: contiguous, one shape and dtype.
// column_scale: undefined, or one factor per entry of the last dimension.
void step(const at::Tensor& param, const at::Tensor& grad, const at::Tensor& first_moment,
          const at::Tensor& second_moment, const at::Tensor& column_scale, const Constants<double>& constants);

#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
void step_cuda(const at::Tensor& param, const at::Tensor& grad, const at::Tensor& first_moment,
               const at::Tensor& second_moment, const at::Tensor& column_scale, const Constants<double>& constants);
#endif

}  // namespace tega::trainer::adam_update
