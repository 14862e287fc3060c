#pragma once
// The CUDA pipeline's error checks: a failed call or launch throws with what failed.

#include "tega/core/cuda_check.h"

#define TEGA_CUDA_CHECK(expr) ::tega::check_cuda((expr), "splat", #expr)
#define TEGA_CHECK_LAUNCH(kernel) ::tega::check_launch("splat", #kernel)
