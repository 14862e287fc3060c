// `tega report` on real workspaces made by `tega run`: a virtual-studio
// capture calibrated and meshed (with tracking and matting configured but not
// run), and a tiny capture trained, evaluated and rendered. Each suite makes
// its workspace once (about 20 s each on 2 cores) and reads the page it gets.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "pipeline_test_support.h"
#include "tega/core/files.h"
#include "tega/core/image.h"
#include "tega/core/mesh.h"
#include "tega/core/rig.h"
#include "tega/pipeline/manifest.h"
#include "tega/scoring/tracking_scores.h"
#include "test_support.h"

namespace tega::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The text of one "## " section of a page, up to the next.
std::string section(const std::string& page, const std::string& title) {
  const size_t start = page.find("\n## " + title);
  if (start == std::string::npos) return "";
  return page.substr(start, page.find("\n## ", start + 1) - start);
}

void expect_png(const fs::path& file, int width, int height) {
  ASSERT_TRUE(fs::exists(file)) << file;
  const Image8 image = read_image_u8(file);
  EXPECT_EQ(image.width, width) << file;
  EXPECT_EQ(image.height, height) << file;
}

// A workspace made once per suite and shared by its tests.
class Workspace : public ::testing::Test {
 protected:
  static void make(const std::string& config, const std::vector<std::string>& run_flags,
                   const std::vector<std::string>& needed_commands) {
    for (const auto& command : needed_commands)
      if (!tega_has_command({command})) {
        skip_reason_ = "this build has no `tega " + command + "`";
        return;
      }
    if (!tega_has_command({"report"})) {
      skip_reason_ = "this build has no `tega report` (OpenCV)";
      return;
    }
    dir_ = new TempDir;
    write_text(*dir_ / "board.yaml", "type: charuco\nsquares_x: 7\nsquares_y: 5\nsquare_m: 0.04\nmarker_m: 0.03\n");
    fs::create_directories(*dir_ / "model");
    write_text(*dir_ / "job.yaml", config);
    std::vector<std::string> args{"run", (*dir_ / "job.yaml").string()};
    args.insert(args.end(), run_flags.begin(), run_flags.end());
    const auto run = run_tega(args, dir_->path());
    ASSERT_EQ(run.exit_code, 0) << run.output;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
    skip_reason_.clear();
  }
  void SetUp() override {
    if (!skip_reason_.empty()) GTEST_SKIP() << skip_reason_;
    ASSERT_NE(dir_, nullptr);
  }
  static fs::path workspace() { return *dir_ / "ws"; }
  static TegaResult report(std::vector<std::string> flags = {}) {
    flags.insert(flags.begin(), {"report", workspace().string()});
    return run_tega(flags, dir_->path());
  }

  static inline TempDir* dir_ = nullptr;
  static inline std::string skip_reason_;
};

// Calibrated and meshed in the virtual studio: both are scored against its truth.
class ReportStudio : public Workspace {
 protected:
  static void SetUpTestSuite() {
    make(
        "workspace: ws\nsubjects:\n  alice: {}\nstages:\n"
        "  synth:\n    options:\n"
        "      studio: {cameras: 3, width: 480, height: 360}\n      calibration_frames: 10\n"
        "      frames: 1\n      takes: [expressions]\n      test_takes: []\n      supersampling: 1\n"
        "      fine_subdivisions: 1\n      threads: 2\n"
        "  calibrate: {after: synth, options: {board: board.yaml}}\n"
        "  mvs:\n    after: calibrate\n    options:\n      device: cpu\n"
        "      patch_match: {iterations: 3, geometric_iterations: 1}\n      surface: {threads: 1}\n"
        "  track: {after: mvs, options: {model: model}}\n"
        "  matte: {after: track}\n",
        {"--only", "synth", "--only", "calibrate", "--only", "mvs", "--jobs", "2"}, {"synth", "calibrate", "mvs"});
  }
};

