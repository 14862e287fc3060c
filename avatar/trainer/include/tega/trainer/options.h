#pragma once
// Options of `tega train`. Defaults are the paper's (TeGA §3.6-3.8) and
// 3D Gaussian Splatting's where the paper follows it. Every schedule is a
// fraction of `iterations`, so that a short run keeps the paper's shape:
// at 60K iterations the defaults give a 10K warm-up, densification from 600
// to 30K every 100 iterations, and an opacity reset every 3K.

#include <string>
#include <vector>

#include "tega/nn/expression_network.h"
#include "tega/uvd/uv_lookup.h"

namespace tega::trainer {

struct LearningRates {
  double position = 5e-5;           // metres; 3DGS's 1.6e-4 x a 0.3 m head
  double position_final = 5e-7;     // exponential decay to this at the end
  double sh_dc = 2.5e-3;
  double sh_rest = 1.25e-4;         // sh_dc / 20, as 3DGS
  double opacity = 0.05;
  double scale = 5e-3;              // of log(std)
  double rotation = 1e-3;
  double network = 5e-4;            // deformation/shading networks (Yang et al. 2024)
  double network_final = 5e-6;
  template <class V>
  void visit(V& v) {
    v("position", position, "Step size of Gaussian positions, in metres (u, v are converted through the template's metres per uv unit).");
    v("position_final", position_final, "Position learning rate at the last iteration (exponential decay).");
    v("sh_dc", sh_dc, "Learning rate of the degree-0 SH coefficients.");
    v("sh_rest", sh_rest, "Learning rate of the higher SH coefficients.");
    v("opacity", opacity, "Learning rate of the opacity logits.");
    v("scale", scale, "Learning rate of the log standard deviations.");
    v("rotation", rotation, "Learning rate of the rotation quaternions.");
    v("network", network, "Learning rate of the U-Net and MLPs.");
    v("network_final", network_final, "Network learning rate at the last iteration (exponential decay).");
  }
};

struct DensifyOptions {
  bool enabled = true;
  double start = 0.01;                // fraction of iterations
  double stop = 0.5;
  double interval = 100.0 / 60000.0;
  double opacity_reset_interval = 3000.0 / 60000.0;
  double gradient_threshold = 2e-4;   // mean |dL/dmean2D| in NDC-like pixel units, as 3DGS
  double clone_max_std = 3e-3;        // metres: smaller Gaussians are cloned, larger split (3DGS: 1% of extent)
  double prune_opacity = 0.005;
  double prune_max_std = 0.03;        // metres: prune larger ones
  int64_t max_gaussians = 4000000;
  template <class V>
  void visit(V& v) {
    v("enabled", enabled, "Adaptive densification (clone, split, prune, opacity reset). Off = the 'no densify' ablation.");
    v("start", start, "First densification, as a fraction of iterations.");
    v("stop", stop, "Last densification, as a fraction of iterations.");
    v("interval", interval, "Densification period, as a fraction of iterations (at least one iteration).");
    v("opacity_reset_interval", opacity_reset_interval, "Opacity reset period, as a fraction of iterations.");
    v("gradient_threshold", gradient_threshold, "Mean screen-space mean-gradient norm above which a Gaussian is densified.");
    v("clone_max_std", clone_max_std, "Largest world std (metres) of a Gaussian that is cloned rather than split.");
    v("prune_opacity", prune_opacity, "Gaussians less opaque than this are pruned.");
    v("prune_max_std", prune_max_std, "Gaussians with a larger world std (metres) are pruned.");
    v("max_gaussians", max_gaussians, "Upper bound on the number of Gaussians, the initial sample included.");
  }
};

struct LossOptions {
  double l1 = 0.8;
  double dssim = 0.2;
  std::string vgg_weights;            // safetensors of torchvision's VGG-16 features; "" = no VGG term
  double vgg_start = 0.5;             // fraction of iterations before which λ_VGG = 0
  double pyramid_l1 = 0.0;            // 0 = off (the paper has no such term)
  int pyramid_levels = 4;
  double smoothness_initial = 1.0;
  double smoothness_final = 0.1;      // reached at half of training
  int64_t smoothness_samples = 100000;
  // GaussianAvatars' regularisers (binding: rigged only), in units of each
  // Gaussian's triangle scale k.
  double rig_position = 0.01;
  double rig_position_threshold = 1.0;
  double rig_scale = 1.0;
  double rig_scale_threshold = 0.6;
  template <class V>
  void visit(V& v) {
    v("l1", l1, "Weight of the L1 term.");
    v("dssim", dssim, "Weight of the D-SSIM term.");
    v("vgg_weights", vgg_weights, "VGG-16 weight file (safetensors, docs/networks-and-losses.md). Empty: the perceptual term is off (the run log says so).");
    v("vgg_start", vgg_start, "Fraction of training after which the VGG term starts at 0.01, growing exponentially to 0.1.");
    v("pyramid_l1", pyramid_l1,
      "Weight of L1 on the 2x, 4x, ... box-averaged images (mean over the levels): coarse gradients for "
      "misalignments wider than the skin's texture, a stand-in for the VGG term's (docs/networks-and-losses.md). 0 = off.");
    v("pyramid_levels", pyramid_levels, "Levels of the pyramid L1 term (the coarsest averages 2^levels pixels a side).");
    v("smoothness_initial", smoothness_initial, "Jacobian smoothness weight at the first iteration (0, with smoothness_final 0: the term is off).");
    v("smoothness_final", smoothness_final, "Smoothness weight from mid-training on (exponential decay before).");
    v("smoothness_samples", smoothness_samples, "Random uvd samples per step for the smoothness term.");
    v("rig_position", rig_position,
      "binding: rigged only (GaussianAvatars): weight of mean(max(|μ| - rig_position_threshold, 0)), μ the local position.");
    v("rig_position_threshold", rig_position_threshold, "Local distance (in triangle scales) that is free of the position term.");
    v("rig_scale", rig_scale,
      "binding: rigged only (GaussianAvatars): weight of mean(|max(s - rig_scale_threshold, 0)|), s the local standard deviations.");
    v("rig_scale_threshold", rig_scale_threshold, "Local standard deviation (in triangle scales) that is free of the scale term.");
  }
};

struct TrainOptions {
  int64_t iterations = 60000;
  std::string device = "cpu";
  int64_t seed = 0;
  int64_t initial_gaussians = 500000;
  int sh_degree = 3;
  double sh_degree_interval = 1000.0 / 60000.0;  // one more SH degree per interval
  double warmup = 10000.0 / 60000.0;             // canonical warm-up without the field
  double min_std = 2e-5;                         // metres (0.02 mm)
  double max_std = 5e-3;                         // metres (5 mm)
  std::vector<double> background{0.0, 0.0, 0.0};
  bool deformation_field = true;                 // false: the 'no warp' ablation
  bool dynamic_shading = true;                   // false: the 'no shading' ablation
  std::string binding = "uvd";                   // uvd (TeGA), triangle or rigged (GaussianAvatars)
  bool antialiased = false;
  int64_t checkpoint_every = 5000;
  double rollback_learning_rate_factor = 0.5;  // after a NaN/Inf step or a runaway field
  bool momentum_per_view = false;                // on N GPUs: Adam's decays ^N (Grendel)
  double max_deformation = 0.05;                 // metres; 0 = unbounded
  int64_t log_every = 10;
  int loader_threads = 8;                        // a real 3072x2048 PNG: ~0.2 s of one core
  int prefetch = 8;
  int cpu_threads = 0;                           // 0: all cores
  bool profile = false;
  LearningRates learning_rates;
  DensifyOptions densify;
  LossOptions loss;
  nn::NetworkOptions network;
  uvd::UvLookupOptions uv_lookup;

