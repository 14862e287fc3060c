#include "tega/pipeline/gpus.h"

#include <algorithm>
#include <cstdlib>
#include <cctype>

#include "tega/core/error.h"

namespace tega::pipeline {
namespace fs = std::filesystem;

void check_gpu_list(const std::vector<std::string>& gpus, const std::string& what) {
  for (auto gpu = gpus.begin(); gpu != gpus.end(); ++gpu) {
    if (gpu->empty() || std::any_of(gpu->begin(), gpu->end(), [](unsigned char c) { return std::isspace(c); }))
      throw Error(what + ": '" + *gpu + "' is not a GPU: give indices or UUIDs, e.g. 0,1,3");
    if (std::find(gpus.begin(), gpu, *gpu) != gpu) throw Error(what + ": GPU '" + *gpu + "' is listed twice");
  }
}

std::vector<std::string> parse_gpu_list(const std::string& text, const std::string& what) {
  std::vector<std::string> gpus;
  if (text.empty()) return gpus;
  size_t start = 0;
  for (size_t comma; (comma = text.find(',', start)) != std::string::npos; start = comma + 1)
    gpus.push_back(text.substr(start, comma - start));
  gpus.push_back(text.substr(start));
  check_gpu_list(gpus, what);
  return gpus;
}

std::vector<std::string> machine_gpus(const std::optional<std::string>& cuda_visible_devices,
                                      const fs::path& driver_gpus) {
  if (cuda_visible_devices) return parse_gpu_list(*cuda_visible_devices, "CUDA_VISIBLE_DEVICES");
  std::error_code error;
  size_t count = 0;
  for (fs::directory_iterator it(driver_gpus, error), end; !error && it != end; it.increment(error)) ++count;
  std::vector<std::string> gpus;
  for (size_t i = 0; i < count; ++i) gpus.push_back(std::to_string(i));
  return gpus;
}

std::string child_visible_device(const std::string& gpu, const std::optional<std::string>& cuda_visible_devices,
                                 const std::string& what) {
  if (!cuda_visible_devices || gpu.find_first_not_of("0123456789") != std::string::npos || gpu.size() > 9) return gpu;
  const std::vector<std::string> visible = parse_gpu_list(*cuda_visible_devices, "CUDA_VISIBLE_DEVICES");
  const size_t index = std::stoul(gpu);
  if (index >= visible.size())
    throw Error(what + ": GPU " + gpu + " is not among this process's " + std::to_string(visible.size()) +
                " (CUDA_VISIBLE_DEVICES=" + *cuda_visible_devices + " numbers them from 0)");
  return visible[index];
}

std::vector<std::string> machine_gpus() {
  const char* visible = std::getenv("CUDA_VISIBLE_DEVICES");
  return machine_gpus(visible ? std::optional<std::string>(visible) : std::nullopt);
}

}  // namespace tega::pipeline
