// scripts/ablation-study end to end on a tiny CPU study: a capture of the
// procedural head, two of the paper's rows, one row of the user's own
// (ROWS_FILE) and one row trained by two processes at once (MULTI_GPU_ROWS), two
// seeds, a curve of two points (so every run resumes once), the table over seeds
// and the liveness of each run against the true meshes.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <set>
#include <string>

#include "cli_support.h"
#include "tega/core/files.h"
#include "tega/core/image.h"
#include "test_support.h"

namespace tega::test {
namespace {

const std::string kScript = std::string(TEGA_SOURCE_DIR) + "/scripts/ablation-study";

// The environment of a study of the procedural head at 96x64, 12 iterations.
std::string tiny_study_environment(const TempDir& tmp) {
  write_text(tmp / "train.yaml",
             "device: cpu\ncpu_threads: 2\ninitial_gaussians: 400\nlog_every: 4\ncheckpoint_every: 100000\n"
             "network: {texture_size: 16, unet_widths: [4, 8], latent_channels: 4, mlp_hidden: 8}\n"
             "uv_lookup: {resolution: 64}\n");
  return "TEGA=" + std::string(TEGA_EXECUTABLE) + " HEAD=procedural WIDTH=96 HEIGHT=64 FRAMES=3 ITERATIONS=12 " +
         "CURVE='0.5 1' SEEDS='0 1' PARALLEL=2 TRAIN_CONFIG=" + (tmp / "train.yaml").string() +
         " SYNTH_SET=self_shadowing.map_size=256 ";
}

bool tega_trains() { return run_tega("train --help").exit_code == 0; }

TEST(AblationStudy, TrainsEveryRowAndSeedThenTabulatesAndInspectsThem) {
  if (!tega_trains()) GTEST_SKIP() << "this tega has no train command (no libtorch)";
  TempDir tmp;
  write_text(tmp / "rows", "# a row of the user's own\npyramid --set loss.pyramid_l1=1 --set loss.pyramid_levels=2\n");
  const auto r = run_command(tiny_study_environment(tmp) + "GPUS='0 1' VARIANTS='full gaussian-avatars' ROWS_FILE=" +
                             (tmp / "rows").string() + " MULTI_GPU_ROWS=full MULTI_GPU=2 bash " + kScript + " " +
                             (tmp / "study").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;

  const nlohmann::json eval = nlohmann::json::parse(read_text_file(tmp / "study/eval.json"));
  std::set<std::string> names;
  for (const auto& model : eval.at("models")) names.insert(model.at("name").get<std::string>());
  EXPECT_EQ(names, (std::set<std::string>{"full.s0", "full.s1", "gaussian-avatars.s0", "gaussian-avatars.s1",
                                          "pyramid.s0", "pyramid.s1", "full-x2.s0", "full-x2.s1"}));
  // The row on two processes: half the steps, two views each, so the same views as full's 12
  // iterations (and 3 of its 6 at the curve's first point); the processes' parameters agreed.
  for (const char* seed : {"s0", "s1"}) {
    const std::string run = std::string("study/runs/full-x2.") + seed;
    EXPECT_EQ(nlohmann::json::parse(read_text_file(tmp / run / "run.json")).at("iterations").get<int>(), 6) << run;
    const std::string log = read_text_file(tmp / (std::string("study/logs/full-x2.") + seed + ".log"));
    EXPECT_NE(log.find("full-x2." + std::string(seed) + " to iteration 3 on GPU 0,1"), std::string::npos) << log;
    EXPECT_NE(log.find("2 processes trained one model: their parameters agree"), std::string::npos) << log;
  }
  EXPECT_NE(read_text_file(tmp / "study/eval-6/full-x2.s0.md").find("full-x2.s0"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(tmp / "study/table-6.md"));  // the curve's first point
  // Each run evaluated on its own, then merged.
  EXPECT_EQ(nlohmann::json::parse(read_text_file(tmp / "study/eval-12/pyramid.s1.json")).at("models").size(), 1u);

  const std::string table = read_text_file(tmp / "study/table.md");
  EXPECT_NE(table.find("(iteration 12)"), std::string::npos) << table;
  EXPECT_NE(table.find("Seeds 0, 1."), std::string::npos) << table;
  for (const char* row : {"| full |", "| gaussian-avatars |", "| pyramid |", "| full-x2 |"})
    EXPECT_NE(table.find(row), std::string::npos) << row << "\n" << table;

  // Round robin over GPUS, rows x seeds in order (on the CPU the device index only names the run's share).
  EXPECT_NE(read_text_file(tmp / "study/logs/full.s1.log").find("full.s1 to iteration 12 on GPU 1"),
            std::string::npos);
  EXPECT_NE(read_text_file(tmp / "study/logs/gaussian-avatars.s0.log").find("on GPU 0"), std::string::npos);
  EXPECT_NE(read_text_file(tmp / "study/logs/pyramid.s1.log").find("on GPU 1"), std::string::npos);

  // The row's flags reached its runs, and only its runs.
  EXPECT_NE(read_text_file(tmp / "study/runs/pyramid.s1/options.yaml").find("pyramid_l1: 1"), std::string::npos);
  EXPECT_NE(read_text_file(tmp / "study/runs/full.s1/options.yaml").find("pyramid_l1: 0"), std::string::npos);

  // Every run inspected on its own, then merged in the table's order.
  const std::string liveness = read_text_file(tmp / "study/liveness.md");
  std::size_t previous = 0;
  for (const char* run : {"## full.s0", "## full.s1", "## gaussian-avatars.s0", "## gaussian-avatars.s1",
                          "## pyramid.s0", "## pyramid.s1", "## full-x2.s0", "## full-x2.s1"}) {
    const std::size_t at = liveness.find(run);
    ASSERT_NE(at, std::string::npos) << run << "\n" << liveness;
    EXPECT_GT(at, previous) << run << "\n" << liveness;
    previous = at;
  }
  EXPECT_EQ(liveness.find("# Liveness of each part"), liveness.rfind("# Liveness of each part")) << liveness;
  EXPECT_NE(liveness.find("against the true meshes"), std::string::npos) << liveness;
  const nlohmann::json inspected = nlohmann::json::parse(read_text_file(tmp / "study/liveness.json"));
  ASSERT_EQ(inspected.size(), 8u);
  EXPECT_EQ(inspected.at(1).at("run").get<std::string>(), (tmp / "study/runs/full.s1").string());
}

// Table 1 on a dataset made elsewhere (the raw chain's, in a real study), scored against the
// truth of the capture it came from, or not scored without one.
TEST(AblationStudy, TrainsOnAGivenDatasetAndInspectsAgainstAGivenTruth) {
  if (!tega_trains()) GTEST_SKIP() << "this tega has no train command (no libtorch)";
  TempDir tmp;
  const auto rendered = run_tega("synth --config " + std::string(TEGA_SOURCE_DIR) +
                                 "/studio_configs/ablation-capture.yaml --set self_shadowing.map_size=256 --out " +
                                 (tmp / "elsewhere").string() + " --force --width 96 --height 64 --frames 3");
  ASSERT_EQ(rendered.exit_code, 0) << rendered.output;
  const std::string given = tiny_study_environment(tmp) + "VARIANTS=full SEEDS=0 CURVE=1 DATASET=" +
                            (tmp / "elsewhere/dataset").string() + " ";

  const auto scored = run_command(given + "TRUTH=" + (tmp / "elsewhere").string() + " bash " + kScript + " " +
                                  (tmp / "study").string());
  ASSERT_EQ(scored.exit_code, 0) << scored.output;
  EXPECT_FALSE(std::filesystem::exists(tmp / "study/capture")) << "nothing rendered";
  EXPECT_NE(read_text_file(tmp / "study/runs/full.s0/run.json").find((tmp / "elsewhere/dataset").string()),
            std::string::npos);
  EXPECT_NE(read_text_file(tmp / "study/liveness.md").find("## full.s0"), std::string::npos);

  // A row added to the finished study is trained, tabulated and inspected with the first.
  const auto grown = run_command(given + "VARIANTS='full gaussian-avatars' TRUTH=" + (tmp / "elsewhere").string() +
                                 " bash " + kScript + " " + (tmp / "study").string());
  ASSERT_EQ(grown.exit_code, 0) << grown.output;
  const std::string liveness = read_text_file(tmp / "study/liveness.md");
  EXPECT_NE(liveness.find("## full.s0"), std::string::npos) << liveness;
  EXPECT_NE(liveness.find("## gaussian-avatars.s0"), std::string::npos) << liveness;
  EXPECT_EQ(nlohmann::json::parse(read_text_file(tmp / "study/liveness.json")).size(), 2u);

  // Trained on to more iterations, its runs are inspected again there.
  const auto longer = run_command(given + "VARIANTS='full gaussian-avatars' ITERATIONS=16 TRUTH=" +
                                  (tmp / "elsewhere").string() + " bash " + kScript + " " + (tmp / "study").string());
  ASSERT_EQ(longer.exit_code, 0) << longer.output;
  const std::string relived = read_text_file(tmp / "study/liveness.md");
  EXPECT_NE(relived.find("## full.s0 (iteration 16,"), std::string::npos) << relived;
  EXPECT_NE(relived.find("## gaussian-avatars.s0 (iteration 16,"), std::string::npos) << relived;

  // The paper's Figs. 6-7 from that study: the given dataset's photo beside each row's render.
  const auto figures = run_command("TEGA=" + std::string(TEGA_EXECUTABLE) + " ROWS='full gaussian-avatars' DATASET=" +
                                   (tmp / "elsewhere/dataset").string() + " TRUTH=" + (tmp / "elsewhere").string() +
                                   " bash " + std::string(TEGA_SOURCE_DIR) + "/scripts/side-by-side " +
                                   (tmp / "study").string() + " " + (tmp / "figures").string());
  ASSERT_EQ(figures.exit_code, 0) << figures.output;
  const std::string picked = read_text_file(tmp / "figures/frames.txt");
  const std::size_t wrinkle = picked.find("wrinkle frame freestyle_");
  ASSERT_NE(wrinkle, std::string::npos) << picked;  // the capture's held-out take
  const std::string frame = picked.substr(wrinkle + 14, picked.find(' ', wrinkle + 14) - wrinkle - 14);
  const Image8 strip = read_image_u8(tmp / "figures" / (frame + "-full.png"));
  EXPECT_EQ(strip.width, 3 * 96 + 2 * 4);  // photo | full | gaussian-avatars, 4 px apart
  EXPECT_EQ(strip.height, 64);

  const auto no_truth = run_command("TEGA=" + std::string(TEGA_EXECUTABLE) + " DATASET=" +
                                    (tmp / "elsewhere/dataset").string() + " bash " + std::string(TEGA_SOURCE_DIR) +
                                    "/scripts/side-by-side " + (tmp / "study").string() + " " +
                                    (tmp / "figures2").string());
  EXPECT_EQ(no_truth.exit_code, 1) << no_truth.output;
  EXPECT_NE(no_truth.output.find("set TRUTH to the study's"), std::string::npos) << no_truth.output;

  const auto unscored = run_command(given + "bash " + kScript + " " + (tmp / "unscored").string());
  ASSERT_EQ(unscored.exit_code, 0) << unscored.output;
  EXPECT_NE(unscored.output.find("no TRUTH to inspect the runs against; liveness skipped"), std::string::npos)
      << unscored.output;
  EXPECT_TRUE(std::filesystem::exists(tmp / "unscored/table.md"));
  EXPECT_FALSE(std::filesystem::exists(tmp / "unscored/liveness.md"));

  const auto missing = run_command(given + "DATASET=" + (tmp / "nowhere").string() + " bash " + kScript + " " +
                                   (tmp / "missing").string());
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  EXPECT_NE(missing.output.find("DATASET: no dataset at"), std::string::npos) << missing.output;
}

TEST(AblationStudy, ARowOfTheRowsFileMustBeNewAndWellNamed) {
  TempDir tmp;
  const std::string study = "VARIANTS='full' bash " + kScript + " " + (tmp / "study").string();
  write_text(tmp / "again", "full --set loss.pyramid_l1=1\n");
  auto r = run_command("ROWS_FILE=" + (tmp / "again").string() + " " + study);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("row 'full' is also in VARIANTS"), std::string::npos) << r.output;

  write_text(tmp / "badly", "Pyramid.s0 --set loss.pyramid_l1=1\n");
  r = run_command("ROWS_FILE=" + (tmp / "badly").string() + " " + study);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("row name 'Pyramid.s0' must be lower-case"), std::string::npos) << r.output;

  r = run_command("ROWS_FILE=" + (tmp / "nowhere").string() + " " + study);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("ROWS_FILE: no file"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(tmp / "study/capture"));  // refused before any work
}

TEST(AblationStudy, MultiGpuRowsAreRowsOfTheStudyOnEnoughGpus) {
  TempDir tmp;
  const std::string study = "VARIANTS='full gaussian-avatars' bash " + kScript + " " + (tmp / "study").string();
  auto r = run_command("MULTI_GPU_ROWS=no-warp " + study);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("MULTI_GPU_ROWS: 'no-warp' is not a row of the study"), std::string::npos) << r.output;

