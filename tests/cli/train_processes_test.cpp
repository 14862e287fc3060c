// `tega train --processes 2`: one model trained by two processes that average their gradients
// (the path `--gpus` takes on GPUs, with Gloo instead of NCCL), as a user runs it.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <regex>

#include "cli_support.h"
#include "test_support.h"

namespace tega::test {
namespace {

CommandResult render_tiny_capture(const std::filesystem::path& capture) {
  return run_tega("synth --out " + capture.string() +
                  " --set studio.width=96 --set studio.height=64 --set frames=3 --set calibration_frames=0");
}

TEST(CliTrain, TwoProcessesTrainOneModelAndAgree) {
  if (run_tega("train --help").exit_code != 0) GTEST_SKIP() << "this tega has no train command (no libtorch)";
  TempDir tmp;
  const auto synth = render_tiny_capture(tmp / "capture");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const std::string train = "train --data " + (tmp / "capture/dataset").string() + " --out " + (tmp / "run").string() +
                            " --iterations 16 --set log_every=4 --set uv_lookup.resolution=64"
                            " --set network.texture_size=16 --set network.unet_widths=[4,8]"
                            " --set network.latent_channels=4 --set network.mlp_hidden=8 --set initial_gaussians=400";
  const auto r = run_tega(train + " --processes 2");
  if (r.output.find("needs libtorch's c10d") != std::string::npos) GTEST_SKIP() << "this build has no c10d with Gloo";
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("tega train: 2 processes on the CPU"), std::string::npos) << r.output;
  // The run's replicas checked against each other at the end: the averaging kept them equal.
  EXPECT_NE(r.output.find("2 processes trained one model: their parameters agree"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("trained 16 iterations"), std::string::npos) << r.output;
  EXPECT_TRUE(std::filesystem::exists(tmp / "run/checkpoint.safetensors"));
  EXPECT_FALSE(std::filesystem::exists(tmp / "run/.rendezvous"));
  // One process's progress lines, not two.
  size_t lines = 0;
  for (size_t at = r.output.find("it 16/16"); at != std::string::npos; at = r.output.find("it 16/16", at + 1)) ++lines;
  EXPECT_EQ(lines, 1u) << r.output;
  // Its rate in steps and in views: two views a step.
  std::smatch rate;
  ASSERT_TRUE(std::regex_search(r.output, rate, std::regex(R"(it 16/16 .* ([0-9.]+) it/s \(([0-9.]+) views/s\))")))
      << r.output;
  EXPECT_NEAR(std::stod(rate[2]), 2 * std::stod(rate[1]), 0.07) << rate[0];

  const auto both = run_tega(train + " --force --processes 2 --gpus 0,1");
  EXPECT_NE(both.exit_code, 0);
  EXPECT_NE(both.output.find("--gpus or --processes, not both"), std::string::npos) << both.output;
  const auto cpu_gpus = run_tega(train + " --force --gpus 0,1");
  EXPECT_NE(cpu_gpus.exit_code, 0);
  EXPECT_NE(cpu_gpus.output.find("--gpus trains on GPUs: pass --device cuda"), std::string::npos) << cpu_gpus.output;
}

// The checksum the processes agreed on at the end of a run, or NaN where they did not say.
double agreed_checksum(const std::string& output) {
  std::smatch m;
  static const std::regex agreed(R"(their parameters agree \(checksum ([0-9.e+-]+)\))");
  return std::regex_search(output, m, agreed) ? std::stod(m[1]) : std::nan("");
}

// SIGTERM to `tega train --processes 2` stops both processes at one step with a checkpoint, sent to
// the launcher alone (`kill PID`) or to the whole process group (a terminal's Ctrl-C, `tega run`,
// `timeout`; Slurm signals every process of a job likewise): then the training processes get it
// directly as well as passed on, and must not take the two for an operator's second signal, which
// kills. Resumed, the run goes on as if it had never stopped.
TEST(CliTrain, TwoProcessesStopTogetherOnSigtermAndResumeAsIfUninterrupted) {
  if (run_tega("train --help").exit_code != 0) GTEST_SKIP() << "this tega has no train command (no libtorch)";
  TempDir tmp;
  const auto synth = render_tiny_capture(tmp / "capture");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const auto train = [&](const std::string& run) {
    return std::string(TEGA_EXECUTABLE) + " train --data " + (tmp / "capture/dataset").string() + " --out " +
           (tmp / run).string() +
           " --processes 2 --iterations 300 --set log_every=2 --set uv_lookup.resolution=64"
           " --set network.texture_size=16 --set network.unet_widths=[4,8] --set network.latent_channels=4"
           " --set network.mlp_hidden=8 --set initial_gaussians=400 --set densify.enabled=false";
  };
  const auto straight = run_command(train("straight") + " --stop-at 100 2>&1");
  if (straight.output.find("needs libtorch's c10d") != std::string::npos) GTEST_SKIP() << "no c10d with Gloo";
  ASSERT_EQ(straight.exit_code, 0) << straight.output;

  // Runs `command` in its own process group (bash's job control) and, once its log shows
  // iteration `after`, sends SIGTERM to the launcher alone or to the group. The iteration it
  // stopped at.
  const auto stop = [&](const std::string& command, int after, bool whole_group) {
    const std::string log = (tmp / "stopped.log").string();
    const auto stopped = run_command("bash -c 'set -m; " + command + " >" + log + " 2>&1 & pid=$!; " +
                                     "for i in $(seq 1200); do grep -q \" it " + std::to_string(after) +
                                     "/300\" " + log + " && break; sleep 0.05; done; kill -TERM " +
                                     (whole_group ? "-" : "") + "$pid; wait $pid; echo exit=$?; cat " + log + "'");
    EXPECT_NE(stopped.output.find("exit=130"), std::string::npos) << stopped.output;
    std::smatch at;
    EXPECT_TRUE(std::regex_search(stopped.output, at, std::regex(R"(interrupted after (\d+) of 300 iterations)")))
        << stopped.output;
    // Both processes stopped at that step: their parameters agree in the checkpoint they saved.
    EXPECT_FALSE(std::isnan(agreed_checksum(stopped.output))) << stopped.output;
    return at.empty() ? -1 : std::stoi(at[1]);
  };
  const int launcher_stopped_at = stop(train("stopped"), 10, false);
  ASSERT_GE(launcher_stopped_at, 10);
  ASSERT_LT(launcher_stopped_at, 70) << "the run got too far before the signal to test its resumption";
  const int group_stopped_at = stop(train("stopped") + " --resume", (launcher_stopped_at / 2 + 5) * 2, true);
  ASSERT_GT(group_stopped_at, launcher_stopped_at);
  ASSERT_LT(group_stopped_at, 100) << "the run got too far before the signal to test its resumption";

  const auto resumed = run_command(train("stopped") + " --resume --stop-at 100 2>&1");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  const double expected = agreed_checksum(straight.output), got = agreed_checksum(resumed.output);
  EXPECT_NEAR(got, expected, 1e-6 * std::abs(expected)) << straight.output << "\n" << resumed.output;
}

}  // namespace
}  // namespace tega::test
