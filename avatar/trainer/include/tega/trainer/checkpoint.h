#pragma once
// A training checkpoint is one safetensors file (readable from Python):
//   gaussians.*          canonical Gaussians
//   network.*            U-Net and MLP weights
//   <group>.adam_m/_v    Adam moments per parameter group, adam.steps
//   densify.*            densification statistics gathered since the last densification
//   trainer.iteration    iterations completed; trainer.rng_state: the sampling generator
// and metadata: format, tega version, options (YAML).

#include <ATen/ATen.h>

#include <filesystem>
#include <map>
#include <string>

namespace tega::trainer {

// Metadata key and value that say the networks were trained on a displacement
// texture without the eyeball triangles (docs/training.md#the-encoders-blind-spot).
inline constexpr const char* kTextureMetadataKey = "displacement_texture";
inline constexpr const char* kTextureWithoutEyeballs = "without eyeballs";
// Metadata key and value that say the Gaussians' uv lie in the layout that
// AvatarModel derives now (docs/uvd-rigging.md#multi-tile-layouts-packed-into-the-unit-square).
inline constexpr const char* kUvLayoutMetadataKey = "uv_layout";
inline constexpr const char* kUvLayoutChartsApartPacked = "charts apart, packed into the unit square";

struct Checkpoint {
  std::map<std::string, at::Tensor> tensors;
  std::map<std::string, std::string> metadata;
  int64_t iteration() const;
};

// Refuses to write non-finite parameters (throws tega::Error), so a checkpoint
// is always usable. Atomic.
void write_checkpoint(const std::filesystem::path& file, const Checkpoint& checkpoint);
Checkpoint read_checkpoint(const std::filesystem::path& file);

}  // namespace tega::trainer
