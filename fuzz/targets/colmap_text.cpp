#include "fuzz_target.h"
#include "tega/core/rig.h"

// A COLMAP text model: cameras.txt, images.txt and points3D.txt, one after the
// other in one input (fuzz_target.h: kPartSeparator).
TEGA_FUZZ_TARGET(colmap_text) {
  const auto parts = tega::fuzz::split_parts(data, size, 3);
  tega::fuzz::input_file("colmap/cameras.txt", parts[0]);
  tega::fuzz::input_file("colmap/images.txt", parts[1]);
  tega::fuzz::input_file("colmap/points3D.txt", parts[2]);
  tega::read_colmap_text(tega::fuzz::scratch_folder() / "colmap", 0.001);
}
