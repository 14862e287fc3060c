// Torch glue of the fused field kernels: checks, the autograd Function,
// outputs from the caching allocator, kernels on the current stream. Builds
// without the kernels support nothing.

#include "fused_field_mlp.h"

#if defined(TEGA_HAVE_CUDA) && defined(TEGA_TORCH_HAS_CUDA)

#include <ATen/ATen.h>
#include <ATen/cuda/CUDAContext.h>
#include <c10/cuda/CUDAGuard.h>
#include <torch/csrc/autograd/custom_function.h>

#include "fused_field_mlp_kernels.h"
#include "tega/core/cuda_grid.h"

namespace tega::nn::fused_field {
namespace {

using torch::autograd::AutogradContext;
using torch::autograd::variable_list;

// Absent inputs (no derivatives, no condition) travel as empty tensors:
// libtorch 2's autograd Functions take no undefined tensors.
bool present(const at::Tensor& t) { return t.defined() && t.numel() > 0; }

cuda::Shape shape_of(const FieldMLPOptions& options, const at::Tensor& encoding, const at::Tensor& derivatives) {
  cuda::Shape s;
  s.points = encoding.size(0);
  s.encoding_width = int(encoding.size(1));
  s.encoding_channels = int(options.encoding.channels());
  s.derivative_width = present(derivatives) ? int(derivatives.size(2)) : 0;
  s.features = int(options.encoding.features());
  s.condition_channels = int(options.condition_channels);
  s.outputs = int(options.outputs);
  return s;
}

template <typename T>
T* maybe(const at::Tensor& t) {
  return present(t) ? t.data_ptr<T>() : nullptr;
}

const __nv_bfloat16* bf16(const at::Tensor& t) {
  return present(t) ? reinterpret_cast<const __nv_bfloat16*>(t.data_ptr<at::BFloat16>()) : nullptr;
}

cuda::Weights weights_of(const variable_list& w) {
  return {w[0].data_ptr<float>(), w[1].data_ptr<float>(), w[2].data_ptr<float>(),
          w[3].data_ptr<float>(), w[4].data_ptr<float>(), w[5].data_ptr<float>()};
}

int multiprocessors() { return at::cuda::getCurrentDeviceProperties()->multiProcessorCount; }

// Inputs: encoding, derivatives (or undefined), condition (or undefined), then
// the six parameters. Outputs: value, and the Jacobian when there are derivatives.
class FusedFieldFunction : public torch::autograd::Function<FusedFieldFunction> {
 public:
  static variable_list forward(AutogradContext* ctx, const at::Tensor& encoding, const at::Tensor& derivatives,
                               const at::Tensor& condition, const at::Tensor& w0, const at::Tensor& b0,
                               const at::Tensor& w1, const at::Tensor& b1, const at::Tensor& w2, const at::Tensor& b2,
                               const FieldMLPOptions& options) {
    const c10::cuda::CUDAGuard guard(encoding.device());
    const cuda::Shape s = shape_of(options, encoding, derivatives);
    ctx->save_for_backward({encoding, derivatives, condition, w0, b0, w1, b1, w2, b2});
    ctx->saved_data["points"] = s.points;
    ctx->saved_data["encoding_channels"] = int64_t(s.encoding_channels);
    ctx->saved_data["features"] = int64_t(s.features);
    ctx->saved_data["condition_channels"] = int64_t(s.condition_channels);
    ctx->saved_data["outputs"] = int64_t(s.outputs);
    const at::TensorOptions to = w0.options();
    at::Tensor value = at::empty({s.points, s.outputs}, to);
    at::Tensor jacobian = s.derivative_width ? at::empty({s.points, s.outputs, 3}, to) : at::Tensor();
    cuda::forward(s, weights_of({w0, b0, w1, b1, w2, b2}), {bf16(encoding), bf16(derivatives), maybe<float>(condition)},
                  value.data_ptr<float>(), maybe<float>(jacobian), multiprocessors(),
                  at::cuda::getCurrentCUDAStream());
    if (!jacobian.defined()) return {value};
    return {value, jacobian};
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const variable_list saved = ctx->get_saved_variables();
    const at::Tensor &encoding = saved[0], &derivatives = saved[1], &condition = saved[2];
    const c10::cuda::CUDAGuard guard(encoding.device());
    cuda::Shape s;
    s.points = ctx->saved_data["points"].toInt();
    s.encoding_width = int(encoding.size(1));
    s.encoding_channels = int(ctx->saved_data["encoding_channels"].toInt());
    s.derivative_width = present(derivatives) ? int(derivatives.size(2)) : 0;
    s.features = int(ctx->saved_data["features"].toInt());
    s.condition_channels = int(ctx->saved_data["condition_channels"].toInt());
    s.outputs = int(ctx->saved_data["outputs"].toInt());
    const at::Tensor grad_value = grads[0].defined() ? grads[0].to(at::kFloat).contiguous() : at::Tensor();
    const at::Tensor grad_jacobian =
        grads.size() > 1 && grads[1].defined() ? grads[1].to(at::kFloat).contiguous() : at::Tensor();

    at::Tensor grad_encoding = at::empty_like(encoding);
    at::Tensor grad_derivatives = present(derivatives) ? at::empty_like(derivatives) : at::Tensor();
    at::Tensor grad_condition = present(condition) ? at::empty_like(condition) : at::Tensor();
    const int64_t sets = s.derivative_width ? 4 : 1, n = s.points, hidden = cuda::kHidden;
    const at::TensorOptions bf = encoding.options();
    const at::Tensor hidden_inputs = at::empty({sets, n, hidden}, bf), hidden_gradients = at::empty_like(hidden_inputs),
                     output_inputs = at::empty_like(hidden_inputs), first_gradients = at::empty_like(hidden_inputs),
                     output_gradients = at::empty({sets, n, cuda::kMaxOutputs}, bf);
    const auto raw = [](const at::Tensor& t) { return reinterpret_cast<__nv_bfloat16*>(t.data_ptr<at::BFloat16>()); };
    const variable_list weights(saved.begin() + 3, saved.end());
    cuda::backward(s, weights_of(weights), {bf16(encoding), bf16(derivatives), maybe<float>(condition)},
                   maybe<float>(grad_value), maybe<float>(grad_jacobian), raw(grad_encoding),
                   present(grad_derivatives) ? raw(grad_derivatives) : nullptr, maybe<float>(grad_condition),
                   {raw(hidden_inputs), raw(hidden_gradients), raw(output_inputs), raw(output_gradients),
                    raw(first_gradients)},
                   multiprocessors(), at::cuda::getCurrentCUDAStream());

    // The weight gradients: sums over points (and row sets) of outer products,
    // bfloat16 products accumulated in float32 by cuBLAS.
    const auto rows = [](const at::Tensor& t) { return t.reshape({-1, t.size(-1)}); };
    const auto column_sum = [](const at::Tensor& t) { return at::sum(t, {0}, false, at::kFloat); };
    const at::Tensor grad_output_weight =
        at::mm(rows(output_gradients).t(), rows(output_inputs)).narrow(0, 0, s.outputs).to(at::kFloat);
    const at::Tensor grad_output_bias =
        grad_value.defined() ? grad_value.sum(0) : at::zeros({s.outputs}, grad_output_weight.options());
    const at::Tensor grad_hidden_weight = at::mm(rows(hidden_gradients).t(), rows(hidden_inputs)).to(at::kFloat);
    const at::Tensor grad_hidden_bias = column_sum(hidden_gradients[0]);
    const at::Tensor first = first_gradients[0].t();
    at::Tensor grad_encoding_weight =
        at::mm(first, encoding).narrow(1, 0, s.encoding_channels).to(at::kFloat).contiguous();
    if (s.derivative_width) {
      // Channel 3f + a of the encoding is feature f of axis a (positional_encoding.h).
      const at::Tensor by_axis = grad_encoding_weight.view({hidden, s.features, 3});
      for (int64_t a = 0; a < 3; ++a)
        by_axis.select(2, a).add_(
            at::mm(first_gradients[1 + a].t(), derivatives[a]).narrow(1, 0, s.features).to(at::kFloat));
    }
    const at::Tensor grad_input_weight =
        present(condition)
            ? at::cat({grad_encoding_weight, at::mm(first, condition.to(at::kBFloat16)).to(at::kFloat)}, 1)
            : grad_encoding_weight;
    variable_list out{grad_encoding,      grad_derivatives,   grad_condition,
                      grad_input_weight,  column_sum(first_gradients[0]),
                      grad_hidden_weight, grad_hidden_bias,   grad_output_weight,
                      grad_output_bias};
    out.push_back(at::Tensor());  // options
    return out;
  }
};

// The kernels read pairs of elements as 32- or 64-bit words. An absent input
// becomes an empty tensor on the inputs' device.
at::Tensor aligned(const at::Tensor& t, const at::Tensor& like) {
  if (!t.defined()) return at::empty({0}, like.options());
  const at::Tensor c = t.contiguous();
  return aligned_to_16_bytes(c.data_ptr()) ? c : c.clone();
}

}  // namespace

bool supports(const FieldMLPOptions& options, const EncodedPositions& encoded, const at::Tensor& input_weight) {
  const at::Tensor& e = encoded.encoding;
  if (!e.is_cuda() || e.scalar_type() != at::kBFloat16 || input_weight.scalar_type() != at::kFloat) return false;
  if (options.hidden != cuda::kHidden || options.outputs > cuda::kMaxOutputs || options.condition_channels % 16 != 0)
    return false;
  if (aligned_width(options.encoding.features()) > cuda::kMaxFeatures) return false;
  const cudaDeviceProp* properties = at::cuda::getDeviceProperties(e.device().index());
  if (properties->major < 8) return false;
  cuda::Shape s = shape_of(options, e, at::Tensor());
  s.derivative_width = cuda::kMaxFeatures;  // the larger need, with tangents
  return cuda::shared_bytes(s) <= properties->sharedMemPerBlockOptin;
}

FieldWithJacobian evaluate(const FieldMLPOptions& options, const Parameters& p, const EncodedPositions& encoded,
                           const at::Tensor& condition) {
  const at::Tensor& e = encoded.encoding;
  const variable_list out = FusedFieldFunction::apply(
      aligned(e, e), aligned(encoded.derivatives, e),
      aligned(condition.defined() ? condition.to(at::kFloat) : condition, e), p.input_weight.contiguous(),
      p.input_bias.contiguous(), p.hidden_weight.contiguous(), p.hidden_bias.contiguous(),
      p.output_weight.contiguous(), p.output_bias.contiguous(), options);
  return {out[0], out.size() > 1 ? out[1] : at::Tensor()};
}

}  // namespace tega::nn::fused_field

#else

#include <c10/util/Exception.h>

namespace tega::nn::fused_field {

bool supports(const FieldMLPOptions&, const EncodedPositions&, const at::Tensor&) { return false; }

FieldWithJacobian evaluate(const FieldMLPOptions&, const Parameters&, const EncodedPositions&, const at::Tensor&) {
  TORCH_CHECK(false, "fused_field_mlp: this build has no CUDA kernels");
}

}  // namespace tega::nn::fused_field

#endif
