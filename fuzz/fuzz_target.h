#pragma once
// One fuzz target per input format tega reads (docs/reliability.md). A target
// is written once:
//
//   TEGA_FUZZ_TARGET(rig_json) {
//     tega::read_rig_json(tega::fuzz::input_file("rig.json", data, size));
//   }
//
// and builds two ways. With TEGA_LIBFUZZER (clang, `-DTEGA_FUZZ=ON`) it is
// the program's LLVMFuzzerTestOneInput; otherwise (gcc, CI) it registers
// itself with the replay test, which runs every corpus and regression input.
//
// The contract both builds check: a malformed input may throw tega::Error,
// the clear error tega promises. Any other exception, a crash, a hang or a
// sanitizer report is a bug in the reader.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace tega::fuzz {

using TargetBody = void (*)(const uint8_t* data, size_t size);

// Runs `body`, swallowing tega::Error and letting anything else escape.
void run_accepting_errors(TargetBody body, const uint8_t* data, size_t size);

// Registers a target with the replay test; returns true so that it can
// initialise a static.
bool register_target(const char* name, TargetBody body);

struct RegisteredTarget {
  std::string name;
  TargetBody body;
};
const std::vector<RegisteredTarget>& registered_targets();

// A scratch folder of this process, under /dev/shm where it exists (readers
// that take paths are fed through it); removed when the process exits.
const std::filesystem::path& scratch_folder();
// Writes the bytes to scratch_folder()/relative (creating its folders) and
// returns the path.
std::filesystem::path input_file(const std::filesystem::path& relative, const uint8_t* data, size_t size);
std::filesystem::path input_file(const std::filesystem::path& relative, std::string_view bytes);

// Inputs that stand for several files (a COLMAP model) hold them one after
// the other, separated by kPartSeparator lines. Returns exactly `count` parts;
// the last takes whatever follows the last separator used, absent ones are empty.
inline constexpr std::string_view kPartSeparator = "\n%%%%\n";
std::vector<std::string_view> split_parts(const uint8_t* data, size_t size, size_t count);
std::string join_parts(const std::vector<std::string>& parts);

}  // namespace tega::fuzz

#ifdef TEGA_LIBFUZZER
#define TEGA_FUZZ_TARGET(name)                                                           \
  static void tega_fuzz_body_##name(const uint8_t* data, size_t size);                   \
  extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {              \
    tega::fuzz::run_accepting_errors(tega_fuzz_body_##name, data, size);                 \
    return 0;                                                                            \
  }                                                                                      \
  static void tega_fuzz_body_##name(const uint8_t* data, size_t size)
#else
#define TEGA_FUZZ_TARGET(name)                                                           \
  static void tega_fuzz_body_##name(const uint8_t* data, size_t size);                   \
  [[maybe_unused]] static const bool tega_fuzz_registered_##name =                       \
      tega::fuzz::register_target(#name, tega_fuzz_body_##name);                         \
  static void tega_fuzz_body_##name(const uint8_t* data, size_t size)
#endif
