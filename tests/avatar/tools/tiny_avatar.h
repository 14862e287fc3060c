#pragma once
// A small avatar on write_tiny_dataset's one-triangle template, built
// directly (no training): random Gaussians over the triangle and a network
// perturbed away from its identity start, so that deformation and shading
// both do something. The triangle is not an eyeball here, so the
// deformation field applies to it.

#include <ATen/ATen.h>

#include <memory>

#include "tega/core/dataset.h"
#include "tega/trainer/trained_avatar.h"
#include "test_support.h"

namespace tega::test {

inline trainer::TrainOptions tiny_network_options() {
  trainer::TrainOptions o;
  o.network.texture_size = 16;
  o.network.unet_widths = {4, 8};
  o.network.latent_channels = 4;
  o.network.mlp_hidden = 8;
  o.uv_lookup.resolution = 32;
  o.background = {0.1, 0.2, 0.3};
  return o;
}

// Random Gaussians over the triangle (uv = its xy, 1 m per uv unit).
inline trainer::Gaussians random_gaussians(int64_t n) {
  at::manual_seed(7);
  trainer::Gaussians g;
  at::Tensor uv = at::rand({n, 2}) * 0.8 + 0.05;
  const at::Tensor outside = uv.sum(1, true).gt(0.9);
  uv = at::where(outside, 0.95 - uv.flip(1), uv);  // fold into the triangle
  g.uvd = at::cat({uv, (at::rand({n, 1}) - 0.5) * 0.04}, 1);
  g.log_scale = at::log(at::rand({n, 3}) * 0.03 + 0.01);
  g.rotation = at::randn({n, 4});
  g.sh_dc = at::randn({n, 1, 3}) * 0.8;
  g.sh_rest = at::randn({n, 15, 3}) * 0.3;
  g.opacity_logit = at::randn({n}) * 2;
  return g;
}

struct TinyAvatar {
  TempDir tmp;
  Dataset dataset;
  std::unique_ptr<trainer::TrainedAvatar> avatar;

  TinyAvatar() {
    write_tiny_dataset(tmp / "data");
    dataset = read_dataset(tmp / "data");
    dataset.eyeball_faces.clear();
    const trainer::TrainOptions options = tiny_network_options();
    // The networks' initial weights come from libtorch's global generator,
    // whose seed otherwise differs from process to process.
    at::manual_seed(7);
    avatar = std::make_unique<trainer::TrainedAvatar>(
        trainer::TrainedAvatar{options, trainer::AvatarModel(dataset, options, at::kCPU), {true, true, 3}, 0});
    avatar->model.gaussians = random_gaussians(300);
    at::NoGradGuard no_grad;
    for (auto& p : avatar->model.network->parameters()) p.add_(at::randn_like(p) * 0.1);
  }
  trainer::AvatarModel& model() { return avatar->model; }
};

}  // namespace tega::test
