#pragma once
// What `tega render`, `tega eval` and `tega export` start from: a training
// run and the dataset it was trained on.

#include <filesystem>
#include <memory>
#include <string>

#include "tega/core/dataset.h"
#include "tega/trainer/trained_avatar.h"

namespace tega::tools {

struct LoadedRun {
  Dataset dataset;
  std::unique_ptr<trainer::TrainedAvatar> avatar;
};

// `data` empty: the dataset RUN/run.json names (written when training ends).
// `device` empty: the device the run trained on, or the CPU (with a
// warning) when that is CUDA and this build has none. Throws tega::Error
// naming the file when the run or the dataset cannot be read, or for a CUDA
// device this build lacks.
LoadedRun load_run(const std::filesystem::path& run, const std::filesystem::path& data, const std::string& device);

// The run's dataset as RUN/run.json records it (throws tega::Error when absent).
std::filesystem::path run_dataset(const std::filesystem::path& run);

}  // namespace tega::tools
