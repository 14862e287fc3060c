// sample_latent (encoders.h): checks, the autograd Function, the CPU loops
// and the dispatch to the CUDA kernels. The latent is sampled channels-last,
// so that a point's channels are contiguous in memory.

#include <ATen/ATen.h>
#include <ATen/Dispatch.h>
#include <ATen/Parallel.h>
#include <torch/csrc/autograd/custom_function.h>

#include "latent_sampling_glue.h"
#include "latent_sampling_math.h"
#include "tega/avatar/device_dispatch.h"
#include "tega/nn/encoders.h"

namespace tega::nn {
namespace latent_sampling {

at::Tensor forward_cpu(const at::Tensor& latent, const at::Tensor& uv) {
  const int64_t height = latent.size(0), width = latent.size(1), channels = latent.size(2), n = uv.size(0);
  at::Tensor sampled = at::empty({n, channels}, latent.options());
  AT_DISPATCH_FLOATING_TYPES(latent.scalar_type(), "sample_latent", [&] {
    const scalar_t* texels = latent.data_ptr<scalar_t>();
    const scalar_t* coords = uv.data_ptr<scalar_t>();
    scalar_t* out = sampled.data_ptr<scalar_t>();
    at::parallel_for(0, n, 256, [&](int64_t begin, int64_t end) {
      for (int64_t p = begin; p < end; ++p) {
        const Taps<scalar_t> t = taps(coords[2 * p], coords[2 * p + 1], height, width);
        for (int64_t c = 0; c < channels; ++c) {
          scalar_t sum = 0;
          for (int k = 0; k < 4; ++k) sum += t.weight[k] * texels[t.texel[k] * channels + c];
          out[p * channels + c] = sum;
        }
      }
    });
  });
  return sampled;
}

std::pair<at::Tensor, at::Tensor> backward_cpu(const at::Tensor& latent, const at::Tensor& uv,
                                               const at::Tensor& grad_sampled) {
  const int64_t height = latent.size(0), width = latent.size(1), channels = latent.size(2), n = uv.size(0);
  at::Tensor grad_latent = at::zeros_like(latent), grad_uv = at::empty_like(uv);
  AT_DISPATCH_FLOATING_TYPES(latent.scalar_type(), "sample_latent_backward", [&] {
    const scalar_t* texels = latent.data_ptr<scalar_t>();
    const scalar_t* coords = uv.data_ptr<scalar_t>();
    const scalar_t* g = grad_sampled.data_ptr<scalar_t>();
    scalar_t* gl = grad_latent.data_ptr<scalar_t>();
    scalar_t* guv = grad_uv.data_ptr<scalar_t>();
    // Points in parallel for the uv gradient; channels in parallel for the
    // latent's, so that no two threads add into the same texel channel.
    at::parallel_for(0, n, 256, [&](int64_t begin, int64_t end) {
      for (int64_t p = begin; p < end; ++p) {
        const Taps<scalar_t> t = taps(coords[2 * p], coords[2 * p + 1], height, width);
        scalar_t du = 0, dv = 0;
        for (int64_t c = 0; c < channels; ++c) {
          for (int k = 0; k < 4; ++k) {
            const scalar_t value = texels[t.texel[k] * channels + c] * g[p * channels + c];
            du += t.dweight_du[k] * value;
            dv += t.dweight_dv[k] * value;
          }
        }
        guv[2 * p] = du;
        guv[2 * p + 1] = dv;
      }
    });
    at::parallel_for(0, channels, 1, [&](int64_t begin, int64_t end) {
      for (int64_t p = 0; p < n; ++p) {
        const Taps<scalar_t> t = taps(coords[2 * p], coords[2 * p + 1], height, width);
        for (int64_t c = begin; c < end; ++c)
          for (int k = 0; k < 4; ++k) gl[t.texel[k] * channels + c] += t.weight[k] * g[p * channels + c];
      }
    });
  });
  return {grad_latent, grad_uv};
}

}  // namespace latent_sampling

namespace {

using torch::autograd::AutogradContext;
using torch::autograd::variable_list;

// latent channels-last [H,W,C], uv [N,2] -> [N,C].
class SampleLatentFunction : public torch::autograd::Function<SampleLatentFunction> {
 public:
  static at::Tensor forward(AutogradContext* ctx, const at::Tensor& latent, const at::Tensor& uv) {
    ctx->save_for_backward({latent, uv});
    if (use_cuda_kernels(latent, "sample_latent")) {
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
      return latent_sampling::forward_cuda(latent, uv);
#endif
    }
    return latent_sampling::forward_cpu(latent, uv);
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const variable_list saved = ctx->get_saved_variables();
    const at::Tensor grad = grads[0].contiguous();
    std::pair<at::Tensor, at::Tensor> g;
    if (use_cuda_kernels(saved[0], "sample_latent")) {
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
      g = latent_sampling::backward_cuda(saved[0], saved[1], grad);
#endif
    } else {
      g = latent_sampling::backward_cpu(saved[0], saved[1], grad);
    }
    return {g.first, g.second};
  }
};

}  // namespace

at::Tensor sample_latent(const at::Tensor& latent, const at::Tensor& uv) {
  TORCH_CHECK(latent.dim() == 3, "latent must be [C,H,W], got ", latent.sizes());
  TORCH_CHECK(uv.dim() == 2 && uv.size(1) == 2, "uv must be [N,2], got ", uv.sizes());
  TORCH_CHECK(latent.device() == uv.device(), "latent and uv on different devices");
  TORCH_CHECK(!latent.is_cuda() || latent.scalar_type() == at::kFloat, "sample_latent: CUDA takes float32");
  return SampleLatentFunction::apply(latent.permute({1, 2, 0}).contiguous(), uv.to(latent.scalar_type()).contiguous());
}

}  // namespace tega::nn
