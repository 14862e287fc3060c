#include "fuzz_target.h"
#include "tega/core/error.h"
#include "tega/core/image.h"
#include "tega/core/image_header.h"

// PNG through core's image layer: the header alone (dataset and take checks),
// libpng (every build's path) and read_image_u8 (OpenImageIO where present).
TEGA_FUZZ_TARGET(png_image) {
  const auto file = tega::fuzz::input_file("image.png", data, size);
  try {
    tega::read_image_header(file);
  } catch (const tega::Error&) {
  }
  try {
    tega::read_png_with_libpng(file);
  } catch (const tega::Error&) {
  }
  tega::read_image_u8(file);
}
