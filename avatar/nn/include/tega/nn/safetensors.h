#pragma once
// Checkpoints in the safetensors format, so that Python's `safetensors`
// package (and anything built on it) reads them unchanged:
//
//   u64 little-endian N | N bytes of JSON header | raw tensor bytes
//
// The header maps each tensor name to {"dtype", "shape", "data_offsets":
// [begin, end]} (offsets into the bytes after the header) and may carry
// string metadata under "__metadata__". It is padded with spaces to a
// multiple of 8 bytes. Data is little-endian and C-contiguous.
//
// Supported dtypes: F64, F32, F16, BF16, I64, I32, I16, I8, U8, BOOL.

#include <ATen/core/Tensor.h>

#include <filesystem>
#include <map>
#include <string>

namespace tega::nn {

using TensorMap = std::map<std::string, at::Tensor>;
using Metadata = std::map<std::string, std::string>;

struct SafetensorsFile {
  TensorMap tensors;  // on the CPU
  Metadata metadata;
};

// Writes atomically (a temporary name, then a rename). Tensors may live on
// any device and need not be contiguous; they are copied to the CPU.
// Throws tega::Error naming the file for an unsupported dtype, the reserved
// name "__metadata__", or a failed write.
void write_safetensors(const std::filesystem::path& file, const TensorMap& tensors,
                       const Metadata& metadata = {});

// Validates the whole file before trusting it: header length and JSON,
// dtype names, shapes, offsets within the data and matching dtype x shape,
// tensors tiling the data with neither gaps nor overlaps (as the Rust
// reference implementation demands). Throws tega::Error naming the file and,
// where one is at fault, the tensor.
SafetensorsFile read_safetensors(const std::filesystem::path& file);

}  // namespace tega::nn