TEST_F(ReportStudio, ThePageHoldsEachStagesNumbersAndTheirGroundTruthScores) {
  const auto r = report();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const fs::path page_dir = workspace() / "report" / "alice";
  EXPECT_TRUE(has(r.output, (page_dir / "report.md").string())) << r.output;
  const std::string page = read_text_file(page_dir / "report.md");

  // Calibration: every camera's RMS as the rig's report gives it.
  const std::string calibration = section(page, "Calibration (calibrate)");
  ASSERT_FALSE(calibration.empty()) << page;
  const json rig_report = json::parse(read_text_file(workspace() / "calibrate/alice/rig.report.json"));
  ASSERT_EQ(rig_report["cameras"].size(), 3u);
  for (const auto& camera : rig_report["cameras"]) {
    const std::string row = "| " + camera["name"].get<std::string>() + " | " +
                            std::to_string(camera["views"].get<int>()) + " | " +
                            std::to_string(camera["corners"].get<int>()) + " | " +
                            std::to_string(camera["outliers"].get<int>()) + " | " + fixed(camera["rms_px"], 3) + " |";
    EXPECT_TRUE(has(calibration, row)) << row << "\n" << calibration;
  }
  EXPECT_TRUE(has(calibration, "total RMS " + fixed(rig_report["rms_px"], 3) + " px")) << calibration;
  EXPECT_TRUE(has(calibration, "](../../calibrate/alice/rig.residuals/cam00.png)")) << calibration;
  expect_png(page_dir / "calibration_rms.png", 960, 300);

  // MVS: the frame record's numbers.
  const std::string mvs = section(page, "Multi-view stereo (mvs)");
  const json frame = json::parse(read_text_file(workspace() / "mvs/alice/meshes/expressions/000000.json"));
  EXPECT_TRUE(has(mvs, "| expressions | 1 | " + std::to_string(frame["depth_map_cameras"].size()) + " | " +
                           std::to_string(frame["depth_pixels"].get<long>()) + " | " +
                           std::to_string(frame["points"].get<long>()) + " | " +
                           std::to_string(frame["vertices"].get<long>())))
      << mvs;
  expect_png(page_dir / "mvs_frames.png", 960, 2 * 260 + 30);

  // Stages configured but not run say so.
  EXPECT_TRUE(has(section(page, "track (track)"), "Not run: track is pending")) << page;
  EXPECT_TRUE(has(section(page, "matte (matte)"), "Not run: matte is pending")) << page;
  EXPECT_TRUE(section(page, "Training").empty()) << "no train stage in the config";

  // The self-test: the calibrated rig and the mesh against the studio's truth, beside their targets.
  const std::string self_test = section(page, "Ground truth: the studio's self-test");
  EXPECT_TRUE(has(self_test, "| calibrate | worst camera centre error | ")) << self_test;
  EXPECT_TRUE(has(self_test, "< 1 mm (CI bound) | ")) << self_test;
  EXPECT_TRUE(has(self_test, "| mvs | mesh accuracy, median (worst scored frame) | ")) << self_test;
  EXPECT_TRUE(has(self_test, "| <= 2.0 mm | met |")) << self_test;
  EXPECT_TRUE(has(self_test, "| >= 90 % |")) << self_test;
  EXPECT_TRUE(has(mvs, "| expressions | 0 | ")) << "the scored frame's row\n" << mvs;

  const std::string html = read_text_file(page_dir / "report.html");
  EXPECT_TRUE(has(html, "<h2>Calibration (calibrate)</h2>")) << html;
  EXPECT_TRUE(has(html, "<img src=\"calibration_rms.png\"")) << html;
}

TEST_F(ReportStudio, AnUnreadableStageOutputIsNamedOnThePageAndTheRestIsReported) {
  const fs::path rig_report = workspace() / "calibrate/alice/rig.report.json";
  const std::string original = read_text_file(rig_report);
  write_text(rig_report, "{\"cameras\": [{\"name\": \"cam00\"}]}");
  const auto r = report({"--out", (*dir_ / "damaged").string(), "--no-ground-truth"});
  write_text(rig_report, original);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string page = read_text_file(*dir_ / "damaged/alice/report.md");
  const std::string calibration = section(page, "calibrate (calibrate)");
  EXPECT_TRUE(has(calibration, "Could not be read: " + rig_report.string() + ": is not a calibration report")) << page;
  EXPECT_FALSE(section(page, "Multi-view stereo (mvs)").empty()) << page;
  EXPECT_TRUE(section(page, "Ground truth").empty()) << "--no-ground-truth";
  EXPECT_FALSE(fs::exists(*dir_ / "damaged/alice/calibration_rms.png"));
}

TEST_F(ReportStudio, AnUnknownSubjectOrANonWorkspaceIsAnError) {
  const auto unknown = report({"--subject", "bob"});
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_TRUE(has(unknown.output, "pipeline.json: its config has no subject 'bob'")) << unknown.output;
  const auto not_workspace = run_tega({"report", (*dir_ / "model").string()}, dir_->path());
  EXPECT_EQ(not_workspace.exit_code, 1);
  EXPECT_TRUE(has(not_workspace.output, "is not a tega workspace")) << not_workspace.output;
}

