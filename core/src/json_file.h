#pragma once
// JSON manifests core reads (dataset.json, take.json, capture.json).
#include <filesystem>
#include <nlohmann/json.hpp>

namespace tega::detail {

// Throws tega::Error naming the file when it is missing or not valid JSON.
nlohmann::json read_json_file(const std::filesystem::path& file);

}  // namespace tega::detail
