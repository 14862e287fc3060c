// Bad input through the real `tega` binary: a message naming the file and
// what is wrong, a non-zero exit, and nothing written.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_support.h"
#include "tega/core/files.h"
#include "test_support.h"

namespace {

using tega::test::run_tega;

TEST(CliBadInput, TruncatedKrtIsNamedWithItsLine) {
  tega::test::TempDir tmp;
  // One camera whose [R|t] block stops after its first row.
  tega::test::write_text(tmp / "KRT",
                         "400002\n1000 0 667 \n0 1000 1024 \n0 0 1 \n0 0 0 0 0\n1 0 0 10\n");
  const auto r = run_tega("rig convert --in " + (tmp / "KRT").string() + " --width 1334 --height 2048 --out " +
                          (tmp / "rig.json").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find((tmp / "KRT").string() + ": line"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(tmp / "rig.json"));
}

TEST(CliBadInput, FileThatIsNotAnImageIsNamed) {
  tega::test::TempDir tmp;
  tega::test::write_tiny_dataset(tmp.path());
  const auto image = tmp / "images/cam00/smile_000000.png";
  tega::test::write_text(image, "this is not a PNG file");
  const auto r = run_tega("dataset check --data " + tmp.path().string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find(image.string() + ": is not a PNG image"), std::string::npos) << r.output;
}

TEST(CliBadInput, MvsOnAMissingCaptureNamesIt) {
  tega::test::TempDir tmp;
  const auto r = run_tega("mvs --capture " + (tmp / "nowhere").string() + " --out " + (tmp / "meshes").string());
  if (r.output.find("could not be matched") != std::string::npos) GTEST_SKIP() << "this build has no tega mvs";
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find((tmp / "nowhere").string()), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(tmp / "meshes"));
  const auto frames = run_tega("mvs --capture x --out y --frames 9:3");
  EXPECT_EQ(frames.exit_code, 1) << frames.output;
  EXPECT_NE(frames.output.find("--frames '9:3'"), std::string::npos) << frames.output;
}

TEST(CliBadInput, TrackNamesAMissingCaptureAndAMissingModel) {
  tega::test::TempDir tmp;
  const auto r = run_tega("track --capture " + (tmp / "nowhere").string() + " --meshes " + (tmp / "m").string() +
                          " --model " + (tmp / "model").string() + " --out " + (tmp / "tracked").string());
  if (r.output.find("could not be matched") != std::string::npos) GTEST_SKIP() << "this build has no tega track";
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find((tmp / "nowhere").string()), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(tmp / "tracked"));
  const auto options = run_tega("track --print-options");
  EXPECT_EQ(options.exit_code, 0) << options.output;
  EXPECT_NE(options.output.find("  model: \"\""), std::string::npos) << options.output;
  EXPECT_NE(options.output.find("landmarks:"), std::string::npos) << options.output;
}

// `tega synth --set` over a config: how a study varies one option of its
// capture (scripts/ablation-study's SYNTH_SET).
TEST(CliSynth, SetOverridesTheConfigAndAnUnknownKeyIsNamed) {
  tega::test::TempDir tmp;
  tega::test::write_text(tmp / "capture.yaml", "frames: 4\ntracking_error: {offset_m: 0.002, lag: 0.5}\n");
  const auto r = run_tega("synth --config " + (tmp / "capture.yaml").string() +
                          " --set tracking_error.lag=0 --set tracking_error.eyelid_gain=0.75 --print-options");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("\nframes: 4\n"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("  offset_m: 0.002\n"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("  lag: 0\n"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("  eyelid_gain: 0.75\n"), std::string::npos) << r.output;
  const auto unknown = run_tega("synth --set tracking_error.lagg=0 --print-options");
  EXPECT_EQ(unknown.exit_code, 1) << unknown.output;
  EXPECT_NE(unknown.output.find("'tracking_error.lagg'"), std::string::npos) << unknown.output;
  const auto malformed = run_tega("synth --set frames --print-options");
  EXPECT_EQ(malformed.exit_code, 1) << malformed.output;
  EXPECT_NE(malformed.output.find("--set frames: expected key=value"), std::string::npos) << malformed.output;
}

// On the CPU without a config, `tega train` starts from CPU sizes; on a GPU, or with a config,
// from the options' own, and a config that keeps GPU sizes on the CPU is warned of.
TEST(CliTrain, TheCpuWithoutAConfigGetsCpuSizes) {
  const auto cpu = run_tega("train --print-options");
  if (cpu.output.find("could not be matched") != std::string::npos) GTEST_SKIP() << "this build has no tega train";
  ASSERT_EQ(cpu.exit_code, 0) << cpu.output;
  EXPECT_NE(cpu.output.find("\niterations: 3000\n"), std::string::npos) << cpu.output;
  EXPECT_NE(cpu.output.find("\ninitial_gaussians: 4000\n"), std::string::npos) << cpu.output;
  EXPECT_NE(cpu.output.find("  texture_size: 32\n"), std::string::npos) << cpu.output;
  EXPECT_NE(cpu.output.find("CPU-sized defaults"), std::string::npos) << cpu.output;
  const auto set = run_tega("train --device cpu --set iterations=50 --set network.texture_size=64 --print-options");
  EXPECT_NE(set.output.find("\niterations: 50\n"), std::string::npos) << set.output;
  EXPECT_NE(set.output.find("  texture_size: 64\n"), std::string::npos) << set.output;
  EXPECT_NE(set.output.find("  max_gaussians: 15000\n"), std::string::npos) << set.output;

  const auto gpu = run_tega("train --device cuda --print-options");
  EXPECT_NE(gpu.output.find("\niterations: 60000\n"), std::string::npos) << gpu.output;
  EXPECT_NE(gpu.output.find("\ninitial_gaussians: 500000\n"), std::string::npos) << gpu.output;

  tega::test::TempDir tmp;
  tega::test::write_text(tmp / "train.yaml", "device: cpu\niterations: 10\n");
  const auto configured = run_tega("train --config " + (tmp / "train.yaml").string() + " --print-options");
  EXPECT_NE(configured.output.find("\ninitial_gaussians: 500000\n"), std::string::npos) << configured.output;
  EXPECT_NE(configured.output.find("sized for a GPU (initial_gaussians 500000, network.texture_size 256)"),
            std::string::npos)
      << configured.output;
}

TEST(CliRigConvert, KrtToJsonToColmapInMetres) {
  tega::test::TempDir tmp;
  tega::test::write_text(tmp / "KRT",
                         "400002\n1000 0 667 \n0 1000 1024 \n0 0 1 \n0 0 0 0 0\n"
                         "1 0 0 10\n0 1 0 20\n0 0 1 1000\n\n");
  const auto json = run_tega("rig convert --in " + (tmp / "KRT").string() + " --width 1334 --height 2048 --out " +
                             (tmp / "rig.json").string());
  ASSERT_EQ(json.exit_code, 0) << json.output;
  const auto colmap =
      run_tega("rig convert --in " + (tmp / "rig.json").string() + " --out " + (tmp / "colmap").string() + "/");
  ASSERT_EQ(colmap.exit_code, 0) << colmap.output;
  EXPECT_TRUE(std::filesystem::exists(tmp / "colmap/cameras.txt"));
  const auto rig = nlohmann::json::parse(tega::read_text_file(tmp / "rig.json"));
  const auto t = rig["cameras"][0]["t"].get<std::vector<double>>();  // millimetres -> metres
  EXPECT_NEAR(t[0], 0.01, 1e-12);
  EXPECT_NEAR(t[2], 1.0, 1e-12);
}

}  // namespace
