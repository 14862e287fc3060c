// Kill -9 `tega run` while its train shard trains, then run it again: the
// shard resumes from its last checkpoint (never from iteration 0) and ends
// with the parameters of an uninterrupted run. Stopped by SIGTERM instead,
// the shard saves the step it was at and resumes from there. Finished but not
// committed, it resumes at its last iteration.

#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <signal.h>

#include <random>
#include <regex>
#include <thread>

#include "pipeline_test_support.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/trainer/checkpoint.h"
#include "test_support.h"

namespace tega::test {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr int kTrials = 10;
constexpr int kIterations = 200;

// The virtual studio's tiniest capture and a training run of a few seconds
// on one CPU thread (deterministic), checkpointing every `checkpoint_every`
// iterations.
std::string config_text(int checkpoint_every = 10) {
  return "workspace: unused\nstages:\n  synth:\n    options:\n" + tiny_synth_options(6) +
         "  train:\n    after: [synth]\n    options:\n"
         "      device: cpu\n      cpu_threads: 1\n      loader_threads: 1\n      prefetch: 2\n"
         "      iterations: " + std::to_string(kIterations) + "\n      checkpoint_every: " +
         std::to_string(checkpoint_every) + "\n      log_every: 1\n"
         "      initial_gaussians: 64\n      warmup: 0.25\n"
         "      densify: {start: 0.0, stop: 1.0, interval: 0.25, gradient_threshold: 0.0}\n"
         "      loss: {smoothness_samples: 32}\n"
         "      network: {texture_size: 16, unet_widths: [4, 8], latent_channels: 4, mlp_hidden: 8}\n"
         "      uv_lookup: {resolution: 32}\n";
}

std::vector<std::string> run_args(const fs::path& config, const fs::path& workspace) {
  return {"run", config.string(), "--workspace", workspace.string()};
}

fs::path committed_run(const fs::path& workspace) { return workspace / "train" / "default" / "run"; }

// The checkpoint in the train shard's staging directory, or an empty path.
fs::path staged_checkpoint(const fs::path& workspace) {
  if (!fs::exists(workspace / "train")) return {};
  for (const auto& entry : fs::directory_iterator(workspace / "train")) {
    const fs::path checkpoint = entry.path() / "run" / "checkpoint.safetensors";
    if (entry.path().filename().string().find("staging") != std::string::npos && fs::exists(checkpoint))
      return checkpoint;
  }
  return {};
}

// The iteration of the checkpoint a killed shard left in its staging
// directory, or 0 where it left none that can be read.
int64_t staged_iteration(const fs::path& workspace) {
  const fs::path checkpoint = staged_checkpoint(workspace);
  if (checkpoint.empty()) return 0;
  try {
    return trainer::read_checkpoint(checkpoint).iteration();
  } catch (const Error&) {
    return 0;
  }
}

void expect_same_parameters(const fs::path& a_run, const fs::path& b_run) {
  const auto a = trainer::read_checkpoint(a_run / "checkpoint.safetensors");
  const auto b = trainer::read_checkpoint(b_run / "checkpoint.safetensors");
  EXPECT_EQ(a.iteration(), b.iteration());
  int compared = 0;
  for (const auto& [name, tensor] : a.tensors) {
    if (name.rfind("gaussians.", 0) != 0 && name.rfind("network.", 0) != 0) continue;
    ASSERT_TRUE(b.tensors.count(name)) << name;
    ASSERT_EQ(tensor.sizes(), b.tensors.at(name).sizes()) << name;
    EXPECT_TRUE(at::allclose(tensor, b.tensors.at(name), 1e-5, 1e-7)) << name;
    ++compared;
  }
  EXPECT_GE(compared, 10);
}

TEST(KillNineTraining, AKilledTrainShardResumesFromItsCheckpoint) {
  if (!tega_has_command({"synth"}) || !tega_has_command({"train"})) GTEST_SKIP() << "this build has no synth or train";
  TempDir dir;
  write_text(dir / "p.yaml", config_text());
  const fs::path config = dir / "p.yaml";

  // The reference: synth alone, then train timed alone.
  ASSERT_EQ(run_tega({"run", config.string(), "--workspace", (dir / "reference").string(), "--only", "synth"},
                     dir.path()).exit_code, 0);
  const auto start = Clock::now();
  const auto reference = run_tega(run_args(config, dir / "reference"), dir.path());
  const double train_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  ASSERT_EQ(reference.exit_code, 0) << reference.output;
  // The trainer's own part of it: at a few hundred steps a second, most of
  // `tega run`'s time is its start and commit.
  const double training_seconds =
      nlohmann::json::parse(read_text_file(committed_run(dir / "reference") / "run.json")).at("seconds").get<double>();

  std::mt19937 random(20261125);
  std::uniform_real_distribution<double> moment(0.0, 1.0);
  int resumed_from_a_checkpoint = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const fs::path ws = dir / ("trial" + std::to_string(trial));
    ASSERT_EQ(run_tega({"run", config.string(), "--workspace", ws.string(), "--only", "synth"}, dir.path()).exit_code,
              0);
    int64_t killed_at = 0;
    for (int kill = 0; kill < (trial % 3 == 2 ? 2 : 1); ++kill) {
      const pid_t run = spawn_tega(run_args(config, ws), dir / "killed-output.txt");
      ASSERT_GT(run, 0);
      // Every fourth kill at any moment of the run; the others once the
      // shard has a checkpoint, at any moment of its training after that.
      if (trial % 4 != 0) {
        const auto started = Clock::now();
        while (staged_iteration(ws) == 0 && Clock::now() - started < std::chrono::duration<double>(2 * train_seconds))
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
      const double span = trial % 4 == 0 ? train_seconds * 0.6 : training_seconds;
      std::this_thread::sleep_for(std::chrono::duration<double>(moment(random) * span));
      ::kill(run, SIGKILL);
      wait_for_exit(run);
      EXPECT_TRUE(wait_until_no_process_mentions(ws.string(), std::chrono::seconds(5)))
          << "a shard process outlived its orchestrator";
      if (fs::exists(committed_run(ws))) break;  // it had finished
      killed_at = staged_iteration(ws);
    }
    const auto resumed = run_tega(run_args(config, ws), dir.path());
    ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
    if (killed_at > 0) {
      // The trainer's own words, in the shard's log.
      const std::string log = read_text_file(ws / "logs" / "train" / "default.log");
      EXPECT_TRUE(std::regex_search(log, std::regex("resumed .*checkpoint.*at iteration " + std::to_string(killed_at))))
          << "killed with a checkpoint at iteration " << killed_at << "; log:\n" << log;
      ++resumed_from_a_checkpoint;
    }
    expect_same_parameters(committed_run(dir / "reference"), committed_run(ws));
    EXPECT_TRUE(staging_dirs(ws).empty());
  }
  // Most kills land after a checkpoint: those resumes are what this tests.
  EXPECT_GE(resumed_from_a_checkpoint, kTrials / 2);
  std::printf("%d of %d trials resumed from a checkpoint; the others had none yet or had finished\n",
              resumed_from_a_checkpoint, kTrials);
}

// A commit that fails after the shard has finished (a full disk: here its
// manifest's name is taken by a directory) keeps the trained run: the next
// `tega run` resumes it at its last iteration rather than training again.
TEST(KillNineTraining, AFinishedShardWhoseCommitFailedIsResumedNotTrainedAgain) {
  if (!tega_has_command({"synth"}) || !tega_has_command({"train"})) GTEST_SKIP() << "this build has no synth or train";
  TempDir dir;
  write_text(dir / "p.yaml", config_text());
  const fs::path config = dir / "p.yaml", ws = dir / "ws";
  ASSERT_EQ(run_tega({"run", config.string(), "--workspace", ws.string(), "--only", "synth"}, dir.path()).exit_code, 0);

  const pid_t run = spawn_tega(run_args(config, ws), dir / "failed-output.txt");
  ASSERT_GT(run, 0);
  const fs::path staging = ws / "train" / ".staging-default";
  const auto launched = Clock::now();
  while (!fs::exists(staging / ".resume-key") && Clock::now() - launched < std::chrono::seconds(60))
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ASSERT_TRUE(fs::create_directories(staging / "manifest.json"));
  EXPECT_NE(wait_for_exit(run), 0);
  ASSERT_NE(read_text_file(dir / "failed-output.txt").find("could not be committed"), std::string::npos)
      << read_text_file(dir / "failed-output.txt");
  ASSERT_EQ(staged_iteration(ws), kIterations);

  fs::remove(staging / "manifest.json");
  const fs::path log = ws / "logs" / "train" / "default.log";
  const size_t failed_log_size = read_text_file(log).size();
  const auto resumed = run_tega(run_args(config, ws), dir.path());
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  const std::string resumed_log = read_text_file(log).substr(failed_log_size);
  EXPECT_TRUE(std::regex_search(resumed_log,
                                std::regex("resumed .*checkpoint.*at iteration " + std::to_string(kIterations))))
      << resumed_log;
  EXPECT_EQ(resumed_log.find(" it 1/"), std::string::npos) << "trained again:\n" << resumed_log;
  EXPECT_EQ(trainer::read_checkpoint(committed_run(ws) / "checkpoint.safetensors").iteration(), kIterations);
  EXPECT_TRUE(staging_dirs(ws).empty());
}

// SIGTERM to `tega run` (Ctrl-C, a scheduler's time limit): the train shard
// stops at the end of its step with a checkpoint there, where its periodic
// checkpoints would have lost every step since iteration 0 here; started
// again, it goes on from that step and ends where an uninterrupted run ends.
TEST(TerminatedTraining, AStoppedTrainShardSavesTheStepItWasAtAndResumesThere) {
  if (!tega_has_command({"synth"}) || !tega_has_command({"train"})) GTEST_SKIP() << "this build has no synth or train";
  TempDir dir;
  write_text(dir / "p.yaml", config_text(/*checkpoint_every=*/100000));
  const fs::path config = dir / "p.yaml";
  for (const char* ws : {"reference", "stopped"}) {
    ASSERT_EQ(run_tega({"run", config.string(), "--workspace", (dir / ws).string(), "--only", "synth"}, dir.path())
                  .exit_code,
              0);
  }
  const auto start = Clock::now();
  const auto reference = run_tega(run_args(config, dir / "reference"), dir.path());
  const double train_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  ASSERT_EQ(reference.exit_code, 0) << reference.output;

  const fs::path ws = dir / "stopped";
  const fs::path log = ws / "logs" / "train" / "default.log";
  const pid_t run = spawn_tega(run_args(config, ws), dir / "stopped-output.txt");
  ASSERT_GT(run, 0);
  // Stopped once the shard's log shows a quarter of the steps: a moment in the run's training
  // itself, however long `tega run`'s start takes on a loaded machine (a delay from the first
  // checkpoint, proportioned to the reference run's time, failed once on a loaded machine).
  const std::string quarter = " it " + std::to_string(kIterations / 4) + "/";
  const auto launched = Clock::now();
  while ((!fs::exists(log) || read_text_file(log).find(quarter) == std::string::npos) &&
         Clock::now() - launched < std::chrono::duration<double>(2 * train_seconds + 60))
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  ::kill(run, SIGTERM);
  EXPECT_EQ(wait_for_exit(run), 130) << read_text_file(dir / "stopped-output.txt");
  const int64_t stopped_at = staged_iteration(ws);
  ASSERT_GE(stopped_at, kIterations / 4) << "no step saved; output:\n" << read_text_file(dir / "stopped-output.txt");
  ASSERT_LT(stopped_at, kIterations);
  EXPECT_NE(read_text_file(log).find("interrupted at iteration " + std::to_string(stopped_at)), std::string::npos)
      << read_text_file(log);

  const auto resumed = run_tega(run_args(config, ws), dir.path());
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_TRUE(std::regex_search(read_text_file(log),
                                std::regex("resumed .*checkpoint.*at iteration " + std::to_string(stopped_at))))
      << read_text_file(log);
  expect_same_parameters(committed_run(dir / "reference"), committed_run(ws));
}

}  // namespace
}  // namespace tega::test
