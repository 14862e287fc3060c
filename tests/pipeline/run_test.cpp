// `tega run` and `tega status` on small virtual-studio pipelines: skipping,
// re-running exactly what changed, failures that stay contained, Ctrl-C.

#include <gtest/gtest.h>
#include <signal.h>

#include <nlohmann/json.hpp>
#include <thread>

#include "pipeline_test_support.h"
#include "tega/core/files.h"
#include "tega/core/mesh.h"
#include "test_support.h"

namespace tega::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

#define REQUIRE_SYNTH() \
  if (!tega_has_command({"synth"})) GTEST_SKIP() << "this build has no `tega synth`"

// Two independent chains: synth_a -> check_a and synth_b -> check_b.
std::string two_chains_config(const std::string& b_extra) {
  return "workspace: ws\nstages:\n  synth_a:\n    kind: synth\n    options:\n" + tiny_synth_options(6) +
         "  check_a: {kind: dataset_check, after: synth_a}\n  synth_b:\n    kind: synth\n    options:\n" +
         tiny_synth_options(6) + b_extra + "  check_b: {kind: dataset_check, after: synth_b}\n";
}

std::string two_subjects_config(const std::string& bob_synth_options) {
  return "workspace: ws\nsubjects:\n  alice: {}\n  bob: {options: {synth: {" + bob_synth_options +
         "}}}\nstages:\n  synth:\n    options:\n" + tiny_synth_options(6) +
         "  check: {kind: dataset_check, after: synth}\n";
}

json status_json(const fs::path& target, const fs::path& scratch) {
  const auto r = run_tega({"status", target.string(), "--json"}, scratch);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return json::parse(r.output);
}

std::string shard_state(const json& status, const std::string& stage, const std::string& shard) {
  for (const auto& s : status["stages"]) {
    if (s["stage"] != stage) continue;
    for (const auto& sh : s["shards"]) {
      if (sh["shard"] == shard) return sh["state"];
    }
  }
  return "(absent)";
}

TEST(TegaRun, SkipsDoneShardsAndReRunsOnlyWhatAChangedOptionReaches) {
  REQUIRE_SYNTH();
  TempDir dir;
  write_text(dir / "p.yaml", two_chains_config(""));
  const fs::path ws = dir / "ws";
  auto r = run_tega({"run", (dir / "p.yaml").string(), "--jobs", "2"}, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("4 shard(s) ran, 0 up to date"), std::string::npos) << r.output;
  const json synth_manifest = json::parse(read_text_file(ws / "synth_a/default/manifest.json"));
  EXPECT_GT(synth_manifest["peak_rss_mib"].get<double>(), 1.0);  // tega synth's own, from wait4
  EXPECT_LT(synth_manifest["peak_rss_mib"].get<double>(), 4096.0);

  r = run_tega({"run", (dir / "p.yaml").string()}, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("0 shard(s) ran, 4 up to date"), std::string::npos) << r.output;

  write_text(dir / "p.yaml", two_chains_config("      noise_sigma: 0.01\n"));
  EXPECT_EQ(shard_state(status_json(dir / "p.yaml", dir.path()), "synth_b", "default"), "stale");
  EXPECT_EQ(shard_state(status_json(dir / "p.yaml", dir.path()), "check_b", "default"), "stale");
  EXPECT_EQ(shard_state(status_json(dir / "p.yaml", dir.path()), "synth_a", "default"), "done");
  r = run_tega({"run", (dir / "p.yaml").string()}, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("2 shard(s) ran, 2 up to date"), std::string::npos) << r.output;
  EXPECT_EQ(attempts(ws, "synth_a", "default"), 1);
  EXPECT_EQ(attempts(ws, "check_a", "default"), 1);
  EXPECT_EQ(attempts(ws, "synth_b", "default"), 2);
  EXPECT_EQ(attempts(ws, "check_b", "default"), 2);
  EXPECT_NE(read_text_file(ws / "synth_b/default/options.yaml").find("noise_sigma: 0.01"), std::string::npos);
}

