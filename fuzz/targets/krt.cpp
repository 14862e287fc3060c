#include "fuzz_target.h"
#include "tega/core/rig.h"

// Multiface's KRT camera file.
TEGA_FUZZ_TARGET(krt) { tega::read_krt(tega::fuzz::input_file("KRT", data, size), 1334, 2048); }
