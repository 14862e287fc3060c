// `tega train --processes 2`: one model trained by two processes that average their gradients
// (the path `--gpus` takes on GPUs, with Gloo instead of NCCL), as a user runs it.

#include <gtest/gtest.h>

#include <filesystem>

#include "cli_support.h"
#include "test_support.h"

namespace tega::test {
namespace {

TEST(CliTrain, TwoProcessesTrainOneModelAndAgree) {
  if (run_tega("train --help").exit_code != 0) GTEST_SKIP() << "this tega has no train command (no libtorch)";
  TempDir tmp;
  const auto synth = run_tega("synth --out " + (tmp / "capture").string() +
                              " --set studio.width=96 --set studio.height=64 --set frames=3 --set calibration_frames=0");
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

  const auto both = run_tega(train + " --force --processes 2 --gpus 0,1");
  EXPECT_NE(both.exit_code, 0);
  EXPECT_NE(both.output.find("--gpus or --processes, not both"), std::string::npos) << both.output;
  const auto cpu_gpus = run_tega(train + " --force --gpus 0,1");
  EXPECT_NE(cpu_gpus.exit_code, 0);
  EXPECT_NE(cpu_gpus.output.find("--gpus trains on GPUs: pass --device cuda"), std::string::npos) << cpu_gpus.output;
}

}  // namespace
}  // namespace tega::test