TEST(TegaRun, ASubjectsOwnOptionsReRunOnlyThatSubject) {
  REQUIRE_SYNTH();
  TempDir dir;
  write_text(dir / "p.yaml", two_subjects_config("seed: 2"));
  ASSERT_EQ(run_tega({"run", (dir / "p.yaml").string()}, dir.path()).exit_code, 0);
  write_text(dir / "p.yaml", two_subjects_config("seed: 3"));
  const auto r = run_tega({"run", (dir / "p.yaml").string()}, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(attempts(dir / "ws", "synth", "alice"), 1);
  EXPECT_EQ(attempts(dir / "ws", "check", "alice"), 1);
  EXPECT_EQ(attempts(dir / "ws", "synth", "bob"), 2);
  EXPECT_EQ(attempts(dir / "ws", "check", "bob"), 2);
}

TEST(TegaRun, ForceFromAndOnlySelectWhatRuns) {
  REQUIRE_SYNTH();
  TempDir dir;
  write_text(dir / "p.yaml", two_subjects_config("seed: 2"));
  const std::string config = (dir / "p.yaml").string();
  const fs::path ws = dir / "ws";

  // --only check before synth is done: nothing runs, and the reason is named.
  auto r = run_tega({"run", config, "--only", "check"}, dir.path());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("synth/alice blocked: is not up to date and its stage is not selected"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("check/alice blocked: needs synth/alice, which is blocked"), std::string::npos) << r.output;
  EXPECT_EQ(attempts(ws, "synth", "alice"), 0);

  ASSERT_EQ(run_tega({"run", config, "--only", "synth"}, dir.path()).exit_code, 0);
  EXPECT_EQ(attempts(ws, "check", "alice"), 0);
  ASSERT_EQ(run_tega({"run", config, "--only", "check"}, dir.path()).exit_code, 0);
  EXPECT_EQ(attempts(ws, "check", "alice"), 1);

  // --force synth re-runs synth; its outputs are identical (deterministic), so check stays done.
  const auto before = committed_outputs(ws);
  r = run_tega({"run", config, "--force", "synth"}, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(attempts(ws, "synth", "alice"), 2);
  EXPECT_EQ(attempts(ws, "check", "alice"), 1);
  EXPECT_EQ(committed_outputs(ws), before);

  // --from synth re-runs synth and everything downstream.
  ASSERT_EQ(run_tega({"run", config, "--from", "synth"}, dir.path()).exit_code, 0);
  EXPECT_EQ(attempts(ws, "synth", "bob"), 3);
  EXPECT_EQ(attempts(ws, "check", "bob"), 2);

  r = run_tega({"run", config, "--only", "chek"}, dir.path());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("has no stage 'chek'; its stages: synth, check"), std::string::npos) << r.output;
}

TEST(TegaRun, AMissingInputFailsItsShardOnlyAndStatusNamesTheError) {
  REQUIRE_SYNTH();
  TempDir dir;
  write_text(dir / "p.yaml", two_subjects_config("head: no-such-head"));
  const auto r = run_tega({"run", (dir / "p.yaml").string()}, dir.path());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("synth/bob failed: " + (dir / "no-such-head").string() + ": does not exist"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("check/bob blocked: needs synth/bob, which failed"), std::string::npos) << r.output;

  const json status = status_json(dir / "ws", dir.path());
  EXPECT_EQ(shard_state(status, "synth", "alice"), "done");
  EXPECT_EQ(shard_state(status, "check", "alice"), "done");
  EXPECT_EQ(shard_state(status, "synth", "bob"), "failed");
  EXPECT_NE(status["stages"][0]["shards"][1]["reason"].get<std::string>().find("no-such-head: does not exist"),
            std::string::npos);
  EXPECT_EQ(status["stages"][0]["shards"][1]["log"], (dir / "ws/logs/synth/bob.log").string());
  EXPECT_EQ(shard_state(status, "check", "bob"), "pending");
}

TEST(TegaRun, ACorruptCommittedInputFailsTheShardThatReadsItAndLeavesCompletedShardsIntact) {
  REQUIRE_SYNTH();
  TempDir dir;
  write_text(dir / "p.yaml", two_subjects_config("seed: 2"));
  const std::string config = (dir / "p.yaml").string();
  const fs::path ws = dir / "ws";
  ASSERT_EQ(run_tega({"run", config}, dir.path()).exit_code, 0);
  const std::string synth_manifest = read_text_file(ws / "synth/alice/manifest.json");

  // Same size, garbage content: the manifest's cheap size check cannot see it; the reader must.
  const fs::path image = ws / "synth/alice/capture/dataset/images/cam00/expressions_000000.png";
  const auto size = fs::file_size(image);
  write_text(image, std::string(size, 'x'));
  auto r = run_tega({"run", config, "--force", "check"}, dir.path());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("check/alice failed: exit code 1: tega: error: " + image.string()), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("(log: " + (ws / "logs/check/alice.log").string() + ")"), std::string::npos) << r.output;
  EXPECT_EQ(read_text_file(ws / "synth/alice/manifest.json"), synth_manifest);
  EXPECT_EQ(attempts(ws, "check", "bob"), 2);
  const json status = status_json(ws, dir.path());
  EXPECT_EQ(shard_state(status, "check", "alice"), "failed");
  EXPECT_EQ(shard_state(status, "check", "bob"), "done");
  EXPECT_EQ(shard_state(status, "synth", "alice"), "done");

  // A missing output file makes its shard stale, and the next run makes it again.
  fs::remove(image);
  EXPECT_EQ(shard_state(status_json(ws, dir.path()), "synth", "alice"), "stale");
  r = run_tega({"run", config}, dir.path());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(image));
  EXPECT_EQ(attempts(ws, "synth", "alice"), 2);
  EXPECT_EQ(shard_state(status_json(ws, dir.path()), "check", "alice"), "done");
}

