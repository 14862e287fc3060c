#include "fuzz_target.h"
#include "tega/core/mesh.h"

// Wavefront OBJ. Normals touch every index, so an index the reader let
// through out of range shows up under the address sanitizer.
TEGA_FUZZ_TARGET(obj) { tega::read_obj(tega::fuzz::input_file("mesh.obj", data, size)).vertex_normals(); }