// A committed shard made outside `tega run`: its manifest matches nothing, so
// `tega status` calls it stale, but its outputs are there to report on.
void commit_by_hand(const fs::path& shard, const std::string& stage, const std::string& kind) {
  pipeline::Manifest manifest;
  manifest.stage = stage, manifest.shard = shard.filename().string(), manifest.kind = kind;
  pipeline::write_manifest(shard / "manifest.json", manifest);
}

// A tracked subject turned 1 degree from the true one in head space, its
// poses turned back so that every world mesh stays the truth's: the head is
// not turned at all, though each pose is that degree off the truth's.
TEST_F(ReportStudio, AFittedSubjectsTurnIsNotATurnOfTheHead) {
  const fs::path capture = workspace() / "synth/alice/capture";
  TempDir dir;
  const fs::path tracked = dir / "tracked";
  scoring::write_studio_truth_as_tracked(capture, tracked);
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(M_PI / 180, Eigen::Vector3d(1, 0.3, 0).normalized()).matrix();
  Mesh neutral = read_obj(tracked / "identity_neutral.obj");
  neutral.positions = (neutral.positions.cast<double>() * turn.transpose()).cast<float>();
  write_obj(neutral, tracked / "identity_neutral.obj");
  for (const auto& entry : fs::directory_iterator(tracked / "expressions")) {
    if (entry.path().extension() != ".json" || entry.path().filename() == "track.json") continue;
    json record = json::parse(read_text_file(entry.path()));
    Eigen::Matrix3d R;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) R(r, c) = record["head_to_world"][r][c];
    const Eigen::Matrix3d turned_back = R * turn.transpose();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) record["head_to_world"][r][c] = turned_back(r, c);
    write_text(entry.path(), record.dump());
  }
  const scoring::TrackScores s = scoring::score_against_studio(tracked, capture, "expressions");
  EXPECT_LT(s.rotation_max_deg, 1e-3);
  EXPECT_NEAR(s.subject_rotation_deg, 1.0, 1e-3);
  EXPECT_NEAR(s.pose_rotation_median_deg, 1.0, 1e-3);
  EXPECT_LT(s.vertex_median_m, 1e-6);
}

// The studio's own truth as the tracked meshes and the mattes (tracking and
// matting themselves take minutes): their sections read them, and the
// self-test finds no error. Runs last: it adds shards to the suite's workspace.
TEST_F(ReportStudio, ZTrackedAndMattedShardsAreShownAndScoredAgainstTheTruth) {
  const fs::path capture = workspace() / "synth/alice/capture";
  fs::create_directories(workspace() / "track/alice");
  // Where tracking with the calibrated rig would put them: in its world.
  const Rig calibrated = read_rig_json(workspace() / "calibrate/alice/rig.json");
  const Rig truth = read_rig_json(capture / "rig.json");
  scoring::write_studio_truth_as_tracked(capture, workspace() / "track/alice/tracked", {},
                                          align_camera_centres(truth, calibrated));
  commit_by_hand(workspace() / "track/alice", "track", "track");
  const fs::path take = workspace() / "matte/alice/mattes/expressions";
  const json cameras = json::parse(read_text_file(capture / "takes/expressions/take.json"))["cameras"];
  for (const auto& camera : cameras) {
    fs::create_directories(take / camera.get<std::string>());
    fs::copy_file(capture / "ground_truth/expressions/alpha" / camera.get<std::string>() / "000000.png",
                  take / camera.get<std::string>() / "000000.png");
  }
  write_text(take / "mattes.json", json({{"take", "expressions"},
                                         {"cameras", cameras},
                                         {"frames_matted", 1},
                                         {"frames_not_tracked", json::array()},
                                         {"clean_plate", "clean_plate"},
                                         {"images", "{camera}/{frame:06d}.png"}})
                                       .dump());
  commit_by_hand(workspace() / "matte/alice", "matte", "matte");

  const auto r = report();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const fs::path page_dir = workspace() / "report" / "alice";
  const std::string page = read_text_file(page_dir / "report.md");
  const std::string tracking = section(page, "Tracking (track)");
  EXPECT_TRUE(has(tracking, "Note: this shard is stale")) << tracking;
  EXPECT_TRUE(has(tracking, "| expressions | 1 | 0 | 0 | 0.000 | 0.000 | 100.0 | - | - |")) << tracking;
  expect_png(page_dir / "tracking_residuals.png", 960, 2 * 260 + 30);
  const std::string matting = section(page, "Matting (matte)");
  EXPECT_TRUE(has(matting, "| expressions | " + std::to_string(cameras.size()) + " | 1 | 0 |")) << page;
  expect_png(page_dir / "matte_coverage.png", 960, 300);
  const std::string self_test = section(page, "Ground truth: the studio's self-test");
  EXPECT_TRUE(has(self_test, "| track (expressions) | vertex error median | 0.00 mm | <= 1.00 mm | met |"))
      << self_test;
  EXPECT_TRUE(has(self_test, "| matte (expressions) | silhouette IoU, worst image | 1.0000 | >= 0.98 | met |"))
      << self_test;
  EXPECT_FALSE(has(self_test, "Not scored")) << self_test;
}

