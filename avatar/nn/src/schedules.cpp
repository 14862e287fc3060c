#include "tega/nn/schedules.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace tega::nn {
namespace {

void check(int64_t iteration, int64_t total) {
  if (total < 2 || iteration < 0) throw std::invalid_argument("schedules need total >= 2 and iteration >= 0");
}

}  // namespace

double vgg_weight(int64_t iteration, int64_t total_iterations) {
  check(iteration, total_iterations);
  const double half = 0.5 * total_iterations;
  if (iteration < half) return 0.0;
  const double last = static_cast<double>(total_iterations - 1);
  const double t = last > half ? std::min(1.0, (iteration - half) / (last - half)) : 1.0;
  return 0.01 * std::pow(10.0, t);
}

double smoothness_weight(int64_t iteration, int64_t total_iterations) {
  check(iteration, total_iterations);
  const double t = std::min(1.0, iteration / (0.5 * total_iterations));
  return std::pow(0.1, t);
}

}  // namespace tega::nn