TEST(TegaRun, CtrlCStopsCleanlyAndTheNextRunFinishes) {
  REQUIRE_SYNTH();
  TempDir dir;
  // One slow shard (a few seconds) to interrupt.
  write_text(dir / "p.yaml",
             "workspace: ws\nstages:\n  synth:\n    options:\n      studio: {cameras: 2, width: 96, height: 72}\n"
             "      frames: 4\n      calibration_frames: 1\n      write_fine_meshes: false\n      threads: 1\n");
  const std::string config = (dir / "p.yaml").string();
  const fs::path ws = dir / "ws";
  const pid_t run = spawn_tega({"run", config}, dir / "interrupted.txt");
  ASSERT_GT(run, 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!fs::exists(ws / "synth/default.state.json") && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));

  // A second run on the same workspace is refused while the first holds it.
  const auto second = run_tega({"run", config}, dir.path());
  EXPECT_EQ(second.exit_code, 1);
  EXPECT_NE(second.output.find("another `tega run` is using this workspace"), std::string::npos) << second.output;

  ::kill(run, SIGINT);
  EXPECT_EQ(wait_for_exit(run), 130);
  const std::string output = read_text_file(dir / "interrupted.txt");
  EXPECT_NE(output.find("interrupted; run it again"), std::string::npos) << output;
  EXPECT_FALSE(process_mentions(ws.string()));
  EXPECT_FALSE(fs::exists(ws / "synth/default/manifest.json"));
  EXPECT_EQ(shard_state(status_json(ws, dir.path()), "synth", "default"), "interrupted");

  const auto resumed = run_tega({"run", config}, dir.path());
  EXPECT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_EQ(shard_state(status_json(ws, dir.path()), "synth", "default"), "done");
  EXPECT_TRUE(staging_dirs(ws).empty());
}