  r = run_command("MULTI_GPU_ROWS=full GPUS='0 1' " + study);  // MULTI_GPU 4 by default
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("GPUS lists 2 device(s), fewer than MULTI_GPU=4"), std::string::npos) << r.output;

  r = run_command("MULTI_GPU_ROWS=full MULTI_GPU=1 " + study);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("MULTI_GPU: '1' is not a number of GPUs above 1"), std::string::npos) << r.output;

  r = run_command("MULTI_GPU_ROWS='full full' MULTI_GPU=2 " + study);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("MULTI_GPU_ROWS: 'full' twice"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(tmp / "study/capture"));  // refused before any work
}

TEST(AblationStudy, GpusAreCudaDeviceIndices) {
  TempDir tmp;
  const auto r = run_command("GPUS='0 cuda:1' VARIANTS='full' bash " + kScript + " " + (tmp / "study").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("GPUS: 'cuda:1' is not a CUDA device index"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(tmp / "study/capture"));
}

TEST(AblationTable, RefusesFilesEvaluatedDifferentlyOrNamingARunTwice) {
  TempDir tmp;
  const auto document = [](const std::string& landmark_note, const std::string& run) {
    return nlohmann::json{{"format", "tega-eval"},
                          {"notes", {{"landmark_px", landmark_note}}},
                          {"models", {{{"name", run}, {"gaussians", 10}, {"splits", nlohmann::json::object()}}}}}
        .dump();
  };
  write_text(tmp / "a.json", document("with a predictor", "full.s0"));
  write_text(tmp / "b.json", document("with a predictor", "full.s1"));
  write_text(tmp / "c.json", document("skipped", "full.s2"));
  write_text(tmp / "d.json", document("with a predictor", "full.s0"));
  const std::string table = "python3 " + std::string(TEGA_SOURCE_DIR) + "/scripts/ablation-table ";
  const std::string files = (tmp / "a.json").string() + " " + (tmp / "b.json").string();

  const auto merged = run_command(table + files + " --merged " + (tmp / "ab.json").string());
  ASSERT_EQ(merged.exit_code, 0) << merged.output;
  EXPECT_EQ(nlohmann::json::parse(read_text_file(tmp / "ab.json")).at("models").size(), 2u);

  const auto differently = run_command(table + files + " " + (tmp / "c.json").string());
  EXPECT_NE(differently.exit_code, 0);
  EXPECT_NE(differently.output.find("evaluated differently"), std::string::npos) << differently.output;
  const auto twice = run_command(table + files + " " + (tmp / "d.json").string());
  EXPECT_NE(twice.exit_code, 0);
  EXPECT_NE(twice.output.find("run 'full.s0' is in both"), std::string::npos) << twice.output;
}

}  // namespace
}  // namespace tega::test
