#include "binary_file.h"

#include <fstream>
#include <iterator>

#include "tega/core/error.h"
#include "tega/core/files.h"

namespace tega::mvs {

std::string read_binary_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(file, "cannot open the file");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw Error(file, "cannot read the file");
  return bytes;
}

void write_binary_file_atomic(const std::filesystem::path& file, const std::string& bytes) {
  std::error_code error;
  std::filesystem::create_directories(file.parent_path(), error);
  if (error) throw Error(file.parent_path(), "cannot create the directory: " + error.message());
  write_file_atomic(file, [&](const std::filesystem::path& temp) {
    std::ofstream out(temp, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) throw Error(file, "cannot write the file");
  });
}

}  // namespace tega::mvs
