#pragma once
// Whole-file binary reading and writing for the COLMAP formats (array files,
// fused.ply), which are little-endian like every machine tega runs on.

#include <bit>
#include <filesystem>
#include <string>

namespace tega::mvs {

static_assert(std::endian::native == std::endian::little, "COLMAP's binary files are little-endian");

std::string read_binary_file(const std::filesystem::path& file);  // throws tega::Error
void write_binary_file_atomic(const std::filesystem::path& file, const std::string& bytes);

}  // namespace tega::mvs
