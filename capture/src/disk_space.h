#pragma once
// Free space on the disk holding a folder, for the writer's guard and the
// recorder's start-up check.
#include <filesystem>

namespace tega::capture {

// Megabytes available to this user; a negative number when it cannot be read.
inline double free_mb(const std::filesystem::path& folder) {
  std::error_code error;
  const auto space = std::filesystem::space(folder, error);
  return error ? -1 : double(space.available) / (1024.0 * 1024.0);
}

}  // namespace tega::capture
