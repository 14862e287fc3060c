#include "tega/core/image_header.h"

#include <array>
#include <cstdint>
#include <cstring>
#include <fstream>

#include "image_backends.h"
#include "tega/core/error.h"

namespace tega {

ImageHeader read_image_header(const std::filesystem::path& file) {
  if (file.extension() == ".zst") return detail::read_zstd_header(file);
  // A PNG starts with an 8-byte signature and then the IHDR chunk:
  // length(4) "IHDR"(4) width(4) height(4) bit depth(1) colour type(1) ...
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(file, std::filesystem::exists(file) ? "cannot be read" : "does not exist");
  std::array<unsigned char, 26> head{};
  in.read(reinterpret_cast<char*>(head.data()), head.size());
  static constexpr unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (in.gcount() != static_cast<std::streamsize>(head.size()) || std::memcmp(head.data(), kSignature, 8) != 0 ||
      std::memcmp(head.data() + 12, "IHDR", 4) != 0) {
    throw Error(file, "is not a PNG image");
  }
  const auto be32 = [&](int at) {
    return static_cast<int>((uint32_t{head[at]} << 24) | (uint32_t{head[at + 1]} << 16) |
                            (uint32_t{head[at + 2]} << 8) | uint32_t{head[at + 3]});
  };
  ImageHeader h;
  h.width = be32(16);
  h.height = be32(20);
  h.bit_depth = head[24];
  switch (head[25]) {  // PNG colour types
    case 0: h.channels = 1; break;  // grey
    case 2: h.channels = 3; break;  // RGB
    case 3: h.channels = 3; break;  // palette (expands to RGB)
    case 4: h.channels = 2; break;  // grey + alpha
    case 6: h.channels = 4; break;  // RGBA
    default: throw Error(file, "has an invalid PNG colour type");
  }
  return h;
}

}  // namespace tega
