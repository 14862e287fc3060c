// The positional encoding: its tensor-op definition, and encode_positions's
// checks, autograd Function, CPU loops and dispatch to the CUDA kernels.

#include "tega/nn/positional_encoding.h"

#include <ATen/ATen.h>
#include <ATen/Dispatch.h>
#include <ATen/Parallel.h>
#include <torch/csrc/autograd/custom_function.h>

#include <cmath>

#include "positional_encoding_glue.h"
#include "positional_encoding_math.h"
#include "tega/avatar/device_dispatch.h"

namespace tega::nn {
namespace {

// Per-axis scale (1, 1, depth_scale), shaped to broadcast against [N,3].
// Filled on the device: a tensor built from host values would be a copy that
// waits for the GPU's queue at every call.
at::Tensor axis_scale(const at::Tensor& uvd, double depth_scale) {
  at::Tensor scale = at::ones({1, 3}, uvd.options().requires_grad(false));
  scale.narrow(1, 2, 1).fill_(depth_scale);
  return scale;
}

// π 2^k for k < frequencies, shaped [1,K,1].
at::Tensor octaves(int64_t frequencies, const at::TensorOptions& options) {
  return (at::pow(2.0, at::arange(frequencies, options)) * M_PI).view({1, -1, 1});
}

void check_uvd(const at::Tensor& uvd) {
  TORCH_CHECK(uvd.dim() == 2 && uvd.size(1) == 3, "uvd must be [N,3], got ", uvd.sizes());
}

}  // namespace

at::Tensor PositionalEncoding::encode(const at::Tensor& uvd) const {
  check_uvd(uvd);
  const at::Tensor x = uvd * axis_scale(uvd, depth_scale);
  const at::Tensor phase = x.unsqueeze(1) * octaves(frequencies, uvd.options());  // [N,K,3]
  const at::Tensor waves = at::stack({at::sin(phase), at::cos(phase)}, 2).view({uvd.size(0), 2 * frequencies, 3});
  return at::cat({x.unsqueeze(1), waves}, 1).view({uvd.size(0), channels()});
}

at::Tensor PositionalEncoding::axis_derivatives(const at::Tensor& uvd) const {
  check_uvd(uvd);
  const at::Tensor scale = axis_scale(uvd, depth_scale).t().unsqueeze(2);  // [3,1,1]
  const at::Tensor omega = octaves(frequencies, uvd.options()).view({1, 1, -1});
  const at::Tensor phase = (uvd.t().unsqueeze(2) * scale) * omega;  // [3,N,K]
  const at::Tensor rate = omega * scale;                            // [3,1,K]
  const at::Tensor waves = at::stack({rate * at::cos(phase), -rate * at::sin(phase)}, 3).view({3, uvd.size(0), -1});
  return at::cat({scale.expand({3, uvd.size(0), 1}), waves}, 2);
}

namespace positional_encoding {

template <typename T>
T axis_scale_of(const PositionalEncoding& encoding, int axis) {
  return axis == 2 ? T(encoding.depth_scale) : T(1);
}

EncodedPositions forward_cpu(const PositionalEncoding& encoding, const at::Tensor& uvd, bool with_derivatives) {
  const int64_t n = uvd.size(0), width = aligned_width(encoding.channels());
  const int64_t derivative_width = aligned_width(encoding.features());
  EncodedPositions out;
  out.encoding = at::zeros({n, width}, uvd.options());
  if (with_derivatives) out.derivatives = at::zeros({kAxes, n, derivative_width}, uvd.options());
  AT_DISPATCH_FLOATING_TYPES(uvd.scalar_type(), "encode_positions", [&] {
    const scalar_t* c = uvd.data_ptr<scalar_t>();
    scalar_t* e = out.encoding.data_ptr<scalar_t>();
    scalar_t* d = with_derivatives ? out.derivatives.data_ptr<scalar_t>() : nullptr;
    at::parallel_for(0, n, 1024, [&](int64_t begin, int64_t end) {
      for (int64_t p = begin; p < end; ++p)
        for (int a = 0; a < kAxes; ++a) {
          scalar_t* derivative_row = d ? d + (a * n + p) * derivative_width : nullptr;
          for (int f = 0; f < encoding.features(); ++f) {
            const Feature<scalar_t> feature =
                encoding_feature(f, c[kAxes * p + a], axis_scale_of<scalar_t>(encoding, a));
            e[p * width + kAxes * f + a] = feature.value;
            if (derivative_row) derivative_row[f] = feature.first;
          }
        }
    });
  });
  return out;
}

at::Tensor backward_cpu(const PositionalEncoding& encoding, const at::Tensor& uvd, const at::Tensor& grad_encoding,
                        const at::Tensor& grad_derivatives) {
  const int64_t n = uvd.size(0), width = aligned_width(encoding.channels());
  const int64_t derivative_width = aligned_width(encoding.features());
  at::Tensor grad_uvd = at::empty_like(uvd);
  AT_DISPATCH_FLOATING_TYPES(uvd.scalar_type(), "encode_positions_backward", [&] {
    const scalar_t* c = uvd.data_ptr<scalar_t>();
    const scalar_t* ge = grad_encoding.data_ptr<scalar_t>();
    const scalar_t* gd = grad_derivatives.defined() ? grad_derivatives.data_ptr<scalar_t>() : nullptr;
    scalar_t* g = grad_uvd.data_ptr<scalar_t>();
    at::parallel_for(0, n, 1024, [&](int64_t begin, int64_t end) {
      for (int64_t p = begin; p < end; ++p)
        for (int a = 0; a < kAxes; ++a) {
          const scalar_t* derivative_row = gd ? gd + (a * n + p) * derivative_width : nullptr;
          scalar_t sum = 0;
          for (int f = 0; f < encoding.features(); ++f) {
            const Feature<scalar_t> feature =
                encoding_feature(f, c[kAxes * p + a], axis_scale_of<scalar_t>(encoding, a));
            sum += ge[p * width + kAxes * f + a] * feature.first;
            if (derivative_row) sum += derivative_row[f] * feature.second;
          }
          g[kAxes * p + a] = sum;
        }
    });
  });
  return grad_uvd;
}

}  // namespace positional_encoding

namespace {

using torch::autograd::AutogradContext;
using torch::autograd::variable_list;

PositionalEncoding saved_encoding(AutogradContext* ctx) {
  PositionalEncoding encoding;
  encoding.frequencies = ctx->saved_data["frequencies"].toInt();
  encoding.depth_scale = ctx->saved_data["depth_scale"].toDouble();
  return encoding;
}

class EncodePositionsFunction : public torch::autograd::Function<EncodePositionsFunction> {
 public:
  // `type` is the output's type on CUDA; on the CPU it is uvd's (checked).
  static variable_list forward(AutogradContext* ctx, const at::Tensor& uvd, const PositionalEncoding& encoding,
                               [[maybe_unused]] at::ScalarType type, bool with_derivatives) {
    ctx->save_for_backward({uvd});
    ctx->saved_data["frequencies"] = encoding.frequencies;
    ctx->saved_data["depth_scale"] = encoding.depth_scale;
    // Unused derivatives get no gradient rather than a tensor of zeros.
    ctx->set_materialize_grads(false);
    EncodedPositions out;
    if (use_cuda_kernels(uvd, "encode_positions")) {
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
      out = positional_encoding::forward_cuda(encoding, uvd, type, with_derivatives);
#endif
    } else {
      out = positional_encoding::forward_cpu(encoding, uvd, with_derivatives);
    }
    if (!with_derivatives) return {out.encoding};
    return {out.encoding, out.derivatives};
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const at::Tensor uvd = ctx->get_saved_variables()[0];
    const at::Tensor grad_derivatives =
        grads.size() > 1 && grads[1].defined() ? grads[1].contiguous() : at::Tensor();
    if (!grads[0].defined() && !grad_derivatives.defined()) return {at::Tensor(), at::Tensor(), at::Tensor(), at::Tensor()};
    const PositionalEncoding encoding = saved_encoding(ctx);
    // The kernels read a gradient of the encoding; zeros stand in for none.
    const at::Tensor grad_encoding = grads[0].defined() ? grads[0].contiguous()
                                                        : at::zeros({uvd.size(0), aligned_width(encoding.channels())},
                                                                    grad_derivatives.options());
    at::Tensor grad_uvd;
    if (use_cuda_kernels(uvd, "encode_positions")) {
#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)
      grad_uvd = positional_encoding::backward_cuda(encoding, uvd, grad_encoding, grad_derivatives);
#endif
    } else {
      grad_uvd = positional_encoding::backward_cpu(encoding, uvd, grad_encoding, grad_derivatives);
    }
    return {grad_uvd, at::Tensor(), at::Tensor(), at::Tensor()};
  }
};

}  // namespace

EncodedPositions encode_positions(const PositionalEncoding& encoding, const at::Tensor& uvd, at::ScalarType type,
                                  bool with_derivatives) {
  check_uvd(uvd);
  TORCH_CHECK(encoding.frequencies >= 0 && encoding.frequencies < 24, "encode_positions: frequencies must be in [0, 24)");
  const at::ScalarType in = uvd.scalar_type();
  if (uvd.is_cuda()) {
    TORCH_CHECK(in == at::kFloat && (type == at::kFloat || type == at::kBFloat16),
                "encode_positions: on CUDA uvd must be float32 and the output float32 or bfloat16");
  } else {
    TORCH_CHECK((in == at::kFloat || in == at::kDouble) && type == in,
                "encode_positions: on the CPU uvd must be float32 or float64, and the output of the same type");
  }
  const variable_list out = EncodePositionsFunction::apply(uvd.contiguous(), encoding, type, with_derivatives);
  EncodedPositions result;
  result.encoding = out[0];
  if (with_derivatives) result.derivatives = out[1];
  return result;
}

}  // namespace tega::nn
