#pragma once
// CUDA kernels of fused_field_mlp (fused_field_mlp.h): raw device pointers;
// the torch glue allocates the outputs and picks the stream. All tensors are
// contiguous. Matrices of the network are float32 (the trained parameters);
// the encoding and its derivatives are bfloat16, as encode_positions writes
// them; the condition and the outputs are float32.

#include <cuda_bf16.h>
#include <cuda_runtime_api.h>

#include <cstdint>

namespace tega::nn::fused_field::cuda {

constexpr int kHidden = 64;      // the only hidden width the kernels take
constexpr int kMaxOutputs = 8;   // one 8-column tile of the output layer
constexpr int kMaxFeatures = 16; // one 16-wide k step of the tangents' first layer

struct Shape {
  int64_t points = 0;
  int encoding_width = 0;      // row length of the encoding (a multiple of 8)
  int encoding_channels = 0;   // its channels that the first layer's weight has (≤ encoding_width)
  int derivative_width = 0;    // row length of each axis's derivatives (≤ 16; 0: no Jacobian)
  int features = 0;            // encoding features per axis (channel 3f + a is feature f of axis a)
  int condition_channels = 0;  // a multiple of 16, or 0
  int outputs = 0;             // ≤ 8
};

struct Weights {
  const float* input_weight;   // [64, encoding_channels + condition_channels]
  const float* input_bias;     // [64]
  const float* hidden_weight;  // [64, 64]
  const float* hidden_bias;    // [64]
  const float* output_weight;  // [outputs, 64]
  const float* output_bias;    // [outputs]
};

struct Inputs {
  const __nv_bfloat16* encoding;     // [points, encoding_width]
  const __nv_bfloat16* derivatives;  // [3, points, derivative_width], or null
  const float* condition;            // [points, condition_channels], or null
};

// What the weight gradients are summed from, bfloat16, one [points, width]
// matrix per row set: the values' rows, then with a Jacobian one set per
// uvd axis (the tangents'). Rows past the points are not written.
struct Products {
  __nv_bfloat16* hidden_inputs;     // [sets, points, 64]: the hidden layer's inputs (H0, and U0 per axis)
  __nv_bfloat16* hidden_gradients;  // [sets, points, 64]: its pre-activations' gradients
  __nv_bfloat16* output_inputs;     // [sets, points, 64]: the output layer's inputs
  __nv_bfloat16* output_gradients;  // [sets, points, 8]: the outputs' gradients (zero past outputs)
  __nv_bfloat16* first_gradients;   // [sets, points, 64]: the first layer's pre-activations' gradients
};

// Bytes of shared memory the kernels need, to check against the device's limit.
size_t shared_bytes(const Shape& shape);

// value [points, outputs]; jacobian [points, outputs, 3] when the shape has
// derivatives (else unused).
void forward(const Shape& shape, const Weights& weights, const Inputs& inputs, float* value, float* jacobian,
             int multiprocessors, cudaStream_t stream);

// grad_value [points, outputs] and grad_jacobian [points, outputs, 3] may be
// null (zero). grad_encoding [points, encoding_width] and grad_derivatives
// [3, points, derivative_width] are written whole; grad_condition
// [points, condition_channels] when there is a condition.
void backward(const Shape& shape, const Weights& weights, const Inputs& inputs, const float* grad_value,
              const float* grad_jacobian, __nv_bfloat16* grad_encoding, __nv_bfloat16* grad_derivatives,
              float* grad_condition, const Products& products, int multiprocessors, cudaStream_t stream);

}  // namespace tega::nn::fused_field::cuda