TEST(TegaRun, StagesTheBuildLacksAreReportedNotFaked) {
  TempDir dir;
  const fs::path config = fs::path(TEGA_STUDIO_CONFIGS) / "studio13-capture.yaml";
  const auto r = run_tega({"run", config.string(), "--workspace", (dir / "ws").string()}, dir.path());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  const bool has_dataset_build = tega_has_command({"dataset", "build"});
  if (!has_dataset_build) {
    EXPECT_NE(r.output.find("dataset/default unavailable: `tega dataset build` is not available in this build"),
              std::string::npos)
        << r.output;
  }
  EXPECT_NE(r.output.find("0 shard(s) ran"), std::string::npos) << r.output;
  const json status = status_json(dir / "ws", dir.path());
  for (const auto& stage : status["stages"]) {
    if (stage["kind"] == "train") {
      EXPECT_EQ(stage["shards"][0]["state"], stage["available"] ? "pending" : "unavailable");
    } else if (stage["kind"] == "dataset") {
      EXPECT_EQ(stage["available"], has_dataset_build) << stage;
    } else if (stage["kind"] != "eval" && stage["kind"] != "render") {
      EXPECT_TRUE(stage["available"]) << stage;  // capture runs, and fails: this machine has no studio cameras
    }
  }
}

TEST(TegaRun, StartsFromATakeRecordedFromSimulatedCameras) {
  if (!tega_has_command({"capture"})) GTEST_SKIP() << "this build has no `tega capture` (Aravis)";
  TempDir dir;
  write_text(dir / "rig.yaml",
             "source: fake\nsettings: {width: 96, height: 64, frame_rate: 30}\n"
             "cameras: [{name: left, serial: P1}, {name: centre, serial: P2}, {name: right, serial: P3}]\n");
  write_text(dir / "session.yaml",
             "workspace: ws\nstages:\n"
             "  capture:\n    options:\n      rig: rig.yaml\n      trigger: free\n      takes:\n"
             "        - {name: board, kind: calibration, frames: 4}\n"
             "        - {name: talk, kind: performance, frames: 6}\n"
             "  check: {kind: capture_check, after: capture}\n");
  const auto r = run_tega({"run", (dir / "session.yaml").string()}, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("2 shard(s) ran"), std::string::npos) << r.output;
  const json capture = json::parse(read_text_file(dir / "ws/capture/default/capture/capture.json"));
  ASSERT_EQ(capture["takes"].size(), 2u);
  EXPECT_EQ(capture["takes"][1]["name"], "talk");
  EXPECT_EQ(capture["takes"][1]["frames"], 6);
  EXPECT_TRUE(fs::exists(dir / "ws/capture/default/capture/takes/talk/right/000005.png"));
  const json status = status_json(dir / "ws", dir.path());
  EXPECT_EQ(shard_state(status, "check", "default"), "done");
}