  template <class V>
  void visit(V& v) {
    v("iterations", iterations, "Training iterations (one view each).");
    v("device", device, "cpu or cuda.");
    v("seed", seed, "Seed of initialisation, view order and samples; a run is reproducible on the CPU.");
    v("initial_gaussians", initial_gaussians, "Gaussians sampled uniformly over the UV area at the start (at most densify.max_gaussians).");
    v("sh_degree", sh_degree, "Highest spherical-harmonics degree (0-3).");
    v("sh_degree_interval", sh_degree_interval, "Fraction of iterations after which the active SH degree grows by one.");
    v("warmup", warmup, "Fraction of iterations trained without the deformation field and shading (canonical warm-up).");
    v("min_std", min_std, "Smallest standard deviation of a Gaussian, metres.");
    v("max_std", max_std, "Largest standard deviation of a Gaussian, metres.");
    v("background", background, "Background colour (linear RGB) that images are composited on.");
    v("deformation_field", deformation_field, "Learn the UVD deformation field. false: the 'no warp' ablation.");
    v("dynamic_shading", dynamic_shading, "Learn the dynamic shading. false: the 'no shading' ablation (both false: 'no network').");
    v("binding", binding,
      "uvd: Gaussians move freely across triangles (TeGA); triangle: each keeps the triangle it started on, still through "
      "the UVD map ('No Triangle Updates'); rigged: GaussianAvatars' rigging, local coordinates in the triangle's "
      "frame scaled by its size, one Gaussian per triangle at the start (initial_gaussians unused; the networks must be off).");
    v("antialiased", antialiased, "Mip-Splatting-style antialiased rasterization.");
    v("checkpoint_every", checkpoint_every, "Iterations between checkpoints (plus one at the start and one at the end).");
    v("rollback_learning_rate_factor", rollback_learning_rate_factor,
      "A step whose loss or gradients hold NaN/Inf, or whose deformation field runs away (max_deformation), rolls "
      "training back to its last checkpoint, once, and every learning rate is multiplied by this from there on; a "
      "second such step stops training.");
    v("momentum_per_view", momentum_per_view,
      "On several GPUs (N views a step): raise Adam's moment decays (0.9, 0.999) to the N-th power, so that the "
      "moments forget at the same rate per view as on one GPU, as Grendel does beside its sqrt(N) learning rates. "
      "false: one GPU's decays a step. No effect on one GPU. On two GPUs it gained nothing over the learning rates' "
      "rule alone and made seeds differ more (docs/training.md).");
    v("max_deformation", max_deformation,
      "Metres: a step whose deformation field moves a Gaussian further than this has diverged, as a NaN/Inf step has "
      "(a field that runs away stays finite while it renders the head away). 0: no bound.");
    v("log_every", log_every, "Iterations between progress lines.");
    v("loader_threads", loader_threads, "Threads decoding training images ahead of use.");
    v("prefetch", prefetch, "Training views decoded ahead of use.");
    v("cpu_threads", cpu_threads, "Threads of libtorch's CPU operations (0: all cores).");
    v("profile", profile, "Time each part of a step (waits for the device between parts; slower).");
    v("learning_rates", learning_rates, "Adam learning rates.");
    v("densify", densify, "Adaptive densification in UVD space.");
    v("loss", loss, "Loss weights and schedules.");
    v("network", network, "Deformation and shading networks.");
    v("uv_lookup", uv_lookup, "uv -> triangle lookup structure.");
  }
};

// Iteration at a fraction of training, at least 1 where a period is meant.
int64_t at_fraction(double fraction, int64_t iterations);
int64_t period(double fraction, int64_t iterations);

}  // namespace tega::trainer

