// CPU path of the fused SSIM (float and double): the separable blur with zero
// padding and the per-pixel math of ssim_math.h, rows in parallel. Each pass
// keeps the horizontally blurred maps of the whole batch, then blurs them
// vertically one output row at a time.

#include "fused_ssim_glue.h"
#include "ssim_math.h"

#include <ATen/ATen.h>
#include <ATen/Dispatch.h>
#include <ATen/Parallel.h>

#include <algorithm>
#include <array>
#include <numeric>
#include <vector>

namespace tega::nn::fused_ssim_glue {
namespace {

using ssim::kRadius;
using ssim::kTaps;

// A row is only a few thousand flops: tasks take several.
constexpr int64_t kGrainRows = 8;

struct Geometry {
  int64_t planes, height, width;
  int64_t rows() const { return planes * height; }
  int64_t pixels() const { return rows() * width; }
};

Geometry geometry_of(const at::Tensor& image) { return {image.size(0), image.size(1), image.size(2)}; }

template <typename T>
std::array<T, kTaps> window() {
  std::array<T, kTaps> w{};
  for (int k = 0; k < kTaps; ++k) w[k] = ssim::window_weight<T>(k);
  return w;
}

// out[m][i] = Σ_k w_k v_m(i + k − 5) along each row, zero beyond its ends;
// source(i, v) fills the K values at pixel i.
template <typename T, int K, typename Source>
std::vector<T> blur_rows(const Geometry& g, const Source& source) {
  const int64_t n = g.pixels(), width = g.width;
  std::vector<T> out(K * n);
  const std::array<T, kTaps> w = window<T>();
  at::parallel_for(0, g.rows(), kGrainRows, [&](int64_t begin, int64_t end) {
    std::array<T, K> v;
    for (int64_t row = begin; row < end; ++row) {
      for (int64_t x = 0; x < width; ++x) {
        std::array<T, K> sum{};
        const int64_t first = std::max<int64_t>(0, kRadius - x);
        const int64_t last = std::min<int64_t>(kTaps, width - x + kRadius);
        for (int64_t k = first; k < last; ++k) {
          source(row * width + x + k - kRadius, v);
          for (int m = 0; m < K; ++m) sum[m] += w[k] * v[m];
        }
        for (int m = 0; m < K; ++m) out[m * n + row * width + x] = sum[m];
      }
    }
  });
  return out;
}

// The vertical pass at one output row (global row index over all planes):
// column[m * width + x] = Σ_k w_k rows_m(y + k − 5, x), zero beyond the plane.
template <typename T, int K>
void blur_column(const Geometry& g, const std::vector<T>& rows, int64_t row, std::vector<T>& column) {
  const std::array<T, kTaps> w = window<T>();
  const int64_t n = g.pixels(), width = g.width, y = row % g.height;
  std::fill(column.begin(), column.end(), T(0));
  const int64_t first = std::max<int64_t>(0, kRadius - y);
  const int64_t last = std::min<int64_t>(kTaps, g.height - y + kRadius);
  for (int64_t k = first; k < last; ++k) {
    const T* src = rows.data() + (row + k - kRadius) * width;
    for (int m = 0; m < K; ++m) {
      T* dst = column.data() + m * width;
      const T* src_m = src + m * n;
      for (int64_t x = 0; x < width; ++x) dst[x] += w[k] * src_m[x];
    }
  }
}

template <typename T>
Forward forward_impl(const at::Tensor& a_tensor, const at::Tensor& b_tensor, bool with_gradient) {
  const Geometry g = geometry_of(a_tensor);
  const int64_t n = g.pixels(), width = g.width;
  const T* a = a_tensor.data_ptr<T>();
  const T* b = b_tensor.data_ptr<T>();
  const std::vector<T> rows = blur_rows<T, 5>(g, [&](int64_t i, std::array<T, 5>& v) {
    v = {a[i], b[i], a[i] * a[i], b[i] * b[i], a[i] * b[i]};
  });

  Forward f;
  T* d_maps = nullptr;
  if (with_gradient) {
    f.d_maps = at::empty({3, g.planes, g.height, width}, a_tensor.options());
    d_maps = f.d_maps.data_ptr<T>();
  }
  // Per-row sums, added in order afterwards: the result does not depend on
  // how the rows were split between threads.
  std::vector<double> row_sums(g.rows());
  at::parallel_for(0, g.rows(), kGrainRows, [&](int64_t begin, int64_t end) {
    std::vector<T> column(5 * width);
    for (int64_t row = begin; row < end; ++row) {
      blur_column<T, 5>(g, rows, row, column);
      double sum = 0;
      for (int64_t x = 0; x < width; ++x) {
        const ssim::PixelSsim<T> p = ssim::pixel_ssim(ssim::Moments<T>{
            column[x], column[width + x], column[2 * width + x], column[3 * width + x], column[4 * width + x]});
        sum += p.value;
        if (d_maps) {
          const int64_t i = row * width + x;
          d_maps[i] = p.d_mu_a;
          d_maps[n + i] = p.d_aa;
          d_maps[2 * n + i] = p.d_ab;
        }
      }
      row_sums[row] = sum;
    }
  });
  const double total = std::accumulate(row_sums.begin(), row_sums.end(), 0.0);
  f.value = at::scalar_tensor(total / double(n), a_tensor.options());
  return f;
}

template <typename T>
at::Tensor backward_impl(const at::Tensor& a_tensor, const at::Tensor& b_tensor, const at::Tensor& d_maps_tensor,
                         double grad_output) {
  const Geometry g = geometry_of(a_tensor);
  const int64_t n = g.pixels(), width = g.width;
  const T* a = a_tensor.data_ptr<T>();
  const T* b = b_tensor.data_ptr<T>();
  const T* d_maps = d_maps_tensor.data_ptr<T>();
  const std::vector<T> rows = blur_rows<T, 3>(g, [&](int64_t i, std::array<T, 3>& v) {
    v = {d_maps[i], d_maps[n + i], d_maps[2 * n + i]};
  });

  at::Tensor grad_tensor = at::empty_like(a_tensor);
  T* grad = grad_tensor.data_ptr<T>();
  const T scale = T(grad_output / double(n));
  at::parallel_for(0, g.rows(), kGrainRows, [&](int64_t begin, int64_t end) {
    std::vector<T> column(3 * width);
    for (int64_t row = begin; row < end; ++row) {
      blur_column<T, 3>(g, rows, row, column);
      for (int64_t x = 0; x < width; ++x) {
        const int64_t i = row * width + x;
        grad[i] = scale * ssim::input_gradient(column[x], column[width + x], column[2 * width + x], a[i], b[i]);
      }
    }
  });
  return grad_tensor;
}

}  // namespace

Forward forward_cpu(const at::Tensor& a, const at::Tensor& b, bool with_gradient) {
  Forward f;
  AT_DISPATCH_FLOATING_TYPES(a.scalar_type(), "fused_ssim_forward_cpu",
                             [&] { f = forward_impl<scalar_t>(a, b, with_gradient); });
  return f;
}

at::Tensor backward_cpu(const at::Tensor& a, const at::Tensor& b, const at::Tensor& d_maps,
                        const at::Tensor& grad_output) {
  at::Tensor grad;
  const double g = grad_output.item<double>();
  AT_DISPATCH_FLOATING_TYPES(a.scalar_type(), "fused_ssim_backward_cpu",
                             [&] { grad = backward_impl<scalar_t>(a, b, d_maps, g); });
  return grad;
}

}  // namespace tega::nn::fused_ssim_glue
