#include "tega/nn/safetensors.h"

#include <ATen/ATen.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <fstream>
#include <limits>
#include <optional>
#include <vector>

#include "tega/core/error.h"
#include "tega/core/files.h"

namespace tega::nn {
namespace {

// The format stores little-endian bytes; we copy tensor memory verbatim.
static_assert(std::endian::native == std::endian::little, "safetensors I/O assumes a little-endian host");

// The Rust reference refuses headers above 100 MB; so do we, which also keeps
// a corrupt length from turning into a huge allocation.
constexpr uint64_t kMaxHeaderBytes = 100'000'000;
constexpr const char* kMetadataKey = "__metadata__";

struct DtypeName {
  at::ScalarType type;
  const char* name;
};
constexpr std::array<DtypeName, 10> kDtypes{{{at::kDouble, "F64"},
                                              {at::kFloat, "F32"},
                                              {at::kHalf, "F16"},
                                              {at::kBFloat16, "BF16"},
                                              {at::kLong, "I64"},
                                              {at::kInt, "I32"},
                                              {at::kShort, "I16"},
                                              {at::kChar, "I8"},
                                              {at::kByte, "U8"},
                                              {at::kBool, "BOOL"}}};

std::optional<at::ScalarType> dtype_from_name(const std::string& name) {
  for (const auto& d : kDtypes)
    if (name == d.name) return d.type;
  return std::nullopt;
}

const char* dtype_name(at::ScalarType type, const std::filesystem::path& file, const std::string& tensor) {
  for (const auto& d : kDtypes)
    if (type == d.type) return d.name;
  throw Error(file, "tensor '" + tensor + "' has dtype " + std::string(c10::toString(type)) +
                        ", which safetensors I/O does not support");
}

struct Entry {
  std::string name;
  at::Tensor data;  // contiguous, on the CPU
  uint64_t bytes = 0;
};

}  // namespace

void write_safetensors(const std::filesystem::path& file, const TensorMap& tensors, const Metadata& metadata) {
  std::vector<Entry> entries;
  entries.reserve(tensors.size());
  for (const auto& [name, tensor] : tensors) {
    if (name == kMetadataKey) throw Error(file, "'__metadata__' cannot name a tensor");
    if (!tensor.defined()) throw Error(file, "tensor '" + name + "' is undefined");
    at::Tensor cpu = tensor.detach().to(at::kCPU).contiguous();
    dtype_name(cpu.scalar_type(), file, name);  // rejects unsupported dtypes before anything is written
    entries.push_back({name, cpu, static_cast<uint64_t>(cpu.numel()) * cpu.element_size()});
  }
  // Larger elements first, then by name, as the Rust writer orders them: with
  // the header padded to 8 bytes every tensor then starts aligned to its
  // element size, which zero-copy readers rely on.
  std::stable_sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return a.data.element_size() > b.data.element_size();
  });

  nlohmann::ordered_json header = nlohmann::ordered_json::object();
  if (!metadata.empty()) {
    nlohmann::ordered_json meta = nlohmann::ordered_json::object();
    for (const auto& [key, value] : metadata) meta[key] = value;
    header[kMetadataKey] = std::move(meta);
  }
  uint64_t offset = 0;
  for (const auto& e : entries) {
    header[e.name] = {{"dtype", dtype_name(e.data.scalar_type(), file, e.name)},
                      {"shape", e.data.sizes().vec()},
                      {"data_offsets", {offset, offset + e.bytes}}};
    offset += e.bytes;
  }
  std::string text = header.dump();
  text.append((8 - text.size() % 8) % 8, ' ');

  write_file_atomic(file, [&](const std::filesystem::path& temp) {
    std::ofstream out(temp, std::ios::binary);
    const uint64_t length = text.size();
    out.write(reinterpret_cast<const char*>(&length), sizeof(length));
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    for (const auto& e : entries)
      out.write(static_cast<const char*>(e.data.data_ptr()), static_cast<std::streamsize>(e.bytes));
    out.close();
    if (!out) throw Error(file, "writing failed");
  });
}

