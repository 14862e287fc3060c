#include "fuzz_target.h"

#include <unistd.h>

#include <fstream>
#include <system_error>

#include "tega/core/error.h"

namespace tega::fuzz {
namespace fs = std::filesystem;

void run_accepting_errors(TargetBody body, const uint8_t* data, size_t size) {
  try {
    body(data, size);
  } catch (const tega::Error&) {
    // The clear error the readers promise for malformed input.
  }
}

namespace {

std::vector<RegisteredTarget>& registry() {
  static std::vector<RegisteredTarget> targets;
  return targets;
}

// Removes the scratch folder at exit; a crashing run leaves it behind, which
// /dev/shm forgets at the next boot.
struct ScratchFolder {
  fs::path path;
  ScratchFolder() {
    const fs::path shm = "/dev/shm";
    const fs::path base = fs::is_directory(shm) ? shm : fs::temp_directory_path();
    path = base / ("tega-fuzz-" + std::to_string(::getpid()));
    fs::create_directories(path);
  }
  ~ScratchFolder() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
};

}  // namespace

bool register_target(const char* name, TargetBody body) {
  registry().push_back({name, body});
  return true;
}

const std::vector<RegisteredTarget>& registered_targets() { return registry(); }

const fs::path& scratch_folder() {
  static const ScratchFolder folder;
  return folder.path;
}

fs::path input_file(const fs::path& relative, std::string_view bytes) {
  const fs::path file = scratch_folder() / relative;
  fs::create_directories(file.parent_path());
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out.flush()) throw std::runtime_error("fuzz harness: cannot write " + file.string());
  return file;
}

fs::path input_file(const fs::path& relative, const uint8_t* data, size_t size) {
  return input_file(relative, std::string_view(reinterpret_cast<const char*>(data), size));
}

std::vector<std::string_view> split_parts(const uint8_t* data, size_t size, size_t count) {
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  std::vector<std::string_view> parts;
  while (parts.size() + 1 < count) {
    const size_t at = rest.find(kPartSeparator);
    if (at == std::string_view::npos) break;
    parts.push_back(rest.substr(0, at));
    rest.remove_prefix(at + kPartSeparator.size());
  }
  parts.push_back(rest);
  parts.resize(count);
  return parts;
}

std::string join_parts(const std::vector<std::string>& parts) {
  std::string joined;
  for (size_t i = 0; i < parts.size(); ++i) {
    if (i > 0) joined += kPartSeparator;
    joined += parts[i];
  }
  return joined;
}

}  // namespace tega::fuzz
