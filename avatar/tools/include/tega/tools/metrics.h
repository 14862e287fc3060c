#pragma once
// Image metrics of `tega eval` (TeGA §5), on float RGB images [3,H,W] in [0,1]:
// over the full image, and inside a mask (the dataset's matte, alpha > 0.5).
//
//  - PSNR = 10 log10(1 / MSE) over all channels; +inf for identical images.
//  - SSIM as in 3DGS (nn::ssim: 11x11 Gaussian window, σ = 1.5, zero
//    padding, C1 = 0.01², C2 = 0.03²). Masked: the mean of the SSIM map over
//    the mask's pixels (the windows still see the whole image).
//  - L1 = mean absolute difference over all channels.
//  - Two detail metrics stand in for LPIPS, which needs weights that tega
//    cannot ship: PSNR and L1 barely move when a render loses its fine
//    detail (wrinkles, stubble, eyelashes: a small part of the error energy),
//    while LPIPS and the paper's close-ups (TeGA §5, Figs. 6-7) show exactly
//    that. Both compute their filters over the whole image (edge-replicated
//    border, so the frame's edge is no edge) and average over the mask, so
//    the silhouette's sharpness counts as in ssim_masked.
//     - gradient_error: per channel, the Sobel gradient magnitude (kernels
//       /8: a ramp of slope s per pixel has magnitude s); the mean absolute
//       difference of the two images' magnitudes. Blur flattens edges, so
//       it lowers the render's magnitudes where the truth's are high.
//     - hf_psnr: the PSNR (peak 1, as psnr) of the high-frequency band, the
//       image minus its Gaussian blur (σ = 1.5 px, the SSIM window). The
//       band is linear, so only the difference's fine part counts: a smooth
//       shading or colour error scores near +inf, a blurred render about its
//       plain PSNR; the gap hf_psnr - psnr says how much of the error is not
//       detail.
// Masked values are NaN when the mask is empty.

#include <ATen/ATen.h>

#include <limits>
#include <map>
#include <string>
#include <vector>

namespace tega::tools {

double psnr(const at::Tensor& a, const at::Tensor& b);
double psnr(const at::Tensor& a, const at::Tensor& b, const at::Tensor& mask);  // mask [H,W] bool
at::Tensor ssim_map(const at::Tensor& a, const at::Tensor& b);                   // [H,W], mean over channels
double ssim(const at::Tensor& a, const at::Tensor& b);
double ssim(const at::Tensor& a, const at::Tensor& b, const at::Tensor& mask);
double l1(const at::Tensor& a, const at::Tensor& b);
double l1(const at::Tensor& a, const at::Tensor& b, const at::Tensor& mask);
double gradient_error(const at::Tensor& a, const at::Tensor& b, const at::Tensor& mask);
double hf_psnr(const at::Tensor& a, const at::Tensor& b, const at::Tensor& mask);

// The per-pixel maps [H,W] (double, on the images' device) whose means over a
// mask are the masked metrics above. Eval filters each view once and averages
// the maps over the head mask and over every close-up (closeups.h), so that a
// close-up's filters see the pixels around it, as the masked metrics' do.
struct ErrorMaps {
  at::Tensor squared_error;     // (a - b)², mean over channels: PSNR
  at::Tensor ssim;              // ssim_map
  at::Tensor gradient_error;    // |Sobel magnitude of a - of b|, mean over channels
  at::Tensor hf_squared_error;  // the difference's high-frequency band squared, mean over channels
};
ErrorMaps error_maps(const at::Tensor& a, const at::Tensor& b);

// psnr, ssim, hf_psnr and gradient_error inside `mask` [H,W] bool (NaN for an empty mask).
struct MaskedMetrics {
  double psnr, ssim, hf_psnr, gradient_error;
};
MaskedMetrics masked_metrics(const ErrorMaps& maps, const at::Tensor& mask);

// The PSNR of a squared-error map (ErrorMaps::squared_error) over `mask` [H,W] bool
// (NaN for an empty mask): eval's background PSNR, outside the head mask.
double masked_psnr(const at::Tensor& squared_error, const at::Tensor& mask);

// Mean and (population) standard deviation of the finite-or-infinite values
// given; NaN values (e.g. masked metrics of an empty mask) are left out and
// counted apart. With an infinite value the mean is infinite and the std NaN.
struct Statistics {
  double mean = std::numeric_limits<double>::quiet_NaN();
  double std = std::numeric_limits<double>::quiet_NaN();
  int64_t count = 0;    // values that entered the statistics
  int64_t skipped = 0;  // NaN values left out
};
Statistics statistics(const std::vector<double>& values);

}  // namespace tega::tools
