// COLMAP's array files (mvs/src/mat.h in COLMAP): "width&height&channels&",
// then float32 planes, channel after channel, each row-major.
#include <spdlog/fmt/fmt.h>

#include <charconv>
#include <cstring>

#include "binary_file.h"
#include "tega/core/error.h"
#include "tega/mvs/colmap_workspace.h"

namespace tega::mvs {
namespace {

// Parses one "<positive integer>&" field of the header at `position`.
int header_field(const std::string& bytes, size_t& position, const char* what, const std::filesystem::path& file) {
  const size_t end = bytes.find('&', position);
  constexpr size_t kMaxDigits = 10;
  int value = 0;
  const char* first = bytes.data() + position;
  const char* last = bytes.data() + (end == std::string::npos ? bytes.size() : end);
  const auto [parsed_to, error] = std::from_chars(first, last, value);
  if (end == std::string::npos || end - position > kMaxDigits || error != std::errc() || parsed_to != last ||
      value <= 0)
    throw Error(file, fmt::format("bad header: expected \"width&height&channels&\", and the {} is not a positive "
                                  "integer followed by '&'",
                                  what));
  position = end + 1;
  return value;
}

}  // namespace

void write_colmap_array(const std::filesystem::path& file, int width, int height, int channels,
                        const std::vector<float>& interleaved) {
  if (width <= 0 || height <= 0 || channels <= 0)
    throw Error(file, fmt::format("cannot write a {}x{}x{} array", width, height, channels));
  const size_t pixels = size_t(width) * size_t(height);
  if (interleaved.size() != pixels * size_t(channels))
    throw Error(file, fmt::format("size mismatch: a {}x{}x{} array holds {} values, given {}", width, height, channels,
                                  pixels * size_t(channels), interleaved.size()));
  std::vector<float> planar(interleaved.size());
  for (size_t p = 0; p < pixels; ++p)
    for (size_t c = 0; c < size_t(channels); ++c) planar[c * pixels + p] = interleaved[p * size_t(channels) + c];
  std::string bytes = fmt::format("{}&{}&{}&", width, height, channels);
  bytes.append(reinterpret_cast<const char*>(planar.data()), planar.size() * sizeof(float));
  write_binary_file_atomic(file, bytes);
}

std::vector<float> read_colmap_array(const std::filesystem::path& file, int& width, int& height, int& channels) {
  const std::string bytes = read_binary_file(file);
  size_t position = 0;
  width = header_field(bytes, position, "width", file);
  height = header_field(bytes, position, "height", file);
  channels = header_field(bytes, position, "channel count", file);
  const size_t found = bytes.size() - position;
  // In floating point first: a corrupt header's product may overflow size_t.
  const double needed = double(width) * double(height) * double(channels) * sizeof(float);
  if (needed > double(found))
    throw Error(file, fmt::format("truncated data: a {}x{}x{} array needs {:.0f} bytes after the header, found {}",
                                  width, height, channels, needed, found));
  const size_t pixels = size_t(width) * size_t(height);
  const size_t expected = pixels * size_t(channels) * sizeof(float);
  if (found > expected)
    throw Error(file, fmt::format("size mismatch: a {}x{}x{} array needs {} bytes after the header, found {}", width,
                                  height, channels, expected, found));
  std::vector<float> planar(pixels * size_t(channels));
  std::memcpy(planar.data(), bytes.data() + position, expected);
  std::vector<float> interleaved(planar.size());
  for (size_t p = 0; p < pixels; ++p)
    for (size_t c = 0; c < size_t(channels); ++c) interleaved[p * size_t(channels) + c] = planar[c * pixels + p];
  return interleaved;
}

}  // namespace tega::mvs
