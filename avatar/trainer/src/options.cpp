#include "tega/trainer/options.h"

#include <algorithm>
#include <cmath>

#include "tega/core/error.h"

namespace tega::trainer {

int64_t at_fraction(double fraction, int64_t iterations) {
  return static_cast<int64_t>(std::llround(fraction * static_cast<double>(iterations)));
}

int64_t period(double fraction, int64_t iterations) { return std::max<int64_t>(1, at_fraction(fraction, iterations)); }

}  // namespace tega::trainer

namespace tega::trainer {

const std::vector<std::string>& ablation_names() {
  static const std::vector<std::string> names{"no-warp", "no-shading", "no-network", "no-densify", "ga-binding",
                                              "mlp-only"};
  return names;
}

void apply_ablation(TrainOptions& options, const std::string& ablation) {
  if (ablation == "no-warp") {
    options.deformation_field = false;
  } else if (ablation == "no-shading") {
    options.dynamic_shading = false;
  } else if (ablation == "no-network") {
    options.deformation_field = options.dynamic_shading = false;
  } else if (ablation == "no-densify") {
    options.densify.enabled = false;
  } else if (ablation == "ga-binding") {
    options.binding = "triangle";
  } else if (ablation == "mlp-only") {
    options.network.latent = "global";
  } else {
    std::string known;
    for (const auto& n : ablation_names()) known += (known.empty() ? "" : ", ") + n;
    throw Error("unknown ablation '" + ablation + "'; known: " + known);
  }
}

}  // namespace tega::trainer
