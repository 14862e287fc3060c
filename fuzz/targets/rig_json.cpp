#include "fuzz_target.h"
#include "tega/core/rig.h"

// tega's own rig file. A rig the reader accepts must also write and read back.
TEGA_FUZZ_TARGET(rig_json) {
  const tega::Rig rig = tega::read_rig_json(tega::fuzz::input_file("rig.json", data, size));
  const auto written = tega::fuzz::scratch_folder() / "rig-written.json";
  tega::write_rig_json(rig, written);
  tega::read_rig_json(written);
}
