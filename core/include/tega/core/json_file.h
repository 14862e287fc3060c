#pragma once
// Reading a JSON file, with errors that name it.

#include <filesystem>
#include <nlohmann/json.hpp>

namespace tega {

// Throws tega::Error naming the file when it is missing or not valid JSON.
nlohmann::json read_json_file(const std::filesystem::path& file);

}  // namespace tega
