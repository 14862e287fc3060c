#include "tega/trainer/schedules.h"

#include <algorithm>
#include <cmath>

namespace tega::trainer::schedules {

namespace {
constexpr double kVggInitial = 0.01;  // the paper's λ_VGG when the term starts
constexpr double kVggFinal = 0.1;     // ... and at the end of training
}  // namespace

double vgg_weight(const LossOptions& loss, int64_t iteration, int64_t iterations) {
  const int64_t start = at_fraction(loss.vgg_start, iterations);
  if (iteration < start) return 0.0;
  const double t = static_cast<double>(iteration - start) / static_cast<double>(std::max<int64_t>(1, iterations - 1 - start));
  return kVggInitial * std::pow(kVggFinal / kVggInitial, std::min(t, 1.0));
}

double smoothness_weight(const LossOptions& loss, int64_t iteration, int64_t iterations) {
  if (loss.smoothness_initial == 0) return 0.0;  // the term is off (validate_train_options: both are 0)
  const double t = static_cast<double>(iteration) / static_cast<double>(std::max<int64_t>(1, iterations / 2));
  return loss.smoothness_initial * std::pow(loss.smoothness_final / loss.smoothness_initial, std::min(t, 1.0));
}

}  // namespace tega::trainer::schedules
