#pragma once
// `tega train --gpus 0,1,2,3` (or `--processes N` on the CPU): one training process per GPU, each
// this same command line without that flag, told its place by the environment, pinned to its GPU
// with CUDA_VISIBLE_DEVICES (docs/training.md#on-several-gpus).

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tega/trainer/parallel_rank.h"

namespace tega::cli {

// Starts the processes and waits for them; returns the exit status to leave with (the first
// failure's). `gpus` empty: `world` processes on the CPU.
int run_training_processes(int world, const std::vector<std::string>& gpus, const std::filesystem::path& run);

// This process's place when run_training_processes started it, else nothing.
std::optional<trainer::ParallelRank> parallel_rank_from_environment();

}  // namespace tega::cli
