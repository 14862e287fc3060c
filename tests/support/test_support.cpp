#include "test_support.h"

#include <cstdlib>
#include <fstream>
#include <random>

namespace tega::test {

std::optional<std::filesystem::path> shared_data_dir() {
  const char* env = std::getenv("TEGA_SHARED_DATA");
  if (!env || !std::filesystem::is_directory(env)) return std::nullopt;
  return std::filesystem::path(env);
}

std::optional<std::filesystem::path> ict_facekit_dir() {
  auto shared = shared_data_dir();
  if (!shared) return std::nullopt;
  auto dir = *shared / "ict-facekit";
  if (!std::filesystem::exists(dir / "generic_neutral_mesh.obj")) return std::nullopt;
  return dir;
}

TempDir::TempDir() {
  std::random_device rd;
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "tega";
  path_ = std::filesystem::temp_directory_path() / ("tega-test-" + name + "-" + std::to_string(rd()));
  std::filesystem::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

void write_text(const std::filesystem::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
}

}  // namespace tega::test
