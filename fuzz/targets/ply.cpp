#include "fuzz_target.h"
#include "tega/core/mesh.h"

// PLY, ASCII and binary little-endian (see obj.cpp for the normals).
TEGA_FUZZ_TARGET(ply) { tega::read_ply(tega::fuzz::input_file("mesh.ply", data, size)).vertex_normals(); }
