#pragma once
// File helpers. Every output of every stage is written atomically: into a
// temporary name in the same directory, then renamed over the final name, so
// a reader never sees a half-written file or directory.

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

namespace tega {

std::string read_text_file(const std::filesystem::path& file);  // throws tega::Error

// Removes a file or a directory tree; a missing path is not an error.
// Use this rather than std::filesystem::remove_all: libtorch 2.x exports its
// own, broken copy of remove_all, which the dynamic linker may bind instead
// of libstdc++'s in any binary linked with it.
void remove_tree(const std::filesystem::path& path);

// Calls write(temp_path), then renames temp_path onto `file`. On an exception
// the temporary is removed and `file` is untouched.
void write_file_atomic(const std::filesystem::path& file,
                       const std::function<void(const std::filesystem::path& temp)>& write);
void write_text_atomic(const std::filesystem::path& file, std::string_view text);

// A directory built under a temporary sibling name and renamed onto its final
// name by commit(). Uncommitted, it is removed on destruction. An existing
// final directory is replaced only when `replace_existing`; otherwise the
// constructor throws tega::Error naming it.
//
// Resumable (given a `resume_key`): the staging directory has a fixed name,
// <final>.partial, and outlives a failed or killed run, so that a long stage
// run again with the same key (its options and inputs) keeps what it had
// written; with another key it starts empty. Whatever the stage wrote there
// must itself be atomic (write_file_atomic): temporaries a killed run left
// are removed.
class StagedDirectory {
 public:
  StagedDirectory(std::filesystem::path final_path, bool replace_existing);
  StagedDirectory(std::filesystem::path final_path, bool replace_existing, const std::string& resume_key);
  ~StagedDirectory();
  StagedDirectory(const StagedDirectory&) = delete;
  StagedDirectory& operator=(const StagedDirectory&) = delete;

  const std::filesystem::path& path() const { return staging_; }  // write here
  const std::filesystem::path& final_path() const { return final_; }
  void commit();

 private:
  std::filesystem::path final_, staging_;
  bool replace_existing_, resumable_ = false, committed_ = false;
};

}  // namespace tega
