#include "tega/tools/load_run.h"

#include <ATen/Context.h>

#include <nlohmann/json.hpp>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/log.h"
#include "tega/core/options.h"

namespace tega::tools {

namespace fs = std::filesystem;

fs::path run_dataset(const fs::path& run) {
  const fs::path file = run / "run.json";
  if (!fs::exists(file))
    throw Error(file, "is missing (training has not finished?): give the dataset with --data");
  try {
    const auto json = nlohmann::json::parse(read_text_file(file));
    return json.at("dataset").get<std::string>();
  } catch (const nlohmann::json::exception& e) {
    throw Error(file, std::string("has no readable \"dataset\": ") + e.what());
  }
}

LoadedRun load_run(const fs::path& run, const fs::path& data, const std::string& device) {
  std::string name = device;
  if (name.empty()) {
    trainer::TrainOptions options;
    load_options(options, run / "options.yaml");
    name = options.device;
    if (name.rfind("cuda", 0) == 0 && !at::hasCUDA()) {
      logging::warn("%s trained on %s, but this build has no CUDA: using the CPU", run.c_str(), name.c_str());
      name = "cpu";
    }
  }
  if (name.rfind("cuda", 0) == 0 && !at::hasCUDA()) throw Error("--device " + name + ": this build of libtorch has no CUDA");
  at::Device dev(at::kCPU);
  try {
    dev = at::Device(name);
  } catch (const c10::Error&) {
    throw Error("--device " + name + ": not a device (cpu, cuda, cuda:1, ...)");
  }
  LoadedRun loaded;
  loaded.dataset = read_dataset(data.empty() ? run_dataset(run) : data);
  loaded.avatar = std::make_unique<trainer::TrainedAvatar>(trainer::load_avatar(run, loaded.dataset, dev));
  logging::info("%s: iteration %lld, %lld Gaussians, on %s", run.c_str(),
                static_cast<long long>(loaded.avatar->iteration),
                static_cast<long long>(loaded.avatar->model.gaussians.size()), dev.str().c_str());
  return loaded;
}

}  // namespace tega::tools
