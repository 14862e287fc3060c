#pragma once
// SHA-256 (FIPS 180-4) for the content hashes in shard manifests. Our own,
// because OpenSSL is not among the dependencies every build machine has.

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace tega::pipeline {

class Sha256 {
 public:
  Sha256();
  void update(std::string_view bytes);
  std::string hex_digest();  // finishes the hash; update() must not follow

 private:
  void compress(const uint8_t* block);

  std::array<uint32_t, 8> state_;
  std::array<uint8_t, 64> buffer_{};
  size_t buffered_ = 0;
  uint64_t total_bytes_ = 0;
};

std::string sha256_hex(std::string_view bytes);
std::string sha256_file(const std::filesystem::path& file);  // throws tega::Error naming the file

}  // namespace tega::pipeline
