// Every image format through OpenImageIO (built where it is installed).

#include <OpenImageIO/imageio.h>

#include <string>

#include "../image_backends.h"
#include "tega/core/error.h"

namespace tega::detail {

namespace {

namespace fs = std::filesystem;

// OIIO premultiplies colour by alpha on read and divides on write unless told
// not to; our pixels are what the file stores, as with libpng.
constexpr const char* kUnassociatedAlpha = "oiio:UnassociatedAlpha";

std::string oiio_error(const std::string& message) { return message.empty() ? OIIO::geterror() : message; }

template <typename T>
void read_pixels(OIIO::ImageInput& in, const fs::path& file, OIIO::TypeDesc type, ImageBuffer<T>& image) {
  const OIIO::ImageSpec& spec = in.spec();
  image = ImageBuffer<T>(spec.width, spec.height, spec.nchannels);
  if (!in.read_image(0, 0, 0, spec.nchannels, type, image.pixels.data())) {
    throw Error(file, "cannot be read (" + oiio_error(in.geterror()) + ")");
  }
}

}  // namespace

StoredImage read_oiio(const fs::path& file) {
  OIIO::ImageSpec config;
  config.attribute(kUnassociatedAlpha, 1);
  auto in = OIIO::ImageInput::open(file.string(), &config);
  if (!in) throw Error(file, "is not a readable image (" + OIIO::geterror() + ")");
  StoredImage image;
  // 8- and 16-bit files keep their integers; everything else reads as float.
  switch (in->spec().format.basetype) {
    case OIIO::TypeDesc::UINT8: read_pixels(*in, file, OIIO::TypeDesc::UINT8, image.emplace<Image8>()); break;
    case OIIO::TypeDesc::UINT16: read_pixels(*in, file, OIIO::TypeDesc::UINT16, image.emplace<Image16>()); break;
    default: read_pixels(*in, file, OIIO::TypeDesc::FLOAT, image.emplace<ImageF>()); break;
  }
  in->close();
  return image;
}

void write_oiio(const StoredImage& image, const fs::path& target, const fs::path& file) {
  // The temporary target has no image extension: the final name picks the format.
  auto out = OIIO::ImageOutput::create(file.string());
  if (!out) throw Error(file, "has no image format this build can write (" + OIIO::geterror() + ")");
  std::visit(
      [&](const auto& buffer) {
        using T = typename std::decay_t<decltype(buffer.pixels)>::value_type;
        const OIIO::TypeDesc type = OIIO::BaseTypeFromC<T>::value;
        OIIO::ImageSpec spec(buffer.width, buffer.height, buffer.channels, type);
        if (buffer.channels == 2) {  // grey + alpha
          spec.channelnames = {"Y", "A"};
          spec.alpha_channel = 1;
        }
        spec.attribute(kUnassociatedAlpha, 1);
        if (!out->open(target.string(), spec) || !out->write_image(type, buffer.pixels.data()) || !out->close()) {
          throw Error(file, "could not be written (" + oiio_error(out->geterror()) + ")");
        }
      },
      image);
}

bool oiio_can_write(const fs::path& file) {
  const bool can = OIIO::ImageOutput::create(file.string()) != nullptr;
  if (!can) OIIO::geterror();  // clears the message the failed lookup left behind
  return can;
}

}  // namespace tega::detail
