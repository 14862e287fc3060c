#include "tega/pipeline/stage_kinds.h"

#include <algorithm>

#include "tega/core/take.h"

namespace tega::pipeline {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> with_config(std::vector<std::string> arguments, const ShardPaths& p) {
  arguments.insert(arguments.end(), {"--config", p.options_file.string()});
  return arguments;
}

std::vector<std::string> with_flags(std::vector<std::string> arguments, const ShardPaths& p) {
  arguments.insert(arguments.end(), p.option_flags.begin(), p.option_flags.end());
  return arguments;
}

// The capture's performance takes, as `tega mvs` and `tega matte` take them by default.
std::vector<CaptureTake> performance_takes(const ShardPaths& p) {
  std::vector<CaptureTake> takes;
  for (const CaptureTake& take : read_capture(p.artifacts.at("capture")).takes)
    if (take.kind == "performance") takes.push_back(take);
  return takes;
}

// A job per take and run of at most `frames_per_job` frames.
std::vector<std::vector<std::string>> by_frame_ranges(const ShardPaths& p, int frames_per_job) {
  std::vector<std::vector<std::string>> jobs;
  for (const CaptureTake& take : performance_takes(p)) {
    for (int first = 0; first < take.frames; first += frames_per_job) {
      const int end = std::min(take.frames, first + frames_per_job);
      jobs.push_back({"--take", take.name, "--frames", std::to_string(first) + ":" + std::to_string(end)});
    }
  }
  return jobs;
}

// A job per take: each writes its take's own summary file.
std::vector<std::vector<std::string>> by_takes(const ShardPaths& p, int) {
  std::vector<std::vector<std::string>> jobs;
  for (const CaptureTake& take : performance_takes(p)) jobs.push_back({"--take", take.name});
  return jobs;
}

std::vector<StageKind> make_stage_kinds() {
  std::vector<StageKind> kinds;

  StageKind synth;
  synth.name = "synth";
  synth.summary = "virtual studio: a synthetic capture with ground truth and a ready dataset (tega synth)";
  synth.subcommand = {"synth"};
  synth.provides = {{"capture", "capture"}, {"dataset", "capture/dataset"}};
  synth.path_options = {"head"};
  synth.arguments = [](const ShardPaths& p) { return with_config({"--out", (p.output / "capture").string()}, p); };
  kinds.push_back(synth);

  // The raw path's input (docs/pipeline.md#raw-frames-to-avatar): with
  // --truth-apart `capture` holds only the takes and the truth (rig,
  // ground_truth/, dataset/) lies beside it, where no stage that takes the
  // capture looks. It provides no `dataset`: the raw path's comes from a
  // `dataset` stage, never from the truth.
  StageKind synth_raw = synth;
  synth_raw.name = "synth_raw";
  synth_raw.summary =
      "virtual studio: a raw synthetic capture, its ground truth apart for tega report (tega synth, truth_apart)";
  synth_raw.provides = {{"capture", "capture"}, {"truth", "capture.truth"}};
  synth_raw.arguments = [](const ShardPaths& p) {
    return with_config({"--out", (p.output / "capture").string(), "--truth-apart"}, p);
  };
  kinds.push_back(synth_raw);

  StageKind ingest;
  ingest.name = "ingest_multiface";
  ingest.summary = "a Multiface capture converted to a dataset (tega ingest multiface)";
  ingest.subcommand = {"ingest", "multiface"};
  ingest.provides = {{"dataset", "dataset"}};
  ingest.options_section = "ingest";
  ingest.reads_capture = true;
  ingest.arguments = [](const ShardPaths& p) {
    return with_config({"--capture", p.capture.string(), "--out", (p.output / "dataset").string()}, p);
  };
  kinds.push_back(ingest);

  StageKind check;
  check.name = "dataset_check";
  check.summary = "checks a dataset the way training does (tega dataset check)";
  check.subcommand = {"dataset", "check"};
  check.needs = {"dataset"};
  check.options_as = OptionsAs::none;
  check.arguments = [](const ShardPaths& p) {
    return std::vector<std::string>{"--data", p.artifacts.at("dataset").string()};
  };
  kinds.push_back(check);

  StageKind train;
  train.name = "train";
  train.summary = "trains a TeGA avatar (tega train)";
  train.subcommand = {"train"};
  train.needs = {"dataset"};
  train.provides = {{"run", "run"}};
  train.path_options = {"loss.vgg_weights"};
  train.device_option = "device";
  train.gpus_flag = "--gpus";  // data parallel (docs/training.md#on-several-gpus)
  // A shard killed mid-run continues from its last checkpoint.
  train.resumes_in_staging = true;
  train.arguments = [](const ShardPaths& p) {
    const fs::path run = p.output / "run";
    std::vector<std::string> arguments{"--data", p.artifacts.at("dataset").string(), "--out", run.string()};
    if (fs::exists(run / "checkpoint.safetensors") || fs::exists(run / "checkpoint.previous.safetensors"))
      arguments.push_back("--resume");
    return with_config(arguments, p);
  };
  kinds.push_back(train);

  // eval and render take their options as flags (`tega eval --help`). The
  // stage reports itself unavailable while the running binary lacks the command.
  StageKind eval;
  eval.name = "eval";
  eval.summary = "evaluates a trained avatar with the paper's protocol: the eval table (tega eval)";
  eval.subcommand = {"eval"};
  eval.needs = {"run", "dataset"};
  eval.provides = {{"eval", "eval.json"}, {"eval_table", "eval.md"}};
  eval.options_as = OptionsAs::flags;
  eval.flag_options = {"split", "lpips_vgg", "lpips_lin", "landmark_predictor", "device"};
  eval.path_options = {"lpips_vgg", "lpips_lin", "landmark_predictor"};
  eval.device_option = "device";
  eval.arguments = [](const ShardPaths& p) {
    return with_flags({"--model", p.artifacts.at("run").string(), "--data", p.artifacts.at("dataset").string(),
                       "--json", (p.output / "eval.json").string()},
                      p);
  };
  kinds.push_back(eval);

  StageKind render;
  render.name = "render";
  render.summary = "renders a trained avatar to images and videos (tega render)";
  render.subcommand = {"render"};
  render.needs = {"run", "dataset"};
  render.provides = {{"renders", "renders"}};
  render.options_as = OptionsAs::flags;
  render.flag_options = {"cameras", "orbit", "camera_file", "frames", "width", "height", "format",
                         "no_side_by_side", "no_video", "fps", "device"};
  render.path_options = {"camera_file"};
  render.device_option = "device";
  render.arguments = [](const ShardPaths& p) {
    return with_flags({"--model", p.artifacts.at("run").string(), "--data", p.artifacts.at("dataset").string(),
                       "--out", (p.output / "renders").string()},
                      p);
  };
  kinds.push_back(render);

  // Without `frame` or `meshes` one PLY, of the first training frame: every
  // frame of a studio subject would be gigabytes of Gaussians each.
  StageKind export_ply;
  export_ply.name = "export";
  export_ply.summary = "exports posed Gaussians as 3D Gaussian Splatting PLY or SPZ files (tega export)";
  export_ply.subcommand = {"export"};
  export_ply.needs = {"run", "dataset"};
  export_ply.provides = {{"export", "export"}};
  export_ply.options_as = OptionsAs::flags;
  export_ply.flag_options = {"frame", "meshes", "mesh_pose", "head_space", "format", "device"};
  export_ply.path_options = {"meshes"};
  export_ply.device_option = "device";
  export_ply.arguments = [](const ShardPaths& p) {
    std::vector<std::string> arguments{"--model", p.artifacts.at("run").string(), "--data",
                                       p.artifacts.at("dataset").string(), "--out", (p.output / "export").string()};
    const auto& flags = p.option_flags;
    if (std::find(flags.begin(), flags.end(), "--frame") == flags.end() &&
        std::find(flags.begin(), flags.end(), "--meshes") == flags.end())
      arguments.insert(arguments.end(), {"--frame", "first"});
    return with_flags(arguments, p);
  };
  kinds.push_back(export_ply);

  StageKind capture;
  capture.name = "capture";
  capture.summary = "records the session's takes from the GenICam rig through Aravis (tega capture session)";
  capture.subcommand = {"capture", "session"};
  capture.provides = {{"capture", "capture"}};
  capture.options_section = "capture";
  capture.path_options = {"rig"};
  capture.arguments = [](const ShardPaths& p) { return with_config({"--out", (p.output / "capture").string()}, p); };
  kinds.push_back(capture);

  StageKind capture_check;
  capture_check.name = "capture_check";
  capture_check.summary = "checks a capture the way later stages read it (tega capture validate)";
  capture_check.subcommand = {"capture", "validate"};
  capture_check.needs = {"capture"};
  capture_check.options_as = OptionsAs::none;
  capture_check.arguments = [](const ShardPaths& p) {
    return std::vector<std::string>{"--capture", p.artifacts.at("capture").string()};
  };
  kinds.push_back(capture_check);

  // The capture's take named "calibration" (docs/calibration.md#in-the-pipeline).
  StageKind calibrate;
  calibrate.name = "calibrate";
  calibrate.summary = "calibrates the rig from the capture's calibration take (tega calibrate)";
  calibrate.subcommand = {"calibrate"};
  calibrate.needs = {"capture"};
  calibrate.provides = {{"rig", "rig.json"}};
  calibrate.options_as = OptionsAs::flags;
  calibrate.flag_options = {"board",          "init",       "world",     "world_camera",
                            "world_board_frame", "robust_loss_px", "outlier_px", "free_k3", "refine_init_intrinsics",
                            "min_views",      "threads"};
  calibrate.path_options = {"board", "init"};
  calibrate.arguments = [](const ShardPaths& p) {
    return with_flags({"--take", (p.artifacts.at("capture") / "takes" / "calibration").string(), "--out",
                       (p.output / "rig.json").string()},
                      p);
  };
  kinds.push_back(calibrate);
  // Every performance take of the capture, with the calibrated rig.
  StageKind mvs;
  mvs.name = "mvs";
  mvs.summary = "reconstructs a mesh per frame of every performance take (tega mvs)";
  mvs.subcommand = {"mvs"};
  mvs.needs = {"capture", "rig"};
  mvs.provides = {{"meshes", "meshes"}};
  mvs.options_section = "mvs";
  mvs.device_option = "device";
  mvs.resumes_in_staging = true;
  mvs.arguments = [](const ShardPaths& p) {
    return with_config({"--capture", p.artifacts.at("capture").string(), "--rig", p.artifacts.at("rig").string(),
                        "--out", (p.output / "meshes").string()},
                       p);
  };
  mvs.split = by_frame_ranges;
  kinds.push_back(mvs);
  // Every performance take, its frames in order (or ranges of them at once); the model is an option (a path).
  StageKind track;
  track.name = "track";
  track.summary = "fits the blendshape head model to every frame's mesh (tega track)";
  track.subcommand = {"track"};
  track.needs = {"capture", "rig", "meshes"};
  track.provides = {{"tracked", "tracked"}};
  track.options_section = "track";
  track.path_options = {"model", "identity", "landmarks.model"};
  track.resumes_in_staging = true;
  track.arguments = [](const ShardPaths& p) {
    return with_config({"--capture", p.artifacts.at("capture").string(), "--rig", p.artifacts.at("rig").string(),
                        "--meshes", p.artifacts.at("meshes").string(), "--out", (p.output / "tracked").string()},
                       p);
  };
  track.split = by_frame_ranges;  // each range fitted afresh at its first frame (docs/tracking.md#in-frame-ranges)
  track.split_changes_outputs = true;
  kinds.push_back(track);
  // Alpha mattes of every performance image, in the captured image space;
  // resumes from the mattes an interrupted shard wrote.
  StageKind matte;
  matte.name = "matte";
  matte.summary = "mattes every image of the performance takes (tega matte)";
  matte.subcommand = {"matte"};
  matte.needs = {"capture", "rig", "tracked"};
  matte.provides = {{"mattes", "mattes"}};
  matte.options_section = "matte";
  matte.resumes_in_staging = true;
  matte.arguments = [](const ShardPaths& p) {
    return with_config({"--capture", p.artifacts.at("capture").string(), "--rig", p.artifacts.at("rig").string(),
                        "--tracked", p.artifacts.at("tracked").string(), "--out", (p.output / "mattes").string()},
                       p);
  };
  matte.split = by_takes;
  kinds.push_back(matte);
  // The trainer's dataset: sampled frames, undistorted and downsampled RGBA
  // images, matted by a matte stage upstream or, without one, here (the
  // sampled images alone); resumes from the images an interrupted shard wrote.
  StageKind dataset;
  dataset.name = "dataset";
  dataset.summary = "assembles the dataset from the capture, its tracked meshes and mattes (tega dataset build)";
  dataset.subcommand = {"dataset", "build"};
  dataset.needs = {"capture", "rig", "tracked"};
  dataset.optional_needs = {"mattes"};
  dataset.provides = {{"dataset", "dataset"}};
  dataset.options_section = "dataset";
  dataset.resumes_in_staging = true;
  dataset.arguments = [](const ShardPaths& p) {
    std::vector<std::string> arguments{"--capture", p.artifacts.at("capture").string(),
                                       "--rig",     p.artifacts.at("rig").string(),
                                       "--tracked", p.artifacts.at("tracked").string(),
                                       "--out",     (p.output / "dataset").string()};
    if (p.artifacts.count("mattes")) arguments.insert(arguments.end(), {"--mattes", p.artifacts.at("mattes").string()});
    return with_config(arguments, p);
  };
  kinds.push_back(dataset);
  return kinds;
}

}  // namespace

const std::vector<StageKind>& stage_kinds() {
  static const std::vector<StageKind> kinds = make_stage_kinds();
  return kinds;
}

const StageKind* find_stage_kind(std::string_view name) {
  for (const auto& kind : stage_kinds()) {
    if (kind.name == name) return &kind;
  }
  return nullptr;
}

}  // namespace tega::pipeline
