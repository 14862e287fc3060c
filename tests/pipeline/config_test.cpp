#include "tega/pipeline/config.h"

#include <gtest/gtest.h>

#include "tega/pipeline/fingerprint.h"
#include "tega/pipeline/stage_graph.h"
#include "test_support.h"

namespace tega::pipeline {
namespace {

PipelineConfig parse(const std::string& text) { return parse_pipeline_config(text, "/cfg/p.yaml", "/cfg"); }

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

bool all_commands(const std::vector<std::string>&) { return true; }

TEST(PipelineConfig, ReadsWorkspaceSubjectsAndStagesRelativeToTheConfig) {
  const auto c = parse(
      "workspace: ../ws\n"
      "subjects:\n  alice: {capture: caps/alice}\n  bob: {options: {synth: {seed: 2}}}\n"
      "stages:\n  synth: {options: {frames: 3}}\n  check: {kind: dataset_check, after: synth}\n");
  EXPECT_EQ(c.workspace, "/ws");
  ASSERT_EQ(c.subjects.size(), 2u);
  EXPECT_EQ(c.subjects[0].capture, "/cfg/caps/alice");
  ASSERT_EQ(c.stages.size(), 2u);
  EXPECT_EQ(c.stages[0].kind, "synth");
  EXPECT_EQ(c.stages[1].kind, "dataset_check");
  EXPECT_EQ(c.stages[1].after, std::vector<std::string>{"synth"});
  EXPECT_EQ(c.options_for(c.stages[0], c.subjects[0]), "frames: 3\n");
  EXPECT_EQ(c.options_for(c.stages[0], c.subjects[1]), "frames: 3\nseed: 2\n");
}

TEST(PipelineConfig, WithoutSubjectsHasOneDefaultSubject) {
  const auto c = parse("workspace: ws\nstages:\n  synth:\n");
  ASSERT_EQ(c.subjects.size(), 1u);
  EXPECT_EQ(c.subjects[0].name, "default");
}

TEST(PipelineConfig, NamesTheGpusOfALocalRunOrLeavesThemToTheMachine) {
  EXPECT_FALSE(parse("workspace: ws\nstages:\n  synth:\n").gpus);
  const auto c = parse("workspace: ws\ngpus: [0, 2, GPU-5e1f]\nstages:\n  synth:\n");
  ASSERT_TRUE(c.gpus);
  EXPECT_EQ(*c.gpus, (std::vector<std::string>{"0", "2", "GPU-5e1f"}));
  EXPECT_NE(error_of([] { parse("workspace: ws\ngpus: [1, 1]\nstages:\n  synth:\n"); }).find("listed twice"),
            std::string::npos);
  EXPECT_EQ(*parse("workspace: ws\ngpus: 1\nstages:\n  synth:\n").gpus, std::vector<std::string>{"1"});
  EXPECT_NE(error_of([] { parse("workspace: ws\ngpus: {first: 0}\nstages:\n  synth:\n"); }).find("gpus"),
            std::string::npos);
}

TEST(PipelineConfig, AStageMaySplitItsShardsIntoJobsOfSomeFrames) {
  const auto c = parse("workspace: ws\nstages:\n  mvs: {frames_per_job: 25}\n  matte:\n");
  EXPECT_EQ(c.stages[0].frames_per_job, 25);
  EXPECT_EQ(c.stages[1].frames_per_job, 0);
  EXPECT_NE(error_of([] { parse("workspace: ws\nstages:\n  mvs: {frames_per_job: -3}\n"); })
                .find("stages.mvs.frames_per_job must be a whole number of frames"),
            std::string::npos);
}

TEST(PipelineConfig, ATrainStageMayTakeSeveralGpusAJob) {
  const auto c = parse("workspace: ws\nstages:\n  train: {gpus_per_job: 4}\n  eval:\n");
  EXPECT_EQ(c.stages[0].gpus_per_job, 4);
  EXPECT_EQ(c.stages[1].gpus_per_job, 1);
  for (const char* bad : {"0", "-2", "two"})
    EXPECT_NE(error_of([&] { parse(std::string("workspace: ws\nstages:\n  train: {gpus_per_job: ") + bad + "}\n"); })
                  .find("stages.train.gpus_per_job must be a whole number of GPUs, at least 1"),
              std::string::npos)
        << bad;
}

TEST(PipelineConfig, AGpuStageMayShareEachGpuAmongSomeOfItsJobs) {
  const StageGraph graph(parse("workspace: ws\nstages:\n  synth: {kind: synth_raw}\n  calibrate: {after: synth}\n"
                               "  mvs: {after: calibrate, jobs_per_gpu: 3}\n"),
                         all_commands);
  EXPECT_EQ(graph.stages()[2].config->jobs_per_gpu, 3);
  EXPECT_EQ(graph.stages()[1].config->jobs_per_gpu, 1);
  EXPECT_NE(error_of([] { parse("workspace: ws\nstages:\n  mvs: {jobs_per_gpu: 0}\n"); })
                .find("stages.mvs.jobs_per_gpu must be a whole number of jobs, at least 1"),
            std::string::npos);
  EXPECT_NE(error_of([] {
              StageGraph(parse("workspace: ws\nstages:\n  synth: {kind: synth_raw}\n"
                               "  calibrate: {after: synth, jobs_per_gpu: 2}\n"),
                         all_commands);
            }).find("stage 'calibrate': jobs_per_gpu: a calibrate shard runs on the CPU"),
            std::string::npos);
  EXPECT_NE(error_of([] {
              StageGraph(parse("workspace: ws\nstages:\n  synth:\n  train: {after: synth, gpus_per_job: 2, "
                               "jobs_per_gpu: 2}\n"),
                         all_commands);
            }).find("jobs_per_gpu and gpus_per_job together"),
            std::string::npos);
}

// The key of each stage's shard: what its outputs depend on, and nothing else.
std::map<std::string, std::string> shard_keys(const std::string& stages) {
  const StageGraph graph(parse("workspace: ws\nstages:\n  synth: {kind: synth_raw}\n"
                               "  calibrate: {after: synth}\n  mvs: {after: calibrate}\n" +
                               stages),
                         all_commands);
  std::map<std::string, std::string> keys;
  for (size_t i = 0; i < graph.stages().size(); ++i)
    keys[graph.stages()[i].name()] =
        fingerprint_shard(graph, i, 0, "test", [](size_t, size_t) { return std::string("upstream"); }).key();
  return keys;
}

TEST(Fingerprint, HoldsTheSplitsAndGpusThatChangeOutputsAndNoOthers) {
  const auto plain = shard_keys("  track: {after: mvs}\n  dataset: {after: track}\n  train: {after: dataset}\n");
  const auto split = shard_keys("  track: {after: mvs, frames_per_job: 10}\n  dataset: {after: track}\n"
                                "  train: {after: dataset, gpus_per_job: 4}\n");
  EXPECT_NE(plain.at("track"), split.at("track")) << "each range's first frame is fitted afresh";
  EXPECT_NE(plain.at("train"), split.at("train")) << "four GPUs see four views a step";
  EXPECT_EQ(plain.at("dataset"), split.at("dataset"));  // the upstream hash stands for track's outputs here
  const auto meshes_in_jobs =
      shard_keys("  mvs2: {kind: mvs, after: calibrate, frames_per_job: 5, jobs_per_gpu: 3}\n");
  const auto meshes_whole = shard_keys("  mvs2: {kind: mvs, after: calibrate}\n");
  EXPECT_EQ(meshes_in_jobs.at("mvs2"), meshes_whole.at("mvs2")) << "split and GPU-sharing meshes are the same bytes";
}

TEST(PipelineConfig, OptionsAreCanonicalWhateverTheirOrderAndLayout) {
  const auto a = parse("workspace: ws\nstages:\n  synth:\n    options:\n      seed: 1\n      studio: {width: 64, cameras: 2}\n");
  const auto b = parse("workspace: ws\nstages:\n  synth: {options: {studio: {cameras: 2, width: 64}, seed: 1}}\n");
  EXPECT_EQ(a.stages[0].options_yaml, b.stages[0].options_yaml);
  const auto quoted = parse("workspace: ws\nstages:\n  synth: {options: {head: \"1\"}}\n");
  EXPECT_NE(quoted.stages[0].options_yaml, parse("workspace: ws\nstages:\n  synth: {options: {head: 1}}\n").stages[0].options_yaml);
}

TEST(PipelineConfig, OptionsFileIsTheBaseThatOptionsOverride) {
  test::TempDir dir;
  test::write_text(dir / "rig.yaml", "frames: 30\nstudio: {cameras: 13, width: 512}\n");
  test::write_text(dir / "p.yaml",
                   "workspace: ws\nstages:\n  synth: {options_file: rig.yaml, options: {studio: {cameras: 6}}}\n");
  const auto c = load_pipeline_config(dir / "p.yaml");
  EXPECT_EQ(c.stages[0].options_yaml, "frames: 30\nstudio:\n  cameras: 6\n  width: 512\n");
  EXPECT_EQ(scalar_option(c.stages[0].options_yaml, "studio.cameras"), "6");
  EXPECT_EQ(scalar_option(c.stages[0].options_yaml, "studio.height"), std::nullopt);
}

TEST(PipelineConfig, AStageMayReadItsOptionsFromASectionOfTheConfigItself) {
  test::TempDir dir;
  const std::string stages = "stages:\n  ingest: {kind: ingest_multiface, options_file: p.yaml, options: {frames: 9}}\n";
  test::write_text(dir / "p.yaml", "ingest:\n  frames: 400\n  downsample: 2\nworkspace: ws\n" + stages);
  const auto c = load_pipeline_config(dir / "p.yaml");
  EXPECT_EQ(c.stages[0].options_yaml, "downsample: 2\nframes: 9\n");
  // The command reads the `ingest` section of the file it is given.
  EXPECT_EQ(options_file_text(c.stages[0].options_yaml, "ingest"), "ingest:\n  downsample: 2\n  frames: 9\n");

  // Without a stage reading it, the section is an unknown key like any other.
  test::write_text(dir / "q.yaml", "ingest:\n  frames: 400\nworkspace: ws\nstages: {synth: }\n");
  EXPECT_NE(error_of([&] { load_pipeline_config(dir / "q.yaml"); }).find("unknown key 'ingest' (line 1)"),
            std::string::npos);
}

TEST(PipelineConfig, OptionsBecomeFlagsForCommandsWithoutAConfigFile) {
  EXPECT_EQ(option_flags("device: cpu\nno_video: true\nno_side_by_side: false\nframes: [a, b]\nformat: \"true\"\n"),
            (std::vector<std::string>{"--device", "cpu", "--no-video", "--frames", "a", "--frames", "b", "--format",
                                      "true"}));
  EXPECT_NE(error_of([] { option_flags("orbit: {n: 3}\n"); }).find("option 'orbit' is a mapping"), std::string::npos);
  EXPECT_NE(error_of([] {
              StageGraph(parse("workspace: ws\nstages: {synth: , train: {after: synth}, "
                               "render: {after: train, options: {widht: 64}}}\n"),
                         all_commands);
            }).find("stage 'render' (kind render): unknown option 'widht'; known options: cameras, orbit"),
            std::string::npos);
}

TEST(PipelineConfig, UnknownKeysAreErrorsNamingTheFileAndTheKnownKeys) {
  EXPECT_EQ(error_of([] { parse("workspace: ws\nstage: {}\n"); }),
            "/cfg/p.yaml: unknown key 'stage' (line 2); known keys: description, workspace, subjects, stages, gpus");
  EXPECT_EQ(error_of([] { parse("workspace: ws\nstages:\n  synth: {option: {}}\n"); }),
            "/cfg/p.yaml: unknown key 'stages.synth.option' (line 3); known keys of 'stages.synth': kind, after, "
            "options, options_file, frames_per_job, gpus_per_job, jobs_per_gpu");
  EXPECT_NE(error_of([] { parse("workspace: ws\nsubjects: {a: {options: {trian: {}}}}\nstages: {train: }\n"); })
                .find("'subjects.a.options.trian' names no stage"),
            std::string::npos);
  EXPECT_NE(error_of([] { parse("stages: {synth: }\n"); }).find("/cfg/p.yaml: needs 'workspace'"), std::string::npos);
  EXPECT_NE(error_of([] { parse("workspace: ws\nsubjects: {../x: {}}\nstages: {synth: }\n"); }).find("subject name '../x'"),
            std::string::npos);
}

TEST(StageGraph, OrdersStagesDependenciesFirstAndFindsArtifacts) {
  const StageGraph g(parse("workspace: ws\nstages:\n"
                           "  eval: {after: train}\n  train: {after: synth}\n  synth:\n"),
                     all_commands);
  ASSERT_EQ(g.stages().size(), 3u);
  EXPECT_EQ(g.stages()[0].name(), "synth");
  EXPECT_EQ(g.stages()[1].name(), "train");
  EXPECT_EQ(g.stages()[2].name(), "eval");
  // eval needs the run (from train) and the dataset, which comes from synth through train.
  EXPECT_EQ(g.stages()[2].artifact_source.at("run"), 1u);
  EXPECT_EQ(g.stages()[2].artifact_source.at("dataset"), 0u);
  EXPECT_EQ(g.stages()[2].inputs, (std::vector<size_t>{0, 1}));
  EXPECT_EQ(g.downstream_of(1), (std::vector<bool>{false, true, true}));
  EXPECT_EQ(g.upstream_of({false, true, false}), (std::vector<bool>{true, true, false}));
}

TEST(StageGraph, TheDatasetTakesMattesOnlyWhereAMatteStageIsUpstream) {
  const std::string chain = "workspace: ws\nstages:\n  capture:\n  calibrate: {after: capture}\n"
                            "  mvs: {after: calibrate}\n  track: {after: mvs}\n";
  const StageGraph without(parse(chain + "  dataset: {after: track}\n"), all_commands);
  const Stage& dataset = without.stages().back();
  ASSERT_EQ(dataset.name(), "dataset");
  EXPECT_FALSE(dataset.artifact_source.count("mattes"));
  EXPECT_EQ(dataset.artifact_source.at("tracked"), 3u);

  const StageGraph with(parse(chain + "  matte: {after: track}\n  dataset: {after: matte}\n"), all_commands);
  ASSERT_EQ(with.stages().back().name(), "dataset");
  EXPECT_EQ(with.stages().back().artifact_source.at("mattes"), 4u);
}

TEST(StageGraph, RejectsUnknownKindsCyclesAndMissingArtifacts) {
  EXPECT_NE(error_of([] { StageGraph(parse("workspace: ws\nstages: {x: {kind: sinth}}\n"), all_commands); })
                .find("stage 'x': unknown kind 'sinth'; known kinds: synth, synth_raw, ingest_multiface, dataset_check"),
            std::string::npos);
  EXPECT_NE(error_of([] {
              StageGraph(parse("workspace: ws\nstages: {a: {kind: synth, after: b}, b: {kind: synth, after: a}}\n"),
                         all_commands);
            }).find("form a cycle: a -> b -> a"),
            std::string::npos);
  EXPECT_NE(error_of([] { StageGraph(parse("workspace: ws\nstages: {train: }\n"), all_commands); })
                .find("stage 'train' (kind train) needs a dataset"),
            std::string::npos);
  EXPECT_NE(error_of([] { StageGraph(parse("workspace: ws\nstages: {synth: , check: {kind: dataset_check, after: synth, "
                                           "options: {x: 1}}}\n"),
                                     all_commands); })
                .find("stage 'check' (kind dataset_check) takes no options"),
            std::string::npos);
}

TEST(StageGraph, StagesWithoutACommandAreUnavailableWithTheReason) {
  const StageGraph g(parse("workspace: ws\nstages:\n  capture:\n  calibrate: {after: capture}\n"
                           "  mvs: {after: calibrate}\n  track: {after: mvs}\n  matte: {after: track}\n"
                           "  dataset: {after: matte}\n  synth:\n"
                           "  train: {after: synth}\n"
                           "  eval: {after: [train]}\n"),
                     [](const std::vector<std::string>& command) { return command[0] != "eval" && command[0] != "matte"; });
  for (const auto& stage : g.stages()) {
    if (stage.name() == "eval" || stage.name() == "matte") {
      EXPECT_FALSE(stage.available);
      EXPECT_EQ(stage.unavailable_reason, "`tega " + stage.name() + "` is not available in this build");
    } else {
      EXPECT_TRUE(stage.available) << stage.name();
    }
  }
}

}  // namespace
}  // namespace tega::pipeline
