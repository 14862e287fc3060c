#pragma once
// Loss-weight schedules of TeGA §3.6 as functions of the iteration, with the
// breakpoints and values taken from LossOptions (defaults: the paper's).

#include <cstdint>

#include "tega/trainer/options.h"

namespace tega::trainer::schedules {

// 0 before loss.vgg_start of training; from there 0.01 growing exponentially
// to 0.1 at the last iteration.
double vgg_weight(const LossOptions& loss, int64_t iteration, int64_t iterations);
// loss.smoothness_initial decaying exponentially to loss.smoothness_final at
// half of training, then constant.
double smoothness_weight(const LossOptions& loss, int64_t iteration, int64_t iterations);

}  // namespace tega::trainer::schedules
