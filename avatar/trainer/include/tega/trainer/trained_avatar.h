#pragma once
// A trained avatar loaded from a run directory, for rendering, evaluation and
// export: the model with its checkpoint's Gaussians and network weights, the
// options it was trained with, and the phase (all parts the run trained).

#include <filesystem>

#include "tega/trainer/avatar_model.h"
#include "tega/trainer/options.h"

namespace tega::trainer {

struct TrainedAvatar {
  TrainOptions options;
  AvatarModel model;
  Phase phase;  // everything the run enabled, at the full SH degree
  int64_t iteration = 0;
};

// Reads RUN/options.yaml and RUN/checkpoint.safetensors. The dataset gives the
// template (topology, UVs, eyeballs) the avatar lives on. Throws tega::Error
// naming the file on anything missing or inconsistent.
TrainedAvatar load_avatar(const std::filesystem::path& run, const Dataset& dataset, const at::Device& device);

}  // namespace tega::trainer
