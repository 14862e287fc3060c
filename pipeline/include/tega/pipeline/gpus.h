#pragma once
// The GPUs a local run spreads its GPU shards over (docs/pipeline.md#several-gpus). Each is
// named as CUDA_VISIBLE_DEVICES names it: an index ("0") or a UUID ("GPU-...", "MIG-..."), so
// that a shard pinned to it sees that one GPU as its device 0.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace tega::pipeline {

// "0,1,3" -> {"0", "1", "3"}; "" -> none. Throws tega::Error naming `what` for an empty entry or a
// repeated one, as check_gpu_list does for a list given as such.
std::vector<std::string> parse_gpu_list(const std::string& text, const std::string& what);
void check_gpu_list(const std::vector<std::string>& gpus, const std::string& what);

// The machine's GPUs as this process may use them: CUDA_VISIBLE_DEVICES's entries when it is set
// (empty: none), else one index per GPU the NVIDIA driver lists in `driver_gpus` (none without
// the driver). Needs no CUDA runtime, so the orchestrator itself never touches a GPU.
std::vector<std::string> machine_gpus(const std::optional<std::string>& cuda_visible_devices,
                                      const std::filesystem::path& driver_gpus = "/proc/driver/nvidia/gpus");
std::vector<std::string> machine_gpus();  // of this process's environment and this machine

// The CUDA_VISIBLE_DEVICES entry that pins a child process to `gpu`, a GPU as this process names
// it: under CUDA_VISIBLE_DEVICES=a,b,... (a `tega run` shard, a Slurm job) index i is this
// process's device i, entry i of that list; a UUID, or any entry without it, is itself. Throws
// tega::Error naming `what` for an index past the list.
std::string child_visible_device(const std::string& gpu, const std::optional<std::string>& cuda_visible_devices,
                                 const std::string& what);

}  // namespace tega::pipeline