namespace {

struct Parsed {
  std::string name;
  at::ScalarType type;
  std::vector<int64_t> shape;
  uint64_t begin, end;
};

uint64_t non_negative(const nlohmann::json& value, const std::filesystem::path& file, const std::string& what) {
  // nlohmann parses every non-negative integer as unsigned.
  if (!value.is_number_unsigned()) throw Error(file, what + " must be a non-negative integer");
  return value.get<uint64_t>();
}

Parsed parse_entry(const std::string& name, const nlohmann::json& info, const std::filesystem::path& file) {
  const std::string where = "tensor '" + name + "'";
  if (!info.is_object()) throw Error(file, where + ": header entry is not an object");
  for (const auto& [key, _] : info.items())
    if (key != "dtype" && key != "shape" && key != "data_offsets")
      throw Error(file, where + ": unknown header field '" + key + "'");
  if (!info.contains("dtype") || !info["dtype"].is_string()) throw Error(file, where + ": missing dtype");
  const auto type = dtype_from_name(info["dtype"].get<std::string>());
  if (!type) throw Error(file, where + ": unsupported dtype '" + info["dtype"].get<std::string>() + "'");
  if (!info.contains("shape") || !info["shape"].is_array()) throw Error(file, where + ": missing shape");
  if (!info.contains("data_offsets") || !info["data_offsets"].is_array() || info["data_offsets"].size() != 2)
    throw Error(file, where + ": data_offsets must be [begin, end]");

  Parsed p{name, *type, {}, 0, 0};
  // A hostile shape must not wrap the byte count around.
  uint64_t bytes = c10::elementSize(*type);
  for (const auto& dim : info["shape"]) {
    const uint64_t d = non_negative(dim, file, where + ": shape entries");
    if (d > static_cast<uint64_t>(std::numeric_limits<int64_t>::max()))
      throw Error(file, where + ": shape entry too large");
    p.shape.push_back(static_cast<int64_t>(d));
    if (d != 0 && bytes > std::numeric_limits<uint64_t>::max() / d)
      throw Error(file, where + ": shape too large");
    bytes *= d;
  }
  p.begin = non_negative(info["data_offsets"][0], file, where + ": data_offsets");
  p.end = non_negative(info["data_offsets"][1], file, where + ": data_offsets");
  if (p.begin > p.end) throw Error(file, where + ": data_offsets begin after end");
  if (p.end - p.begin != bytes)
    throw Error(file, where + ": data_offsets span " + std::to_string(p.end - p.begin) + " bytes, but dtype " +
                          info["dtype"].get<std::string>() + " x shape needs " + std::to_string(bytes));
  return p;
}

}  // namespace

SafetensorsFile read_safetensors(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(file, "cannot open");
  std::error_code ec;
  const uint64_t file_size = std::filesystem::file_size(file, ec);
  if (ec) throw Error(file, "cannot read its size: " + ec.message());
  if (file_size < 8) throw Error(file, "too short for a safetensors header length");

  uint64_t header_size = 0;
  in.read(reinterpret_cast<char*>(&header_size), sizeof(header_size));
  if (header_size > kMaxHeaderBytes) throw Error(file, "header length " + std::to_string(header_size) + " is too large");
  if (header_size > file_size - 8)
    throw Error(file, "truncated: header length " + std::to_string(header_size) + " exceeds the file");
  std::string text(header_size, '\0');
  in.read(text.data(), static_cast<std::streamsize>(header_size));
  if (!in) throw Error(file, "cannot read the header");
  const uint64_t data_size = file_size - 8 - header_size;

  nlohmann::json header;
  try {
    header = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw Error(file, std::string("malformed JSON header: ") + e.what());
  }
  if (!header.is_object()) throw Error(file, "the JSON header is not an object");

  SafetensorsFile result;
  std::vector<Parsed> parsed;
  for (const auto& [key, value] : header.items()) {
    if (key == kMetadataKey) {
      if (!value.is_object()) throw Error(file, "__metadata__ is not an object");
      for (const auto& [mk, mv] : value.items()) {
        if (!mv.is_string()) throw Error(file, "__metadata__ value '" + mk + "' is not a string");
        result.metadata[mk] = mv.get<std::string>();
      }
      continue;
    }
    parsed.push_back(parse_entry(key, value, file));
  }

  // The tensors must tile [0, data_size) exactly.
  std::sort(parsed.begin(), parsed.end(), [](const Parsed& a, const Parsed& b) {
    return a.begin != b.begin ? a.begin < b.begin : a.end < b.end;
  });
  uint64_t expected = 0;
  for (const auto& p : parsed) {
    if (p.end > data_size)
      throw Error(file, "tensor '" + p.name + "': data_offsets end " + std::to_string(p.end) +
                            " lies beyond the data (" + std::to_string(data_size) + " bytes; truncated file?)");
    if (p.begin != expected)
      throw Error(file, "tensor '" + p.name + "': data_offsets begin " + std::to_string(p.begin) + " leaves " +
                            (p.begin > expected ? "a gap" : "an overlap") + " (expected " +
                            std::to_string(expected) + ")");
    expected = p.end;
  }
  if (expected != data_size)
    throw Error(file, std::to_string(data_size - expected) + " bytes after the last tensor belong to none");

  for (const auto& p : parsed) {
    at::Tensor t = at::empty(p.shape, at::TensorOptions().dtype(p.type));
    in.seekg(static_cast<std::streamoff>(8 + header_size + p.begin));
    in.read(static_cast<char*>(t.data_ptr()), static_cast<std::streamsize>(p.end - p.begin));
    if (!in) throw Error(file, "tensor '" + p.name + "': cannot read its data");
    result.tensors.emplace(p.name, std::move(t));
  }
  return result;
}

}  // namespace tega::nn
