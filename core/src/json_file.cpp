#include "tega/core/json_file.h"

#include "tega/core/error.h"
#include "tega/core/files.h"

namespace tega {

nlohmann::json read_json_file(const std::filesystem::path& file) {
  try {
    return nlohmann::json::parse(read_text_file(file));
  } catch (const nlohmann::json::exception& e) {
    throw Error(file, std::string("is not valid JSON: ") + e.what());
  }
}

}  // namespace tega
