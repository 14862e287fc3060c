#include "fuzz_target.h"
#include "tega/core/image.h"

// OpenEXR through core's image layer (OpenImageIO; fuzz/CMakeLists.txt
// builds this target only where tega_core has it).
TEGA_FUZZ_TARGET(exr_image) { tega::read_image(tega::fuzz::input_file("image.exr", data, size)); }