namespace tega::trainer {

// The paper's Table 1 ablations by name: no-warp, no-shading, no-network,
// no-densify, ga-binding, mlp-only, cap-200k. Throws tega::Error for another name.
void apply_ablation(TrainOptions& options, const std::string& ablation);
const std::vector<std::string>& ablation_names();

// Another method trained by the same trainer: "gaussian-avatars" (Qian et al.
// 2024; docs/training.md#the-gaussianavatars-baseline). Applied on top of the
// run's options. Throws tega::Error for another name.
void apply_baseline(TrainOptions& options, const std::string& baseline);
const std::vector<std::string>& baseline_names();

// Throws tega::Error naming what is wrong with a combination of options that
// the trainer cannot run (an unknown binding, networks with rigged Gaussians).
void validate_train_options(const TrainOptions& options);

// The defaults for training on the CPU. TrainOptions' own are sized for a GPU (500K Gaussians
// growing to 4M, a 256² U-Net, 60K iterations), which the CPU runs at 0.1-0.3 iterations a
// second; these are the demo's sizes (studio_configs/demo.yaml) with 3000 iterations: 15K
// Gaussians at most, a 32² U-Net of widths 8-32, a 256² uv lookup. `tega train` starts from them
// on the CPU when it is given no config (docs/training.md#on-the-cpu).
TrainOptions cpu_sized_options();

// What of `options` is sized for a GPU though they run on the CPU ("" when nothing is), to warn of.
std::string gpu_sized_on_cpu(const TrainOptions& options);

}  // namespace tega::trainer