// Trained, evaluated and rendered on the tiniest capture.
class ReportTraining : public Workspace {
 protected:
  static void SetUpTestSuite() {
    make("workspace: ws\nstages:\n  synth:\n    options:\n" + tiny_synth_options(6) +
             "  train:\n    after: [synth]\n    options:\n"
             "      device: cpu\n      cpu_threads: 1\n      loader_threads: 1\n      prefetch: 2\n"
             "      iterations: 30\n      log_every: 5\n      initial_gaussians: 64\n      warmup: 0.25\n"
             "      densify: {start: 0.0, stop: 1.0, interval: 0.25, gradient_threshold: 0.0}\n"
             "      loss: {smoothness_samples: 32}\n"
             "      network: {texture_size: 16, unet_widths: [4, 8], latent_channels: 4, mlp_hidden: 8}\n"
             "      uv_lookup: {resolution: 32}\n"
             "  eval: {after: [train], options: {device: cpu}}\n"
             "  render: {after: [train], options: {device: cpu, no_video: true}}\n",
         {"--jobs", "2"}, {"synth", "train", "eval", "render"});
  }
};

TEST_F(ReportTraining, ThePageHoldsTheCurvesTheEvalTableAndRendersBesideThePhotos) {
  const auto r = report({"--contact-sheet-views", "3"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const fs::path page_dir = workspace() / "report" / "default";
  const std::string page = read_text_file(page_dir / "report.md");

  const std::string training = section(page, "Training (train)");
  const json run = json::parse(read_text_file(workspace() / "train/default/run/run.json"));
  EXPECT_TRUE(has(training, "| 30 | " + std::to_string(run["gaussians"].get<long>()) + " | " +
                                fixed(run["final_loss"], 5) + " | " + fixed(run["train_psnr"], 2) + " | "))
      << training;
  expect_png(page_dir / "training_curves.png", 960, 3 * 260 + 30);

  const std::string eval = section(page, "Evaluation (eval)");
  const json table = json::parse(read_text_file(workspace() / "eval/default/eval.json"));
  const json& psnr = table["models"][0]["splits"]["reenactment"]["metrics"]["psnr"];
  EXPECT_TRUE(has(eval, "| reenactment | ")) << eval;
  EXPECT_TRUE(has(eval, fixed(psnr["mean"], 2) + " ± " + fixed(psnr["std"], 2))) << eval;
  // The virtual studio's dataset has no landmark vertices and eval was given no predictor: said, not shown.
  EXPECT_TRUE(has(eval, "landmark_px skipped")) << eval;
  EXPECT_TRUE(has(eval, "close-ups skipped")) << eval;
  EXPECT_FALSE(has(eval, "closeup_mouth_psnr")) << eval;

  const std::string renders = section(page, "Renders (render)");
  EXPECT_TRUE(has(renders, "3 of ")) << renders;
  EXPECT_TRUE(has(renders, "beside the dataset's photo")) << renders;
  ASSERT_TRUE(fs::exists(page_dir / "contact_sheet.png"));
  const Image8 sheet = read_image_u8(page_dir / "contact_sheet.png");
  EXPECT_EQ(sheet.width, 2 * (2 * 192 + 8) + 8);  // two views a row, each render | photo at 192 px a half

  // No calibration stage: no calibration section; a studio capture with nothing to score says so.
  EXPECT_TRUE(section(page, "Calibration").empty()) << page;
  EXPECT_TRUE(has(section(page, "Ground truth"), "No stage with a ground truth to score has run.")) << page;
  EXPECT_TRUE(fs::exists(page_dir / "report.html"));
}

}  // namespace
}  // namespace tega::test
