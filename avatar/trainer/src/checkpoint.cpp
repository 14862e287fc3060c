#include "tega/trainer/checkpoint.h"

#include "tega/core/error.h"
#include "tega/nn/safetensors.h"

namespace tega::trainer {

constexpr const char* kFormat = "tega-avatar-checkpoint";

int64_t Checkpoint::iteration() const {
  auto it = tensors.find("trainer.iteration");
  if (it == tensors.end()) throw Error("checkpoint has no trainer.iteration");
  return it->second.item<int64_t>();
}

void write_checkpoint(const std::filesystem::path& file, const Checkpoint& checkpoint) {
  for (const auto& [name, tensor] : checkpoint.tensors) {
    if (tensor.is_floating_point() && !at::isfinite(tensor).all().item<bool>()) {
      throw Error(file, "not written: tensor '" + name + "' holds NaN or Inf");
    }
  }
  auto metadata = checkpoint.metadata;
  metadata["format"] = kFormat;
  nn::write_safetensors(file, checkpoint.tensors, metadata);
}

Checkpoint read_checkpoint(const std::filesystem::path& file) {
  nn::SafetensorsFile contents = nn::read_safetensors(file);
  auto format = contents.metadata.find("format");
  if (format == contents.metadata.end() || format->second != kFormat) {
    throw Error(file, "is not a tega avatar checkpoint");
  }
  return {std::move(contents.tensors), std::move(contents.metadata)};
}

}  // namespace tega::trainer
