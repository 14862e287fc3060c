#pragma once
// `tega train`: fits a TeGA avatar to a dataset (docs/training.md).
//
// A run directory holds (docs/layouts.md#run):
//   RUN/options.yaml                 the options of the run
//   RUN/checkpoint.safetensors       the latest checkpoint (atomic)
//   RUN/metrics.csv                  iteration, loss, psnr, gaussians, seconds
//   RUN/run.json                     dataset, state and the final summary

#include <filesystem>
#include <string>

#include "tega/trainer/options.h"

namespace tega::trainer {

struct TrainSummary {
  int64_t iterations = 0;       // completed
  int64_t gaussians = 0;
  double seconds = 0;           // this invocation's training time
  double final_loss = 0;
  double train_psnr = 0;        // mean over the last logged window
  double heldout_psnr = 0;      // train frames seen from the test cameras (novel view)
  std::filesystem::path checkpoint;
};

// Validates the dataset before anything else (throws tega::Error naming the
// offending file). With `resume`, continues from RUN/checkpoint.safetensors
// with its parameters, optimizer state and RNG state, and the options saved
// in the run (except `iterations`, which may be raised); without it, an
// existing run directory is an error unless `overwrite`.
TrainSummary train(const std::filesystem::path& dataset, const std::filesystem::path& run, TrainOptions options,
                   bool resume, bool overwrite);

}  // namespace tega::trainer
