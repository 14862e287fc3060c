#include <iostream>
#include <memory>
#include <optional>

#include "commands.h"
#include "stage_options.h"
#include "train_processes.h"
#include "tega/core/error.h"
#include "tega/core/log.h"
#include "tega/core/options.h"
#include "tega/core/thread_pool.h"
#include "tega/pipeline/gpus.h"
#include "tega/trainer/trainer.h"

namespace tega::cli {

namespace {
struct TrainArguments {
  std::string data, out;
  std::vector<std::string> ablations;
  std::string baseline;
  std::optional<int64_t> iterations;
  int64_t stop_at = 0;
  std::optional<std::string> device;
  bool resume = false, force = false, profile = false;
  std::optional<std::string> gpus;
  int processes = 0;
  StageOptionFlags options;
};
}  // namespace

void add_train_command(CLI::App& app) {
  auto args = std::make_shared<TrainArguments>();
  auto* cmd = app.add_subcommand("train", "Train a TeGA avatar on a dataset (docs/training.md).");
  cmd->add_option("--data", args->data, "Dataset directory (docs/layouts.md#dataset).");
  cmd->add_option("--out", args->out, "Run directory: checkpoint, metrics, options (docs/layouts.md#run).");
  cmd->add_option("--iterations", args->iterations, "Training iterations (default 60000; schedules scale with it).");
  cmd->add_option("--device", args->device,
                  "cpu or cuda (default cpu; on the CPU without --config the defaults are CPU-sized: "
                  "docs/training.md#on-the-cpu).");
  args->options.add_to(*cmd, "", "training", "densify.max_gaussians=1000000");
  cmd->add_option("--ablation", args->ablations,
                  "Paper Table 1 ablation: no-warp, no-shading, no-network, no-densify, ga-binding, mlp-only, cap-200k "
                  "(repeatable).");
  cmd->add_option("--baseline", args->baseline,
                  "Train another method instead of TeGA: gaussian-avatars (GaussianAvatars' rigging, densification and "
                  "losses, no networks; docs/training.md#the-gaussianavatars-baseline).");
  cmd->add_flag("--resume", args->resume, "Continue the run in --out from its checkpoint (its saved options apply; "
                                          "--iterations and --device still override).");
  cmd->add_option("--stop-at", args->stop_at,
                  "Stop with a checkpoint after this iteration; continue later with --resume.");
  cmd->add_flag("--force", args->force, "Start over even if --out already holds a run.");
  cmd->add_flag("--profile", args->profile, "Report the time of each part of a step (slower).");
  cmd->add_option("--gpus", args->gpus,
                  "Train on several GPUs at once, one process each (indices or UUIDs, e.g. 0,1,2,3): every GPU renders "
                  "its own view of a step and the gradients are averaged (docs/training.md#on-several-gpus).");
  cmd->add_option("--processes", args->processes,
                  "Train in this many processes on the CPU, as --gpus does on GPUs (a step sees as many views).");
  cmd->callback([args] {
    // Everything the user gave, over `base`.
    const auto assembled = [&](trainer::TrainOptions options) {
      if (args->resume) {
        load_options(options, std::filesystem::path(args->out) / "options.yaml");
      } else if (!args->options.config.empty()) {
        load_options(options, args->options.config);
      }
      if (!args->baseline.empty()) trainer::apply_baseline(options, args->baseline);
      for (const auto& ablation : args->ablations) trainer::apply_ablation(options, ablation);
      apply_overrides(options, args->options.overrides);
      if (args->iterations) options.iterations = *args->iterations;
      if (args->device) options.device = *args->device;
      if (args->profile) options.profile = true;
      return options;
    };
    trainer::TrainOptions options = assembled({});
    const bool configured = args->resume || !args->options.config.empty();
    if (!configured && options.device == "cpu") {
      options = assembled(trainer::cpu_sized_options());
      logging::info("tega train: on the CPU with no config: CPU-sized defaults (%lld iterations, at most %lld "
                    "Gaussians, a %d² U-Net; docs/training.md#on-the-cpu)",
                    static_cast<long long>(options.iterations), static_cast<long long>(options.densify.max_gaussians),
                    options.network.texture_size);
    } else if (const std::string heavy = trainer::gpu_sized_on_cpu(options); !heavy.empty()) {
      logging::warn("tega train: on the CPU with options sized for a GPU (%s): expect a fraction of an iteration a "
                    "second; docs/training.md#on-the-cpu has CPU sizes",
                    heavy.c_str());
    }
    if (args->options.print_if_asked(options)) return;
    if (args->data.empty() || args->out.empty()) throw Error("tega train needs --data and --out");
    if (args->gpus || args->processes > 1) {
      if (args->gpus && args->processes > 0) throw Error("tega train: --gpus or --processes, not both");
      std::vector<std::string> gpus = args->gpus ? pipeline::parse_gpu_list(*args->gpus, "--gpus")
                                                 : std::vector<std::string>{};
      // Numbered as this process sees them: a `tega run` shard or Slurm job is pinned to its own.
      const char* visible = std::getenv("CUDA_VISIBLE_DEVICES");
      for (std::string& gpu : gpus)
        gpu = pipeline::child_visible_device(gpu, visible ? std::optional<std::string>(visible) : std::nullopt,
                                             "tega train --gpus");
      if (args->gpus && options.device.rfind("cuda", 0) != 0)
        throw Error("tega train: --gpus trains on GPUs: pass --device cuda (or --processes N for the CPU)");
      if (!args->gpus && options.device != "cpu")
        throw Error("tega train: --processes spreads CPU training; on GPUs pass --gpus");
      const int world = args->gpus ? static_cast<int>(gpus.size()) : args->processes;
      if (world > 1) {
        const int status = run_training_processes(world, gpus, args->out);
        if (status != 0) throw CLI::RuntimeError(status);
        return;
      }
    }
    trainer::RunControl control{args->resume, args->force, args->stop_at};
    if (const auto rank = parallel_rank_from_environment()) {
      control.parallel = *rank;
      if (options.device == "cpu" && options.cpu_threads == 0)  // the cores shared out, not each taken by all
        options.cpu_threads = std::max(1, default_thread_count() / rank->world);
    }
    const auto s = trainer::train(args->data, args->out, options, control);
    if (control.parallel.rank > 0) return;
    if (s.interrupted) {
      std::cerr << "tega train: interrupted after " << s.iterations << " of " << options.iterations
                << " iterations; checkpoint saved: " << s.checkpoint.string() << "\n(tega train --out " << args->out
                << " --resume continues)\n";
      throw CLI::RuntimeError(130);
    }
    std::cout << "trained " << s.iterations << " iterations in " << s.seconds << " s: " << s.gaussians
              << " Gaussians, loss " << s.final_loss << ", train PSNR " << s.train_psnr << " dB, held-out-camera PSNR "
              << s.heldout_psnr << " dB\ncheckpoint: " << s.checkpoint.string() << "\n";
  });
}

}  // namespace tega::cli
