#pragma once
// Module parameters (and buffers) ↔ safetensors tensor maps, keyed by their
// dotted module paths ("unet.down.0.0.weight", "deformation.output.bias").

#include <torch/nn/module.h>

#include <filesystem>
#include <string>

#include "tega/nn/safetensors.h"

namespace tega::nn {

// Every parameter and buffer of `module`, prefixed by `prefix` (e.g. "network.").
TensorMap module_tensors(const torch::nn::Module& module, const std::string& prefix = "");

// Copies tensors[prefix + name] into each parameter and buffer of `module`, on
// the module's device. Throws tega::Error naming `source` and the tensor when
// one is missing or has another shape; tensors without the prefix, or
// unknown to the module, are left to the caller.
void load_module_tensors(torch::nn::Module& module, const TensorMap& tensors, const std::filesystem::path& source,
                         const std::string& prefix = "");

}  // namespace tega::nn