TEST(TegaRun, CalibratesTheRigFromTheCapturesCalibrationTake) {
  REQUIRE_SYNTH();
  if (!tega_has_command({"calibrate"})) GTEST_SKIP() << "this build has no `tega calibrate` (OpenCV + Ceres)";
  TempDir dir;
  write_text(dir / "board.yaml", "type: charuco\nsquares_x: 7\nsquares_y: 5\nsquare_m: 0.04\nmarker_m: 0.03\n");
  write_text(dir / "studio.yaml",
             "workspace: ws\nstages:\n"
             "  synth:\n    options:\n"
             "      studio: {cameras: 3, width: 480, height: 360}\n      calibration_frames: 10\n"
             "      frames: 1\n      takes: [expressions]\n      test_takes: []\n      supersampling: 1\n"
             "      fine_subdivisions: 0\n      write_fine_meshes: false\n"
             "  calibrate: {after: synth, options: {board: board.yaml}}\n");
  const auto r = run_tega({"run", (dir / "studio.yaml").string()}, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const json status = status_json(dir / "ws", dir.path());
  EXPECT_EQ(shard_state(status, "calibrate", "default"), "done");
  const json report = json::parse(read_text_file(dir / "ws/calibrate/default/rig.report.json"));
  EXPECT_EQ(report["cameras"].size(), 3u);
  EXPECT_LE(report["rms_px"].get<double>(), 0.5);
}

// The calibrated rig meshes every performance frame; a shard stopped half way
// keeps its finished frames (the stage resumes in its staging directory).
TEST(TegaRun, MeshesEveryPerformanceFrameWithTheCalibratedRig) {
  REQUIRE_SYNTH();
  if (!tega_has_command({"mvs"})) GTEST_SKIP() << "this build has no `tega mvs` (Open3D + OpenCV)";
  if (!tega_has_command({"calibrate"})) GTEST_SKIP() << "this build has no `tega calibrate` (OpenCV + Ceres)";
  TempDir dir;
  write_text(dir / "board.yaml", "type: charuco\nsquares_x: 7\nsquares_y: 5\nsquare_m: 0.04\nmarker_m: 0.03\n");
  write_text(dir / "studio.yaml",
             "workspace: ws\nstages:\n"
             "  synth:\n    options:\n"
             "      studio: {cameras: 5, width: 320, height: 240}\n      calibration_frames: 12\n"
             "      frames: 2\n      takes: [speech]\n      test_takes: []\n      write_fine_meshes: false\n"
             "  calibrate: {after: synth, options: {board: board.yaml}}\n"
             "  mvs:\n    after: calibrate\n    options:\n      device: cpu\n"
             "      patch_match: {iterations: 3, geometric_iterations: 1}\n      surface: {threads: 1}\n");
  const auto r = run_tega({"run", (dir / "studio.yaml").string()}, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const json status = status_json(dir / "ws", dir.path());
  EXPECT_EQ(shard_state(status, "mvs", "default"), "done");
  for (const char* frame : {"000000", "000001"}) {
    const fs::path mesh = dir / "ws/mvs/default/meshes/speech" / (std::string(frame) + ".ply");
    ASSERT_TRUE(fs::exists(mesh)) << mesh;
    EXPECT_GT(read_mesh(mesh).num_faces(), 1000);
  }
  EXPECT_FALSE(fs::exists(dir / "ws/mvs/default/.resume-key"));

  // As if a run had been killed after both frames: a staging directory with
  // the frames and the shard's key. Run again, the frames are kept.
  const fs::path staging = dir / "ws/mvs/.staging-default";
  fs::create_directories(staging);
  fs::copy(dir / "ws/mvs/default/meshes", staging / "meshes", fs::copy_options::recursive);
  const json manifest = json::parse(read_text_file(dir / "ws/mvs/default/manifest.json"));
  write_text(staging / ".resume-key", manifest["key"].get<std::string>());
  const auto resumed = run_tega({"run", (dir / "studio.yaml").string(), "--force", "mvs"}, dir.path());
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  const std::string log = read_text_file(dir / "ws/logs/mvs/default.log");
  EXPECT_NE(log.find("0 frame(s) meshed, 2 already done"), std::string::npos) << log;

  // Split into a job per frame, run at once: the same meshes, byte for byte.
  const fs::path meshes = dir / "ws/mvs/default/meshes/speech";
  const std::string unsplit[] = {read_text_file(meshes / "000000.ply"), read_text_file(meshes / "000001.ply")};
  write_text(dir / "split.yaml", read_text_file(dir / "studio.yaml") + "    frames_per_job: 1\n");
  const auto split = run_tega({"run", (dir / "split.yaml").string(), "--force", "mvs", "--jobs", "2"}, dir.path());
  ASSERT_EQ(split.exit_code, 0) << split.output;
  EXPECT_NE(split.output.find("mvs/default started as 2 jobs"), std::string::npos) << split.output;
  EXPECT_TRUE(read_text_file(meshes / "000000.ply") == unsplit[0]);
  EXPECT_TRUE(read_text_file(meshes / "000001.ply") == unsplit[1]);
  for (const char* part : {"default#1.log", "default#2.log"}) {
    const std::string part_log = read_text_file(dir / "ws/logs/mvs" / part);
    EXPECT_NE(part_log.find("1 frame(s) meshed"), std::string::npos) << part << ": " << part_log;
  }
}

TEST(TegaRun, OnlyStagesThatSplitTakeFramesPerJob) {
  TempDir dir;
  write_text(dir / "p.yaml", "workspace: ws\nstages:\n  synth:\n  check: {kind: dataset_check, after: synth, "
                             "frames_per_job: 10}\n");
  const auto r = run_tega({"run", (dir / "p.yaml").string()}, dir.path());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("stage 'check': frames_per_job: a dataset_check shard runs as one job"), std::string::npos)
      << r.output;
}

// No GPU needed: the train shard's log header shows the GPUs it was pinned to and the flag that
// spreads training over them, before tega train finds that CUDA is not there.
TEST(TegaRun, ATrainShardOfSeveralGpusIsPinnedToThatManyAndTrainsOnAllOfThem) {
  REQUIRE_SYNTH();
  TempDir dir;
  const std::string stages = "workspace: ws\nstages:\n  synth:\n    options:\n" + tiny_synth_options(6) +
                             "  train:\n    after: synth\n    gpus_per_job: 2\n    options: {iterations: 2, device: ";
  write_text(dir / "cuda.yaml", stages + "cuda}\n");
  const auto r = run_tega({"run", (dir / "cuda.yaml").string(), "--gpus", "3,1,2"}, dir.path());
  EXPECT_NE(r.output.find("train/default started on 2 GPUs"), std::string::npos) << r.output;
  const std::string log = read_text_file(dir / "ws/logs/train/default.log");
  EXPECT_NE(log.find("train/default on GPUs 3,1, "), std::string::npos) << log;
  EXPECT_NE(log.find(" --gpus 0,1"), std::string::npos) << log;

  write_text(dir / "cpu.yaml", stages + "cpu}\n");
  const auto cpu = run_tega({"run", (dir / "cpu.yaml").string(), "--workspace", (dir / "cpu").string()}, dir.path());
  EXPECT_NE(cpu.exit_code, 0);
  EXPECT_NE(cpu.output.find("gpus_per_job: 2 needs the option device: cuda (it is cpu)"), std::string::npos)
      << cpu.output;

  write_text(dir / "check.yaml", "workspace: ws\nstages:\n  synth:\n  check: {kind: dataset_check, after: synth, "
                                 "gpus_per_job: 2}\n");
  const auto check = run_tega({"run", (dir / "check.yaml").string()}, dir.path());
  EXPECT_NE(check.exit_code, 0);
  EXPECT_NE(check.output.find("stage 'check': gpus_per_job: a dataset_check shard runs on one GPU"), std::string::npos)
      << check.output;
}

TEST(TegaRun, ABadGpuListIsAnErrorBeforeAnythingRuns) {
  TempDir dir;
  write_text(dir / "p.yaml", "workspace: ws\nstages:\n  check: {kind: dataset_check}\n");
  const auto twice = run_tega({"run", (dir / "p.yaml").string(), "--gpus", "0,1,0"}, dir.path());
  EXPECT_NE(twice.exit_code, 0);
  EXPECT_NE(twice.output.find("--gpus: GPU '0' is listed twice"), std::string::npos) << twice.output;
  const auto slurm = run_tega({"run", (dir / "p.yaml").string(), "--executor", "slurm", "--gpus", "0"}, dir.path());
  EXPECT_NE(slurm.exit_code, 0);
  EXPECT_NE(slurm.output.find("--gpus applies to --executor local only"), std::string::npos) << slurm.output;
  EXPECT_FALSE(fs::exists(dir / "ws"));
}

TEST(TegaRun, TheShippedConfigsAreValidGraphs) {
  for (const char* name : {"demo.yaml", "studio13-capture.yaml", "studio-raw.yaml"}) {
    TempDir dir;
    const auto r = run_tega({"status", (fs::path(TEGA_STUDIO_CONFIGS) / name).string(), "--json"}, dir.path());
    EXPECT_EQ(r.exit_code, 0) << name << ": " << r.output;
  }
}

}  // namespace
}  // namespace tega::test
