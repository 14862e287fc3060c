#include "tega/trainer/options.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "tega/core/error.h"

namespace tega::trainer {

int64_t at_fraction(double fraction, int64_t iterations) {
  return static_cast<int64_t>(std::llround(fraction * static_cast<double>(iterations)));
}

int64_t period(double fraction, int64_t iterations) { return std::max<int64_t>(1, at_fraction(fraction, iterations)); }

}  // namespace tega::trainer

namespace tega::trainer {
namespace {

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

}  // namespace

const std::vector<std::string>& ablation_names() {
  static const std::vector<std::string> names{"no-warp", "no-shading", "no-network", "no-densify", "ga-binding",
                                              "mlp-only", "cap-200k"};
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
  } else if (ablation == "cap-200k") {
    options.densify.max_gaussians = 200000;
  } else {
    throw Error("unknown ablation '" + ablation + "'; known: " + joined(ablation_names()));
  }
}

const std::vector<std::string>& baseline_names() {
  static const std::vector<std::string> names{"gaussian-avatars"};
  return names;
}

void apply_baseline(TrainOptions& options, const std::string& baseline) {
  if (baseline != "gaussian-avatars") {
    throw Error("unknown baseline '" + baseline + "'; known: " + joined(baseline_names()));
  }
  // GA's rigging, no networks, GA's losses (no perceptual or pyramid term).
  options.binding = "rigged";
  options.deformation_field = options.dynamic_shading = false;
  options.loss.vgg_weights.clear();
  options.loss.pyramid_l1 = 0;
  // GA's adaptive density control as fractions of its 600K iterations:
  // from 10K to the end, every 2K, opacity reset every 60K; at most ~200K.
  options.densify.enabled = true;
  options.densify.start = 10000.0 / 600000.0;
  options.densify.stop = 1.0;
  options.densify.interval = 2000.0 / 600000.0;
  options.densify.opacity_reset_interval = 60000.0 / 600000.0;
  options.densify.max_gaussians = 200000;
}

void validate_train_options(const TrainOptions& options) {
  if (options.binding != "uvd" && options.binding != "triangle" && options.binding != "rigged") {
    throw Error("binding must be 'uvd', 'triangle' or 'rigged', not '" + options.binding + "'");
  }
  if (options.loss.pyramid_l1 < 0 || (options.loss.pyramid_l1 > 0 && options.loss.pyramid_levels < 1)) {
    std::ostringstream what;
    what << "loss.pyramid_l1 must be at least 0 and loss.pyramid_levels at least 1 (got " << options.loss.pyramid_l1
         << " and " << options.loss.pyramid_levels << ")";
    throw Error(what.str());
  }
  const double smooth_initial = options.loss.smoothness_initial, smooth_final = options.loss.smoothness_final;
  const bool smoothness_off = smooth_initial == 0 && smooth_final == 0;
  if (!smoothness_off && !(smooth_initial > 0 && smooth_final > 0)) {
    // The weight decays geometrically from one to the other, which needs both positive.
    std::ostringstream what;
    what << "loss.smoothness_initial and loss.smoothness_final must both be positive, or both 0 to turn the "
            "smoothness term off (got "
         << smooth_initial << " and " << smooth_final << ")";
    throw Error(what.str());
  }
  if (options.binding == "rigged" && (options.deformation_field || options.dynamic_shading)) {
    throw Error("binding: rigged (GaussianAvatars) has no UVD space for the networks: set deformation_field and "
                "dynamic_shading to false (--baseline gaussian-avatars does)");
  }
}

TrainOptions cpu_sized_options() {
  TrainOptions options;
  options.device = "cpu";
  options.iterations = 3000;
  options.initial_gaussians = 4000;
  options.densify.max_gaussians = 15000;
  options.densify.interval = 0.01;               // every 30 iterations of 3000
  options.densify.opacity_reset_interval = 1.0;  // none: too few iterations to grow back from one
  options.loss.smoothness_samples = 500;
  options.network.texture_size = 32;
  options.network.unet_widths = {8, 16, 32};
  options.network.latent_channels = 8;
  options.network.mlp_hidden = 32;
  options.uv_lookup.resolution = 256;
  return options;
}

std::string gpu_sized_on_cpu(const TrainOptions& options) {
  if (options.device != "cpu") return "";
  const TrainOptions gpu_sized;
  std::vector<std::string> parts;
  if (options.initial_gaussians >= gpu_sized.initial_gaussians / 5)
    parts.push_back("initial_gaussians " + std::to_string(options.initial_gaussians));
  if (options.network.texture_size >= gpu_sized.network.texture_size / 2)
    parts.push_back("network.texture_size " + std::to_string(options.network.texture_size));
  return joined(parts);
}

}  // namespace tega::trainer
