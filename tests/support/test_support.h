#pragma once
// Helpers shared by the test suites.

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <optional>
#include <string>

namespace tega::test {

// ../shared/data (from TEGA_SHARED_DATA), or nullopt when it is absent.
std::optional<std::filesystem::path> shared_data_dir();
std::optional<std::filesystem::path> ict_facekit_dir();

// A fresh, empty directory removed when the object dies.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

void write_text(const std::filesystem::path& file, const std::string& text);

// The message of the tega::Error that `action` throws; a test failure when it
// throws none.
std::string error_message(const std::function<void()>& action);

// Writes a valid dataset into `root`: a one-triangle template, cameras
// cam00 (train) and cam01 (test), frames smile_000000 (train) and
// blink_000000 (test), 8x6 RGBA images whose pixels encode (camera, frame):
// R = 10 * camera index + frame index. The triangle is an eyeball's (the
// deformation field leaves it alone) unless `eyeball` is false.
void write_tiny_dataset(const std::filesystem::path& root, bool eyeball = true);

}  // namespace tega::test

// Skips the current test, with a message, when ICT-FaceKit is not beside the project.
#define TEGA_REQUIRE_ICT_FACEKIT(dir_var)                                             \
  const auto dir_var##_opt = ::tega::test::ict_facekit_dir();                         \
  if (!dir_var##_opt) GTEST_SKIP() << "ICT-FaceKit not found under ../shared/data"; \
  const std::filesystem::path dir_var = *dir_var##_opt
