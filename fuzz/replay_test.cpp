// CI's half of the fuzzing: every target, built with gcc, runs every input of
// fuzz/corpus/<target> and fuzz/regressions/<target>. An input may end in
// tega::Error; any other exception fails the target's test, naming the input.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>

#include "fuzz_target.h"

namespace {
namespace fs = std::filesystem;

std::vector<fs::path> replay_inputs(const std::string& target) {
  std::vector<fs::path> inputs;
  for (const char* kind : {"corpus", "regressions"}) {
    const fs::path folder = fs::path(TEGA_FUZZ_DIR) / kind / target;
    if (!fs::is_directory(folder)) continue;
    for (const auto& entry : fs::directory_iterator(folder))
      if (entry.is_regular_file()) inputs.push_back(entry.path());
  }
  std::sort(inputs.begin(), inputs.end());
  return inputs;
}

std::vector<std::string> target_names() {
  std::vector<std::string> names;
  for (const auto& target : tega::fuzz::registered_targets()) names.push_back(target.name);
  return names;
}

class FuzzReplay : public testing::TestWithParam<std::string> {};

TEST_P(FuzzReplay, EveryCorpusAndRegressionInputEndsCleanly) {
  const auto& targets = tega::fuzz::registered_targets();
  const auto target = std::find_if(targets.begin(), targets.end(), [](const auto& t) { return t.name == GetParam(); });
  ASSERT_NE(target, targets.end());
  const auto inputs = replay_inputs(target->name);
  ASSERT_FALSE(inputs.empty()) << "fuzz/corpus/" << target->name << " holds no seed";
  for (const auto& input : inputs) {
    std::ifstream in(input, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    try {
      tega::fuzz::run_accepting_errors(target->body, reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
    } catch (const std::exception& e) {
      ADD_FAILURE() << input << ": an exception other than tega::Error escaped: " << e.what();
    } catch (...) {
      ADD_FAILURE() << input << ": a non-standard exception escaped";
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Targets, FuzzReplay, testing::ValuesIn(target_names()),
                         [](const testing::TestParamInfo<std::string>& info) { return info.param; });

}  // namespace
