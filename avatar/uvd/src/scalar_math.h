#pragma once
// sqrt, exp and floor for the per-element math of tega_uvd's fused ops, resolved by
// overload to the float or double function on the host and on the device.

#include <cmath>

#include "tega/core/host_device.h"

namespace tega::uvd {

TEGA_HD float math_sqrt(float x) { return sqrtf(x); }
TEGA_HD double math_sqrt(double x) { return sqrt(x); }
TEGA_HD float math_exp(float x) { return expf(x); }
TEGA_HD double math_exp(double x) { return exp(x); }
TEGA_HD float math_floor(float x) { return floorf(x); }
TEGA_HD double math_floor(double x) { return floor(x); }

}  // namespace tega::uvd
