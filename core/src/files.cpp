#include "tega/core/files.h"

#include <ftw.h>
#include <unistd.h>

#include <atomic>
#include <fstream>
#include <random>
#include <sstream>
#include <vector>

#include "tega/core/error.h"

namespace tega {
namespace fs = std::filesystem;

namespace {

constexpr const char* kTemporaryMark = ".tmp-";
constexpr const char* kResumeKeyFile = ".resume-key";

// Unique within this process and across processes writing the same directory.
std::string temporary_suffix() {
  static std::atomic<uint64_t> counter{0};
  static const uint64_t salt = std::random_device{}();
  return kTemporaryMark + std::to_string(::getpid()) + "-" + std::to_string(salt % 100000) + "-" +
         std::to_string(counter++);
}

}  // namespace

std::string read_text_file(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(file, fs::exists(file) ? "cannot be read" : "does not exist");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void remove_tree(const fs::path& path) {
  const auto remove_entry = [](const char* entry, const struct stat*, int, struct FTW*) { return ::remove(entry); };
  // Depth first (FTW_DEPTH) so that directories are empty when removed; links are not followed.
  if (::nftw(path.c_str(), remove_entry, 16, FTW_DEPTH | FTW_PHYS) != 0 && ::access(path.c_str(), F_OK) == 0) {
    throw Error(path, "could not be removed");
  }
}

void write_file_atomic(const fs::path& file, const std::function<void(const fs::path& temp)>& write) {
  if (file.has_parent_path()) fs::create_directories(file.parent_path());
  const fs::path temp = file.string() + temporary_suffix();
  try {
    write(temp);
    fs::rename(temp, file);
  } catch (...) {
    std::error_code ignored;
    fs::remove(temp, ignored);
    throw;
  }
}

void write_text_atomic(const fs::path& file, std::string_view text) {
  write_file_atomic(file, [&](const fs::path& temp) {
    std::ofstream out(temp, std::ios::binary);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.close();
    if (!out) throw Error(file, "could not be written");
  });
}

StagedDirectory::StagedDirectory(fs::path final_path, bool replace_existing)
    : final_(std::move(final_path)), replace_existing_(replace_existing) {
  if (final_.filename().empty()) final_ = final_.parent_path();  // "out/" -> "out"
  if (fs::exists(final_) && !replace_existing_) {
    throw Error(final_, "already exists (pass --force to replace it)");
  }
  if (final_.has_parent_path()) fs::create_directories(final_.parent_path());
  staging_ = final_.string() + temporary_suffix();
  fs::create_directories(staging_);
}

StagedDirectory::StagedDirectory(fs::path final_path, bool replace_existing, const std::string& resume_key)
    : final_(std::move(final_path)), replace_existing_(replace_existing), resumable_(true) {
  if (final_.filename().empty()) final_ = final_.parent_path();
  if (fs::exists(final_) && !replace_existing_) {
    throw Error(final_, "already exists (pass --force to replace it)");
  }
  staging_ = final_.string() + ".partial";
  const fs::path key_file = staging_ / kResumeKeyFile;
  if (fs::exists(key_file) && read_text_file(key_file) == resume_key) {
    std::vector<fs::path> leftovers;
    for (const auto& entry : fs::recursive_directory_iterator(staging_))
      if (entry.path().filename().string().find(kTemporaryMark) != std::string::npos) leftovers.push_back(entry.path());
    for (const auto& leftover : leftovers) remove_tree(leftover);
  } else {
    remove_tree(staging_);
    fs::create_directories(staging_);
    write_text_atomic(key_file, resume_key);
  }
}

StagedDirectory::~StagedDirectory() {
  if (committed_ || resumable_) return;
  try {
    remove_tree(staging_);
  } catch (const Error&) {
    // A destructor must not throw; the next run's cleanup takes the leftover.
  }
}

void StagedDirectory::commit() {
  // rename() cannot replace a non-empty directory, so the old one is moved
  // aside first and removed only once the new one is in place.
  if (resumable_) fs::remove(staging_ / kResumeKeyFile);
  fs::path old;
  if (fs::exists(final_)) {
    if (!replace_existing_) throw Error(final_, "appeared while it was being written");
    old = final_.string() + temporary_suffix() + ".old";
    fs::rename(final_, old);
  }
  fs::rename(staging_, final_);
  committed_ = true;
  if (!old.empty()) remove_tree(old);
}

}  // namespace tega
