#include "fuzz_target.h"
#include "tega/nn/safetensors.h"

// Checkpoints and exported networks (safetensors: header length, JSON header, tensor bytes).
TEGA_FUZZ_TARGET(safetensors) { tega::nn::read_safetensors(tega::fuzz::input_file("model.safetensors", data, size)); }
