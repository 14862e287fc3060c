#include "tega/tools/metrics.h"

#include <cmath>

namespace tega::tools {

namespace {

constexpr int kWindow = 11;
constexpr double kSigma = 1.5, kC1 = 0.01 * 0.01, kC2 = 0.03 * 0.03;

void check_pair(const at::Tensor& a, const at::Tensor& b) {
  TORCH_CHECK(a.dim() == 3 && a.sizes() == b.sizes(), "metrics compare [C,H,W] images of one size, got ", a.sizes(),
              " and ", b.sizes());
}

double mse_to_psnr(double mse) {
  return mse > 0 ? -10.0 * std::log10(mse) : std::numeric_limits<double>::infinity();
}

// The 1-D Gaussian of the SSIM window, also the blur of hf_psnr's band.
at::Tensor gaussian_taps(const at::TensorOptions& options) {
  const at::Tensor x = at::arange(kWindow, options) - kWindow / 2;
  const at::Tensor g = at::exp(-x.square() / (2 * kSigma * kSigma));
  return g / g.sum();
}

// [C,H,W] as C one-channel images [C,1,H+2r,W+2r], in double.
at::Tensor replicate_padded(const at::Tensor& image, int64_t r) {
  return at::replication_pad2d(image.to(at::kDouble).unsqueeze(1), {r, r, r, r});
}

at::Tensor gradient_magnitude(const at::Tensor& image /* [C,H,W] */) {
  const at::Tensor padded = replicate_padded(image, 1);
  const at::Tensor sobel_x =
      at::tensor({-1.0, 0.0, 1.0, -2.0, 0.0, 2.0, -1.0, 0.0, 1.0}, padded.options()).view({3, 3}) / 8;
  const at::Tensor kernels = at::stack({sobel_x, sobel_x.t()}).unsqueeze(1);  // [2,1,3,3]: d/dx, d/dy
  return at::conv2d(padded, kernels).square().sum(1).sqrt();                  // [C,H,W]
}

at::Tensor high_pass(const at::Tensor& image /* [C,H,W] */) {
  const at::Tensor padded = replicate_padded(image, kWindow / 2);
  const at::Tensor g = gaussian_taps(padded.options());
  // Separable: 22 taps a pixel instead of 121, which matters at 4K on the CPU.
  const at::Tensor blurred = at::conv2d(at::conv2d(padded, g.view({1, 1, kWindow, 1})), g.view({1, 1, 1, kWindow}));
  return image.to(at::kDouble) - blurred.squeeze(1);
}

double masked_mean(const at::Tensor& per_pixel /* [H,W] */, const at::Tensor& mask) {
  const double pixels = mask.sum().item<double>();
  if (pixels == 0) return std::numeric_limits<double>::quiet_NaN();
  return (per_pixel.to(at::kDouble) * mask.to(at::kDouble)).sum().item<double>() / pixels;
}

at::Tensor squared_error_map(const at::Tensor& a, const at::Tensor& b) {
  return (a.to(at::kDouble) - b.to(at::kDouble)).square().mean(0);
}

at::Tensor gradient_error_map(const at::Tensor& a, const at::Tensor& b) {
  return (gradient_magnitude(a) - gradient_magnitude(b)).abs().mean(0);
}

// The band is linear: filtering the difference once is the band of each.
at::Tensor hf_squared_error_map(const at::Tensor& a, const at::Tensor& b) {
  return high_pass(a.to(at::kDouble) - b.to(at::kDouble)).square().mean(0);
}

}  // namespace

double masked_psnr(const at::Tensor& squared_error, const at::Tensor& mask) {
  const double mse = masked_mean(squared_error, mask);
  return std::isnan(mse) ? mse : mse_to_psnr(mse);
}

double psnr(const at::Tensor& a, const at::Tensor& b) {
  check_pair(a, b);
  return mse_to_psnr((a.to(at::kDouble) - b.to(at::kDouble)).square().mean().item<double>());
}

double psnr(const at::Tensor& a, const at::Tensor& b, const at::Tensor& mask) {
  check_pair(a, b);
  return masked_psnr(squared_error_map(a, b), mask);
}

at::Tensor ssim_map(const at::Tensor& a_in, const at::Tensor& b_in) {
  check_pair(a_in, b_in);
  const at::Tensor a = a_in.to(at::kDouble), b = b_in.to(at::kDouble);
  const int64_t channels = a.size(0);
  const at::Tensor g = gaussian_taps(a.options());
  // The window is separable, zero padding too: 22 taps a pixel instead of 121, and the five
  // blurred images as one batch of one-channel images rather than a grouped convolution,
  // which libtorch's CPU runs through a dense im2col (3.5 s a 640 x 480 view).
  const at::Tensor stacked = at::cat({a, b, a * a, b * b, a * b}).unsqueeze(1);  // [5C,1,H,W]
  const int64_t r = kWindow / 2, no_stride[] = {1, 1}, down_pad[] = {r, 0}, across_pad[] = {0, r};
  const at::Tensor down = at::conv2d(stacked, g.view({1, 1, kWindow, 1}), at::Tensor(), no_stride, down_pad);
  const std::vector<at::Tensor> blurred =
      at::conv2d(down, g.view({1, 1, 1, kWindow}), at::Tensor(), no_stride, across_pad).squeeze(1).split(channels);
  const at::Tensor &mu_a = blurred[0], &mu_b = blurred[1];
  const at::Tensor var_a = blurred[2] - mu_a * mu_a, var_b = blurred[3] - mu_b * mu_b;
  const at::Tensor cov = blurred[4] - mu_a * mu_b;
  const at::Tensor map = ((2 * mu_a * mu_b + kC1) * (2 * cov + kC2)) /
                         ((mu_a * mu_a + mu_b * mu_b + kC1) * (var_a + var_b + kC2));
  return map.mean(0);
}

double ssim(const at::Tensor& a, const at::Tensor& b) { return ssim_map(a, b).mean().item<double>(); }

double ssim(const at::Tensor& a, const at::Tensor& b, const at::Tensor& mask) {
  return masked_mean(ssim_map(a, b), mask);
}

double l1(const at::Tensor& a, const at::Tensor& b) {
  check_pair(a, b);
  return (a.to(at::kDouble) - b.to(at::kDouble)).abs().mean().item<double>();
}

double l1(const at::Tensor& a, const at::Tensor& b, const at::Tensor& mask) {
  check_pair(a, b);
  return masked_mean((a.to(at::kDouble) - b.to(at::kDouble)).abs().mean(0), mask);
}

double gradient_error(const at::Tensor& a, const at::Tensor& b, const at::Tensor& mask) {
  check_pair(a, b);
  return masked_mean(gradient_error_map(a, b), mask);
}

double hf_psnr(const at::Tensor& a, const at::Tensor& b, const at::Tensor& mask) {
  check_pair(a, b);
  return masked_psnr(hf_squared_error_map(a, b), mask);
}

ErrorMaps error_maps(const at::Tensor& a, const at::Tensor& b) {
  check_pair(a, b);
  return {squared_error_map(a, b), ssim_map(a, b), gradient_error_map(a, b), hf_squared_error_map(a, b)};
}

MaskedMetrics masked_metrics(const ErrorMaps& maps, const at::Tensor& mask) {
  return {masked_psnr(maps.squared_error, mask), masked_mean(maps.ssim, mask),
          masked_psnr(maps.hf_squared_error, mask), masked_mean(maps.gradient_error, mask)};
}

Statistics statistics(const std::vector<double>& values) {
  Statistics s;
  double sum = 0;
  bool infinite = false;
  for (double v : values) {
    if (std::isnan(v)) {
      ++s.skipped;
      continue;
    }
    ++s.count;
    if (std::isinf(v)) infinite = true;
    sum += v;
  }
  if (s.count == 0) return s;
  s.mean = sum / s.count;
  if (infinite) return s;  // mean ±inf (or NaN for +inf and -inf together), std undefined
  double squares = 0;
  for (double v : values)
    if (!std::isnan(v)) squares += (v - s.mean) * (v - s.mean);
  s.std = std::sqrt(squares / s.count);
  return s;
}

}  // namespace tega::tools
