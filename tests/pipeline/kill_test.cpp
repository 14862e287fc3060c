// Kill -9 `tega run` at random moments, then run it again: the final outputs
// equal those of an uninterrupted run, no shard is ever visible as complete
// unless it is, and no shard process outlives the killed orchestrator.

#include <gtest/gtest.h>
#include <signal.h>

#include <random>
#include <set>
#include <thread>

#include "pipeline_test_support.h"
#include "tega/core/files.h"
#include "tega/pipeline/workspace.h"
#include "test_support.h"

namespace tega::test {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// 18 kills, spread uniformly over the run: enough to land one before the first
// commit, in the middle and in each stage with near certainty.
constexpr int kTrials = 14;

// Three subjects through synth and dataset check: six shards, two at a time.
std::string config_text() {
  return "workspace: unused\nsubjects:\n  alice: {}\n  bob: {options: {synth: {seed: 2}}}\n"
         "  carol: {options: {synth: {seed: 3}}}\nstages:\n  synth:\n    options:\n" +
         tiny_synth_options(6) + "  check: {kind: dataset_check, after: synth}\n";
}

std::vector<std::string> run_args(const fs::path& config, const fs::path& workspace) {
  return {"run", config.string(), "--workspace", workspace.string(), "--jobs", "2"};
}

// The stages that had a shard running (a "running" state record) when the run died.
std::set<std::string> stages_caught_running(const fs::path& workspace) {
  std::set<std::string> stages;
  for (const char* stage : {"synth", "check"}) {
    for (const char* shard : {"alice", "bob", "carol"}) {
      const auto state = pipeline::read_shard_state(workspace / stage / (std::string(shard) + ".state.json"));
      if (state && state->state == "running") stages.insert(stage);
    }
  }
  return stages;
}

TEST(KillNine, ResumedRunsEqualAnUninterruptedRun) {
  if (!tega_has_command({"synth"})) GTEST_SKIP() << "this build has no `tega synth`";
  TempDir dir;
  write_text(dir / "p.yaml", config_text());
  const fs::path config = dir / "p.yaml";

  const auto start = Clock::now();
  const auto reference_run = run_tega(run_args(config, dir / "reference"), dir.path());
  const double reference_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  ASSERT_EQ(reference_run.exit_code, 0) << reference_run.output;
  const auto reference = committed_outputs(dir / "reference");
  ASSERT_GT(reference.size(), 20u);

  std::mt19937 random(20240611);
  std::uniform_real_distribution<double> moment(0.0, reference_seconds);
  std::set<std::string> caught_running;
  std::set<size_t> committed_counts;
  for (int trial = 0; trial < kTrials; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const fs::path ws = dir / ("trial" + std::to_string(trial));
    // Every third trial is killed twice before it may finish.
    for (int kill = 0; kill < (trial % 3 == 2 ? 2 : 1); ++kill) {
      const pid_t run = spawn_tega(run_args(config, ws), dir / "killed-output.txt");
      ASSERT_GT(run, 0);
      std::this_thread::sleep_for(std::chrono::duration<double>(moment(random)));
      ::kill(run, SIGKILL);
      wait_for_exit(run);
      EXPECT_TRUE(wait_until_no_process_mentions(ws.string(), std::chrono::seconds(5)))
          << "a shard process outlived its orchestrator";

      // Whatever is committed is complete and equal to the reference.
      const auto committed = committed_outputs(ws);
      std::set<std::string> shards;
      for (const auto& [path, hash] : committed) {
        ASSERT_TRUE(reference.count(path)) << path;
        EXPECT_EQ(hash, reference.at(path)) << path;
        shards.insert(path.substr(0, path.find('/', path.find('/') + 1)));
      }
      for (const auto& [path, hash] : reference) {
        const std::string shard = path.substr(0, path.find('/', path.find('/') + 1));
        if (shards.count(shard)) EXPECT_TRUE(committed.count(path)) << "committed shard lacks " << path;
      }
      EXPECT_TRUE(shard_dirs_without_manifest(ws).empty());
      committed_counts.insert(shards.size());
      for (const auto& stage : stages_caught_running(ws)) caught_running.insert(stage);
    }

    const auto resumed = run_tega(run_args(config, ws), dir.path());
    ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
    EXPECT_EQ(committed_outputs(ws), reference);
    EXPECT_TRUE(staging_dirs(ws).empty());
    tega::remove_tree(ws);
  }
  // The kills landed all over the run: before anything was committed, in the
  // middle, and while shards of each stage were running.
  EXPECT_TRUE(committed_counts.count(0));
  EXPECT_GE(committed_counts.size(), 3u);
  EXPECT_EQ(caught_running, (std::set<std::string>{"synth", "check"}));
}

}  // namespace
}  // namespace tega::test
