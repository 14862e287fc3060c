#pragma once
// Loss-weight schedules of TeGA §3.6, as functions of the iteration
// (0-based) and the total number of iterations.

#include <cstdint>

namespace tega::nn {

// λ_VGG: 0 for the first half of training; from the halfway iteration on,
// 0.01 growing exponentially to 0.1 at the last iteration
// (0.01 · 10^((it - T/2) / (T - 1 - T/2))).
double vgg_weight(int64_t iteration, int64_t total_iterations);

// λ_JD: 1.0 decaying exponentially to 0.1 at the halfway iteration
// (0.1^(it / (T/2))), then constant at 0.1.
double smoothness_weight(int64_t iteration, int64_t total_iterations);

}  // namespace tega::nn
