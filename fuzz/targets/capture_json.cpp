#include "fuzz_target.h"
#include "tega/core/take.h"

// A capture's manifest (capture.json: cameras, image size, takes). No take
// folder exists beside it, so validation stops at the first take it lists.
TEGA_FUZZ_TARGET(capture_json) {
  const auto root = tega::fuzz::scratch_folder() / "capture";
  tega::fuzz::input_file("capture/capture.json", data, size);
  const tega::CaptureInfo capture = tega::read_capture(root);
  capture.rig_file();
  tega::validate_capture(root);
}
