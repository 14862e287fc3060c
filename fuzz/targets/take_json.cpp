#include "fuzz_target.h"
#include "tega/core/take.h"

// One take's metadata (take.json), then its check, which fills in the image
// pattern for every camera and frame that take.json does not list as missing.
TEGA_FUZZ_TARGET(take_json) {
  tega::fuzz::input_file("take/take.json", data, size);
  tega::validate_take(tega::read_take(tega::fuzz::scratch_folder() / "take"));
}
