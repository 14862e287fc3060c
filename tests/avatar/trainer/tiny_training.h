#pragma once
// Options and checks for tests that train on write_tiny_dataset's dataset on the CPU.

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "tega/trainer/checkpoint.h"
#include "tega/trainer/options.h"

namespace tega::test {

// Small enough for a few CPU iterations, yet every part of a step runs (the
// tests write the tiny dataset with its triangle on the skin, for the field):
// the warm-up ends at iteration 2 and densification runs every 2 iterations.
inline trainer::TrainOptions tiny_options() {
  trainer::TrainOptions o;
  o.iterations = 6;
  o.initial_gaussians = 64;
  o.warmup = 2.0 / 6.0;
  o.densify.start = 0.0;
  o.densify.stop = 1.0;
  o.densify.interval = 2.0 / 6.0;
  o.densify.gradient_threshold = 0.0;  // densify every visible Gaussian
  o.densify.opacity_reset_interval = 5.0 / 6.0;
  o.loss.smoothness_samples = 32;
  o.network.texture_size = 16;
  o.network.unet_widths = {4, 8};
  o.network.latent_channels = 4;
  o.network.mlp_hidden = 8;
  o.uv_lookup.resolution = 32;
  o.checkpoint_every = 100;
  o.log_every = 1;
  o.loader_threads = 1;
  o.prefetch = 2;
  o.cpu_threads = 1;
  return o;
}

// Every learning rate of `options` times `factor`.
inline trainer::TrainOptions scaled_learning_rates(trainer::TrainOptions options, double factor) {
  auto& lr = options.learning_rates;
  for (double* rate : {&lr.position, &lr.position_final, &lr.sh_dc, &lr.sh_rest, &lr.opacity, &lr.scale, &lr.rotation,
                       &lr.network, &lr.network_final}) {
    *rate *= factor;
  }
  return options;
}

// The Gaussians and network weights of two runs' final checkpoints agree.
inline void expect_same_parameters(const std::filesystem::path& a_run, const std::filesystem::path& b_run) {
  const trainer::Checkpoint a = trainer::read_checkpoint(a_run / "checkpoint.safetensors");
  const trainer::Checkpoint b = trainer::read_checkpoint(b_run / "checkpoint.safetensors");
  int compared = 0;
  for (const auto& [name, tensor] : a.tensors) {
    if (name.rfind("gaussians.", 0) != 0 && name.rfind("network.", 0) != 0) continue;
    ASSERT_TRUE(b.tensors.count(name)) << name;
    ASSERT_EQ(tensor.sizes(), b.tensors.at(name).sizes()) << name;
    EXPECT_TRUE(at::allclose(tensor, b.tensors.at(name), 1e-5, 1e-7))
        << name << ": max difference " << (tensor - b.tensors.at(name)).abs().max().item<double>();
    ++compared;
  }
  EXPECT_GE(compared, 10);
}

}  // namespace tega::test
