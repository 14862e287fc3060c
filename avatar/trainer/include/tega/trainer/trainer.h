#pragma once
// `tega train`: fits a TeGA avatar to a dataset (docs/training.md).
//
// A run directory holds (docs/layouts.md#run):
//   RUN/options.yaml                 the options of the run
//   RUN/checkpoint.safetensors       the latest checkpoint (atomic)
//   RUN/checkpoint.previous.safetensors  the one before it, which a resume falls back on
//   RUN/metrics.csv                  iteration, loss, psnr, gaussians, seconds
//   RUN/run.json                     dataset, state and the final summary (or where an
//                                    interrupt stopped it)

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "tega/trainer/parallel_rank.h"
#include "tega/trainer/options.h"

namespace tega::trainer {

struct TrainSummary {
  int64_t iterations = 0;       // completed
  // SIGINT or SIGTERM stopped the run at a step's end, with a checkpoint
  // (tega/core/interrupt.h); heldout_psnr is then NaN.
  bool interrupted = false;
  int64_t gaussians = 0;
  double seconds = 0;           // this invocation's training time
  // The iterations after this invocation's first (which waits for the loader's
  // first image), without the final checkpoint and evaluation.
  int64_t steady_iterations = 0;
  double steady_seconds = 0;
  double checkpoint_seconds = 0;  // the final checkpoint's writing, which a longer run repeats
  double final_loss = 0;
  double train_psnr = 0;        // mean over the last logged window
  double heldout_psnr = 0;      // train frames seen from the test cameras (novel view)
  std::filesystem::path checkpoint;
  std::map<std::string, double> milliseconds_per_step;  // by part of the step, with options.profile
};

struct RunControl {
  // Continue from RUN/checkpoint.safetensors: parameters, optimizer, RNG and
  // densification state, so the run goes on exactly as if uninterrupted.
  // Where it is missing or damaged, from the checkpoint before it (warned).
  bool resume = false;
  // Without resume, an existing run is an error unless this is set.
  bool overwrite = false;
  // Stop with a checkpoint after this iteration (0: run to the end); the
  // schedules still follow TrainOptions::iterations. For training in slices.
  int64_t stop_at = 0;
  // Fault injection, for tests: the loss of each of these iterations
  // (1-based) is made NaN the first time the run reaches it.
  std::vector<int64_t> poisoned_iterations;
  // This process's place among the processes that train one run together (data_parallel.h);
  // world 1: alone. `tega train --gpus` / `--processes` start them.
  ParallelRank parallel;
};

// Validates the dataset before anything else (throws tega::Error naming the
// offending file), then trains.
TrainSummary train(const std::filesystem::path& dataset, const std::filesystem::path& run, TrainOptions options,
                   const RunControl& control);

}  // namespace tega::trainer
