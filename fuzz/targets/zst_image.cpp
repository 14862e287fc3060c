#include "fuzz_target.h"
#include "tega/core/error.h"
#include "tega/core/image.h"
#include "tega/core/image_header.h"

// tega's raw pixels in zstd (.zst, the dataset's fast image container):
// the header alone, then the pixels.
TEGA_FUZZ_TARGET(zst_image) {
  const auto file = tega::fuzz::input_file("image.zst", data, size);
  try {
    tega::read_image_header(file);
  } catch (const tega::Error&) {
  }
  tega::read_image_u8(file);
}
