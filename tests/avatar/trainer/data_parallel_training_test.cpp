// Training shared by two processes (data_parallel.h) on the CPU and on two GPUs: a NaN in one
// process's step rolls both back, as on one GPU; momentum_per_view sets Adam's decays for two views
// a step. The test runs its own executable twice as the two processes.

#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "tega/trainer/checkpoint.h"
#include "tega/trainer/data_parallel.h"
#include "tega/trainer/trainer.h"
#include "test_support.h"
#include "tiny_training.h"

extern char** environ;

namespace tega::trainer {
namespace {

constexpr const char* kRankVariable = "TEGA_TEST_TRAINING_RANK";
constexpr const char* kFolderVariable = "TEGA_TEST_TRAINING_FOLDER";
constexpr const char* kPhaseVariable = "TEGA_TEST_TRAINING_PHASE";
constexpr const char* kDeviceVariable = "TEGA_TEST_TRAINING_DEVICE";

// One of the two processes of a phase, in FOLDER: "rolled" trains FOLDER/rolled with the second
// process's loss of iteration 5 made NaN; "reference-start" trains FOLDER/reference to iteration 3
// and "reference-rest" resumes it with every learning rate halved, what a roll-back from 5 to
// the checkpoint of 3 does; "per-view" and "per-step" take one step into FOLDER/<phase>, with
// and without momentum_per_view. On `device`: cpu, or cuda (the process's own GPU).
void train_as_one_of_two(int rank, const std::filesystem::path& folder, const std::string& phase,
                         const std::string& device) {
  TrainOptions options = test::tiny_options();
  options.device = device;
  options.checkpoint_every = 3;
  RunControl control;
  control.parallel = {rank, 2, folder / (phase + ".rendezvous")};
  std::filesystem::path run = folder / "reference";
  if (phase == "per-view" || phase == "per-step") {
    run = folder / phase;
    options.momentum_per_view = phase == "per-view";
    control.stop_at = 1;
  } else if (phase == "rolled") {
    run = folder / "rolled";
    if (rank == 1) control.poisoned_iterations = {5};
  } else if (phase == "reference-start") {
    control.stop_at = 3;
  } else {
    ASSERT_EQ(phase, "reference-rest");
    options = test::scaled_learning_rates(options, 0.5);
    control.resume = true;
  }
  const TrainSummary summary = train(folder / "data", run, options, control);
  EXPECT_EQ(summary.iterations, control.stop_at ? control.stop_at : 6);
}

// In a process that start_process started: trains its part and says so.
bool trained_as_one_of_two() {
  const char* rank = std::getenv(kRankVariable);
  if (!rank) return false;
  train_as_one_of_two(std::atoi(rank), std::getenv(kFolderVariable), std::getenv(kPhaseVariable),
                      std::getenv(kDeviceVariable));
  return true;
}

// The GPU a process of rank `rank` trains on, as `tega train --gpus 0,1` gives it: the rank-th of
// the GPUs this process sees.
std::string visible_gpu(int rank) {
  const char* visible = std::getenv("CUDA_VISIBLE_DEVICES");
  if (!visible) return std::to_string(rank);
  std::vector<std::string> gpus;
  std::istringstream list(visible);
  for (std::string gpu; std::getline(list, gpu, ',');) gpus.push_back(gpu);
  return rank < static_cast<int>(gpus.size()) ? gpus[rank] : std::to_string(rank);
}

// Starts this test in another process, as `rank` of `phase`'s two.
pid_t start_process(int rank, const std::filesystem::path& folder, const std::string& phase,
                    const std::string& device) {
  std::vector<std::string> environment{std::string(kRankVariable) + "=" + std::to_string(rank),
                                       std::string(kFolderVariable) + "=" + folder.string(),
                                       std::string(kPhaseVariable) + "=" + phase,
                                       std::string(kDeviceVariable) + "=" + device};
  if (device == "cuda") environment.push_back("CUDA_VISIBLE_DEVICES=" + visible_gpu(rank));
  for (char** e = environ; *e; ++e)
    if (device != "cuda" || std::string(*e).rfind("CUDA_VISIBLE_DEVICES=", 0) != 0) environment.emplace_back(*e);
  std::vector<char*> envp;
  for (auto& e : environment) envp.push_back(e.data());
  envp.push_back(nullptr);
  std::string program = "/proc/self/exe";
  const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string filter = "--gtest_filter=" + std::string(test->test_suite_name()) + "." + test->name();
  std::vector<char*> argv{program.data(), filter.data(), nullptr};
  pid_t pid = 0;
  if (posix_spawn(&pid, program.c_str(), nullptr, nullptr, argv.data(), envp.data()) != 0) return -1;
  return pid;
}

// The process's exit status, or -1 when it is still running after `patience` (then killed).
int wait_for(pid_t pid, std::chrono::seconds patience) {
  const auto deadline = std::chrono::steady_clock::now() + patience;
  int status = 0;
  while (waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// Both processes of `phase` to their end; false if either failed.
bool train_two_processes(const std::filesystem::path& folder, const std::string& phase,
                         const std::string& device = "cpu") {
  const pid_t first = start_process(0, folder, phase, device), second = start_process(1, folder, phase, device);
  // Patience for a process that would wait for the other's gradients forever.
  const int first_status = first > 0 ? wait_for(first, std::chrono::seconds(300)) : -1;
  const int second_status = second > 0 ? wait_for(second, std::chrono::seconds(300)) : -1;
  EXPECT_EQ(first_status, 0) << phase << ", process 0";
  EXPECT_EQ(second_status, 0) << phase << ", process 1";
  return first_status == 0 && second_status == 0;
}

// The second process's NaN at iteration 5 rolls both back to the checkpoint of iteration 3 at
// the same step, with their learning rates halved: they end where two processes stopped at 3 and
// resumed with halved learning rates end (and, compared at the end, agree with each other).
TEST(DataParallelTraining, ANanInOneProcessRollsEveryProcessBack) {
  if (!DataParallel::available(at::kCPU)) GTEST_SKIP() << "this build's libtorch has no c10d with Gloo";
  if (trained_as_one_of_two()) return;
  test::TempDir tmp;
  test::write_tiny_dataset(tmp / "data", /*eyeball=*/false);
  ASSERT_TRUE(train_two_processes(tmp.path(), "rolled"));
  const Checkpoint last = read_checkpoint(tmp / "rolled/checkpoint.safetensors");
  EXPECT_EQ(last.iteration(), 6);
  EXPECT_EQ(last.tensors.at("trainer.learning_rate_scale").item<double>(), 0.5);

  ASSERT_TRUE(train_two_processes(tmp.path(), "reference-start"));
  ASSERT_TRUE(train_two_processes(tmp.path(), "reference-rest"));
  test::expect_same_parameters(tmp / "reference", tmp / "rolled");
}

// The same on two GPUs, through NCCL and the gradients' average started during backward (whose
// hooks let go of the rolled-back parameters and take the checkpoint's). Two GPU runs differ in
// their last bits (the rasterizer's backward adds with atomics) and Adam's first steps magnify
// that, so no reference run is compared: both processes finishing, their parameters equal at the
// end (the run checks), after one roll-back to the same step is the check.
TEST(DataParallelTrainingCuda, ANanInOneGpusProcessRollsBothGpusBack) {
  if (trained_as_one_of_two()) return;  // first: a process of the pair sees one GPU
  if (!at::hasCUDA() || at::getNumGPUs() < 2) GTEST_SKIP() << "fewer than two GPUs";
  if (!DataParallel::available(at::kCUDA)) GTEST_SKIP() << "this build has no NCCL";
  test::TempDir tmp;
  test::write_tiny_dataset(tmp / "data", /*eyeball=*/false);
  ASSERT_TRUE(train_two_processes(tmp.path(), "rolled", "cuda"));
  const Checkpoint last = read_checkpoint(tmp / "rolled/checkpoint.safetensors");
  EXPECT_EQ(last.iteration(), 6);
  EXPECT_EQ(last.tensors.at("trainer.learning_rate_scale").item<double>(), 0.5);
}

// The first step's moments hold (1 - β1) g and (1 - β2) g² of each gradient g, so m² / v is
// (1 - β1)² / (1 - β2) wherever g is not zero: 10 with Adam's decays a step, and with
// momentum_per_view on two processes (β1², β2²) 0.19² / (1 - 0.999²).
TEST(DataParallelTraining, MomentumPerViewSquaresTheDecaysOnTwoProcesses) {
  if (!DataParallel::available(at::kCPU)) GTEST_SKIP() << "this build's libtorch has no c10d with Gloo";
  if (trained_as_one_of_two()) return;
  test::TempDir tmp;
  test::write_tiny_dataset(tmp / "data", /*eyeball=*/false);
  for (const auto& [phase, ratio] : {std::pair<std::string, double>{"per-step", 0.1 * 0.1 / 0.001},
                                     {"per-view", 0.19 * 0.19 / (1 - 0.999 * 0.999)}}) {
    ASSERT_TRUE(train_two_processes(tmp.path(), phase));
    const Checkpoint first = read_checkpoint(tmp / phase / "checkpoint.safetensors");
    ASSERT_EQ(first.iteration(), 1);
    const at::Tensor m = first.tensors.at("sh_dc.adam_m").to(at::kDouble);
    const at::Tensor v = first.tensors.at("sh_dc.adam_v").to(at::kDouble);
    const at::Tensor moved = v > 1e-20;
    ASSERT_GT(moved.sum().item<int64_t>(), 0) << phase;
    const at::Tensor ratios = m.pow(2).masked_select(moved) / v.masked_select(moved);
    EXPECT_NEAR(ratios.min().item<double>(), ratio, 1e-3 * ratio) << phase;
    EXPECT_NEAR(ratios.max().item<double>(), ratio, 1e-3 * ratio) << phase;
  }
}

}  // namespace
}  // namespace tega::trainer
