#pragma once
// Expression encoders: from the UV displacement texture [B,3,N,N] (the
// tracked mesh minus the neutral one, pose removed; see uv_raster.h) to the
// latents that condition the deformation and shading MLPs (TeGA §3.4–3.5).
//
// Both encoders return two latents, one for deformation and one for shading:
// "the last layer is duplicated", so the two fields can be regularised
// differently (only deformation is smoothed).
//
// No normalisation layers: GroupNorm/BatchNorm would divide out the overall
// magnitude of the displacements, making a half smile and a full smile look
// alike. Instead the input is multiplied by `input_scale` (default 100:
// centimetres, so typical expression offsets are O(1)).

#include <ATen/core/Tensor.h>
#include <torch/nn/module.h>
#include <torch/nn/modules/container/modulelist.h>
#include <torch/nn/modules/conv.h>
#include <torch/nn/modules/linear.h>
#include <torch/nn/pimpl.h>

#include <utility>
#include <vector>

namespace tega::nn {

struct LatentPair {
  at::Tensor deformation;  // [B,C,H,W]
  at::Tensor shading;      // [B,C,H,W]
};

// A U-Net. Level i (0 = full resolution) has widths[i] channels and runs two
// 3x3 conv + LeakyReLU(0.2); levels are joined by 2x2 average pooling on the
// way down and nearest-neighbour upsampling plus skip concatenation on the way
// up. Two 1x1 convolutions (the duplicated last layer) give the latents at
// full resolution. N must be divisible by 2^(levels-1).
//
// Defaults, widths {32, 64, 128, 256}: 256² → 32² at the bottom, 1.95 M
// parameters, about 11 G multiply-adds per 256² frame.
struct UNetOptions {
  int64_t in_channels = 3;
  int64_t latent_channels = 64;
  std::vector<int64_t> widths{32, 64, 128, 256};
  double input_scale = 100.0;
};

class UNetImpl : public torch::nn::Module {
 public:
  explicit UNetImpl(const UNetOptions& options);
  LatentPair forward(const at::Tensor& texture);  // [B,in,N,N] → 2 x [B,latent,N,N]

 private:
  UNetOptions options_;
  torch::nn::ModuleList down_, up_;  // two-conv blocks per level
  torch::nn::Conv2d deformation_head_{nullptr}, shading_head_{nullptr};
};
TORCH_MODULE(UNet);

// The paper's "MLP" ablation (§5.2.1): an 8-layer CNN encoder that produces a
// single latent code for the whole expression instead of a latent texture.
// Each layer is a stride-2 3x3 conv + LeakyReLU(0.2) (256² → 1² for 8
// layers), widths 16, 32, ... capped at 256; the remaining pixels are
// averaged and two linear heads give the codes, returned as [B,C,1,1]
// textures so that sampling them (sample_latent) broadcasts one code to
// every Gaussian. 2.2 M parameters with the defaults.
struct GlobalEncoderOptions {
  int64_t in_channels = 3;
  int64_t latent_channels = 64;
  int64_t layers = 8;
  double input_scale = 100.0;
};

class GlobalEncoderImpl : public torch::nn::Module {
 public:
  explicit GlobalEncoderImpl(const GlobalEncoderOptions& options);
  LatentPair forward(const at::Tensor& texture);  // [B,in,N,N] → 2 x [B,latent,1,1]

 private:
  GlobalEncoderOptions options_;
  torch::nn::ModuleList convs_;
  torch::nn::Linear deformation_head_{nullptr}, shading_head_{nullptr};
};
TORCH_MODULE(GlobalEncoder);

// Bilinear lookup of a latent texture [C,H,W] at uv [N,2] → [N,C].
//
// Convention (the one uv_raster.h writes): u runs along columns, left to
// right; v = 0 is the bottom row (OBJ), so texel (row r, column c) has its
// centre at u = (c + 0.5)/W, v = 1 - (r + 0.5)/H. This is grid_sample with
// align_corners = false and x = 2u - 1, y = 1 - 2v. Outside the outermost
// texel centres the border texels extend (padding "border"), so a Gaussian
// at u = 0 does not fade towards zero. A [C,1,1] texture yields its single
// code everywhere.
at::Tensor sample_latent(const at::Tensor& latent, const at::Tensor& uv);

}  // namespace tega::nn
