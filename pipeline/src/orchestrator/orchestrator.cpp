#include "tega/pipeline/orchestrator.h"

#include <spdlog/spdlog.h>

#include <nlohmann/json.hpp>
#include <algorithm>
#include <map>
#include <vector>
#include <optional>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/progress.h"
#include "tega/pipeline/log_tail.h"
#include "tega/pipeline/manifest.h"
#include "tega/pipeline/workspace.h"

namespace tega::pipeline {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

enum class Phase { waiting, queued, done, failed, blocked, unavailable };

struct ShardRun {
  size_t stage = 0, subject = 0;
  std::string id;  // "<stage>/<subject>"
  Phase phase = Phase::waiting;
  Fingerprint fingerprint;
  std::vector<std::string> command;
  std::string started;
  std::string output_hash;  // once done
  // Its jobs: one, or one per part of a split shard (StageKind::split), in order.
  std::vector<Job> jobs;
  size_t jobs_running = 0;
  Clock::time_point launched;
  double seconds = 0;        // its job's; a split shard's from its launch to its last job's end
  long peak_rss_kib = 0;     // its largest job's
  std::string job_failure;   // the first failed job's error, reported when the last has finished
};

class Run {
 public:
  Run(const StageGraph& graph, const RunRequest& request, Executor& executor)
      : graph_(graph), config_(graph.config()), request_(request), executor_(executor), ws_(config_.workspace) {
    select_stages();
    const size_t subjects = config_.subjects.size();
    for (size_t s = 0; s < graph_.stages().size(); ++s) {
      for (size_t j = 0; j < subjects; ++j) {
        ShardRun shard;
        shard.stage = s;
        shard.subject = j;
        shard.id = graph_.stages()[s].name() + "/" + config_.subjects[j].name;
        shards_.push_back(std::move(shard));
        if (selected_[s]) ++to_settle_;
      }
    }
  }

  RunSummary execute(const std::atomic<bool>& stop_requested) {
    std::vector<std::string> stage_names;
    for (const auto& stage : graph_.stages()) stage_names.push_back(stage.name());
    ws_.remove_leftovers(stage_names);
    record_config();
    spdlog::info("tega run: {} stages x {} subjects, workspace {}", graph_.stages().size(), config_.subjects.size(),
                 ws_.root().string());

    auto last_heartbeat = Clock::now();
    while (!stop_requested) {
      const bool progressed = schedule_ready_shards();
      if (executor_.unfinished() == 0 && !progressed) break;
      for (const JobResult& result : executor_.wait(std::chrono::milliseconds(200))) finish(result);
      if (Clock::now() - last_heartbeat >= request_.heartbeat) {
        report_running();
        last_heartbeat = Clock::now();
      }
    }
    if (stop_requested) stop();
    return summary_;
  }

 private:
  void select_stages() {
    const size_t n = graph_.stages().size();
    selected_.assign(n, request_.only.empty() && request_.from.empty());
    forced_.assign(n, false);
    for (const auto& name : request_.only) selected_[graph_.index_of(name)] = true;
    for (const auto& name : request_.from) {
      const auto downstream = graph_.downstream_of(graph_.index_of(name));
      for (size_t i = 0; i < n; ++i) {
        selected_[i] = selected_[i] || downstream[i];
        forced_[i] = forced_[i] || downstream[i];
      }
    }
    for (const auto& name : request_.force) forced_[graph_.index_of(name)] = true;
    evaluated_ = graph_.upstream_of(selected_);
  }

  void record_config() const {
    const nlohmann::json record = {{"config", fs::absolute(config_.source).string()},
                                   {"base_dir", config_.base_dir.string()},
                                   {"text", config_.text},
                                   {"tool_version", request_.tool_version}};
    write_text_atomic(ws_.config_record(), record.dump(2) + "\n");
  }

  ShardRun& shard(size_t stage, size_t subject) { return shards_[stage * config_.subjects.size() + subject]; }
  const Stage& stage_of(const ShardRun& s) const { return graph_.stages()[s.stage]; }
  const std::string& subject_of(const ShardRun& s) const { return config_.subjects[s.subject].name; }

  // Decides every waiting shard whose inputs are settled; true if any was.
  bool schedule_ready_shards() {
    bool progressed = false;
    for (ShardRun& s : shards_) {
      if (s.phase != Phase::waiting || !evaluated_[s.stage]) continue;
      const Stage& stage = stage_of(s);
      if (!stage.available) {
        settle(s, Phase::unavailable, stage.unavailable_reason);
        progressed = true;
        continue;
      }
      std::optional<std::string> blocker;
      bool ready = true;
      for (size_t in : stage.inputs) {
        const ShardRun& input = shard(in, s.subject);
        if (input.phase == Phase::waiting || input.phase == Phase::queued) ready = false;
        if (input.phase == Phase::failed) blocker = "needs " + input.id + ", which failed";
        if (input.phase == Phase::blocked) blocker = "needs " + input.id + ", which is blocked";
        if (input.phase == Phase::unavailable) blocker = "needs " + input.id + ", which is unavailable";
      }
      if (!ready) continue;
      progressed = true;
      if (blocker) {
        settle(s, Phase::blocked, *blocker);
      } else {
        decide(s);
      }
    }
    return progressed;
  }

  void decide(ShardRun& s) {
    const Stage& stage = stage_of(s);
    const std::string& subject = subject_of(s);
    try {
      s.fingerprint = fingerprint_shard(graph_, s.stage, s.subject, request_.tool_version,
                                        [&](size_t in, size_t j) { return shard(in, j).output_hash; });
    } catch (const Error& e) {
      fail(s, e.what());
      return;
    }
    std::optional<Manifest> manifest;
    try {
      manifest = read_manifest(ws_.manifest_file(stage.name(), subject));
    } catch (const Error& e) {
      spdlog::warn("{}: {}; re-running it", s.id, e.what());
    }
    const bool current = manifest && manifest->key == s.fingerprint.key() &&
                         damaged_output(ws_.shard_dir(stage.name(), subject), *manifest).empty();
    if (current && !forced_[s.stage]) {
      s.output_hash = manifest->output_hash;
      fs::remove(ws_.state_file(stage.name(), subject));  // outdated by the committed shard
      ++summary_.up_to_date;
      settle(s, Phase::done, "");
      return;
    }
    if (!selected_[s.stage]) {
      settle(s, Phase::blocked,
             "is not up to date and its stage is not selected: run it first (drop --only/--from)");
      return;
    }
    try {
      launch(s);
    } catch (const std::exception& e) {
      fail(s, std::string("could not be started: ") + e.what());
    }
  }

  void launch(ShardRun& s) {
    const Stage& stage = stage_of(s);
    const SubjectConfig& subject = config_.subjects[s.subject];
    const fs::path staging = ws_.staging_dir(stage.name(), subject.name);
    const fs::path resume_key = staging / kResumeKeyFile;
    const std::string key = s.fingerprint.key();
    if (!(stage.kind->resumes_in_staging && fs::exists(resume_key) && read_text_file(resume_key) == key))
      remove_tree(staging);
    fs::create_directories(staging);
    if (stage.kind->resumes_in_staging) write_text_atomic(resume_key, key);

    ShardPaths paths;
    paths.output = staging;
    paths.capture = subject.capture;
    if (stage.kind->options_as == OptionsAs::config_file) {
      paths.options_file = staging / "options.yaml";
      write_text_atomic(paths.options_file, options_file_text(s.fingerprint.options_yaml, stage.kind->options_section));
    } else if (stage.kind->options_as == OptionsAs::flags) {
      paths.option_flags = option_flags(s.fingerprint.options_yaml);
    }
    for (const auto& [artifact, source] : stage.artifact_source) {
      paths.artifacts[artifact] =
          ws_.shard_dir(graph_.stages()[source].name(), subject.name) / graph_.stages()[source].kind->provides.at(artifact);
    }

    Job job;
    job.id = s.id;
    job.argv = {request_.tega_executable.string()};
    job.argv.insert(job.argv.end(), stage.kind->subcommand.begin(), stage.kind->subcommand.end());
    const auto arguments = stage.kind->arguments(paths);
    job.argv.insert(job.argv.end(), arguments.begin(), arguments.end());
    job.working_directory = config_.base_dir;
    job.log_file = ws_.log_file(stage.name(), subject.name);
    std::optional<std::string> device;
    if (!stage.kind->device_option.empty()) {
      device = scalar_option(s.fingerprint.options_yaml, stage.kind->device_option);
      if (device && device->rfind("cuda", 0) == 0) job.resources.gpu_device = *device;
      job.resources.jobs_per_gpu = stage.config->jobs_per_gpu;
    }
    if (const int gpus = stage.config->gpus_per_job; gpus > 1) {
      if (job.resources.gpu_device != "cuda")
        throw Error("gpus_per_job: " + std::to_string(gpus) + " needs the option " + stage.kind->device_option +
                    ": cuda (it is " + (device ? *device : "unset") + "), so that tega run chooses the GPUs");
      job.resources.gpu_count = gpus;
      std::string visible = "0";  // the job sees its GPUs as its devices 0 to N-1
      for (int g = 1; g < gpus; ++g) visible.append(",").append(std::to_string(g));
      job.argv.insert(job.argv.end(), {stage.kind->gpus_flag, visible});
    }
    s.command = job.argv;

    std::vector<std::vector<std::string>> parts;
    if (stage.config->frames_per_job > 0) parts = stage.kind->split(paths, stage.config->frames_per_job);
    s.jobs.clear();
    if (parts.size() > 1) {
      // Each part its own job id and log ("mvs/alice#2", logs/mvs/alice#2.log): '#' is in no
      // subject's name.
      for (size_t k = 0; k < parts.size(); ++k) {
        Job part = job;
        part.id = s.id + "#" + std::to_string(k + 1);
        part.argv.insert(part.argv.end(), parts[k].begin(), parts[k].end());
        part.log_file = ws_.log_file(stage.name(), subject.name + "#" + std::to_string(k + 1));
        s.jobs.push_back(std::move(part));
      }
    } else {
      s.jobs.push_back(std::move(job));
    }

    s.started = utc_now();
    s.launched = Clock::now();
    s.seconds = 0;
    s.peak_rss_kib = 0;
    s.job_failure.clear();
    s.jobs_running = s.jobs.size();
    const Job& first = s.jobs.front();
    write_shard_state(ws_.state_file(stage.name(), subject.name), {"running", "", first.log_file.string(), s.started, ""});
    spdlog::info("{} started{}{} (log: {})", s.id,
                 s.jobs.size() > 1 ? " as " + std::to_string(s.jobs.size()) + " jobs" : "",
                 first.resources.gpu_device.empty()   ? ""
                 : first.resources.gpu_count > 1      ? " on " + std::to_string(first.resources.gpu_count) + " GPUs"
                                                      : " on " + first.resources.gpu_device,
                 s.jobs.size() > 1 ? ws_.log_file(stage.name(), subject.name + "#*").string() : first.log_file.string());
    s.phase = Phase::queued;
    for (const Job& part : s.jobs) {
      job_shard_[part.id] = static_cast<size_t>(&s - shards_.data());
      executor_.submit(part);
    }
  }

  void finish(const JobResult& result) {
    const auto found = job_shard_.find(result.id);
    if (found == job_shard_.end()) return;
    ShardRun& s = shards_[found->second];
    const auto job = std::find_if(s.jobs.begin(), s.jobs.end(), [&](const Job& j) { return j.id == result.id; });
    if (job == s.jobs.end()) return;
    const fs::path log = job->log_file;
    if (result.requeue) {
      spdlog::warn("{}: {}", result.id, result.failure);
      try {
        if (s.jobs.size() > 1) {
          executor_.submit(*job);  // the other parts' files stay in the staging directory
        } else {
          launch(s);
        }
      } catch (const std::exception& e) {
        fail(s, std::string("could not be started again: ") + e.what());
      }
      return;
    }
    --s.jobs_running;
    s.seconds = s.jobs.size() > 1 ? std::chrono::duration<double>(Clock::now() - s.launched).count() : result.seconds;
    s.peak_rss_kib = std::max(s.peak_rss_kib, result.peak_rss_kib);
    if (!result.succeeded && s.job_failure.empty()) {
      s.job_failure = (s.jobs.size() > 1 ? result.id + ": " : "") + result.failure + ": " + last_error_line(log) +
                      " (log: " + log.string() + ")";
    }
    if (s.jobs_running > 0) {
      if (!result.succeeded) spdlog::error("{} failed; the shard fails when its other jobs end", result.id);
      return;
    }
    if (!s.job_failure.empty()) {
      fail(s, s.job_failure);
      return;
    }
    try {
      commit(s, s.seconds);
    } catch (const std::exception& e) {
      fail(s, std::string("could not be committed: ") + e.what());
      return;
    }
    ++summary_.ran;
    settle(s, Phase::done, "");
    spdlog::info("{} done in {}  [{}]", s.id, Progress::format_duration(s.seconds), progress_line(s.stage));
  }

  void commit(ShardRun& s, double seconds) {
    const Stage& stage = stage_of(s);
    const std::string& subject = subject_of(s);
    const fs::path staging = ws_.staging_dir(stage.name(), subject);
    for (const auto& [artifact, path] : stage.kind->provides) {
      if (!fs::exists(staging / path)) throw Error(staging / path, "was not produced by the shard's command");
    }
    Manifest m;
    m.stage = stage.name();
    m.shard = subject;
    m.kind = stage.kind->name;
    m.fingerprint = s.fingerprint;
    m.key = s.fingerprint.key();
    m.command = s.command;
    m.log = s.jobs.front().log_file.string();  // a split shard's first part's
    m.started = s.started;
    m.finished = utc_now();
    m.seconds = seconds;
    m.peak_rss_mib = s.peak_rss_kib / 1024.0;
    m.outputs = hash_outputs(staging);
    m.output_hash = outputs_hash(m.outputs);
    write_manifest(staging / kManifestFile, m);
    // The resume key goes last: killed before the rename, the next run keeps
    // the staged outputs (a whole training run) rather than starting over.
    ws_.commit(stage.name(), subject);
    fs::remove(ws_.shard_dir(stage.name(), subject) / kResumeKeyFile);
    fs::remove(ws_.state_file(stage.name(), subject));
    s.output_hash = m.output_hash;
  }

  void fail(ShardRun& s, const std::string& error) {
    const Stage& stage = stage_of(s);
    const std::string& subject = subject_of(s);
    const fs::path log = s.jobs.empty() ? ws_.log_file(stage.name(), subject) : s.jobs.front().log_file;
    write_shard_state(ws_.state_file(stage.name(), subject), {"failed", error, log.string(), s.started, utc_now()});
    ++summary_.failed;
    summary_.problems.push_back(s.id + " failed: " + error);
    settle(s, Phase::failed, error);
    spdlog::error("{} failed: {}  [{}]", s.id, error, progress_line(s.stage));
  }

  void settle(ShardRun& s, Phase phase, const std::string& reason) {
    s.phase = phase;
    if (selected_[s.stage]) ++settled_;
    if (phase == Phase::blocked) {
      ++summary_.blocked;
      summary_.problems.push_back(s.id + " blocked: " + reason);
    } else if (phase == Phase::unavailable) {
      ++summary_.unavailable;
      summary_.problems.push_back(s.id + " unavailable: " + reason);
    }
  }

  // "synth 1/2, all 3/8, ETA 0:42"
  std::string progress_line(size_t stage) const {
    int stage_settled = 0, stage_total = 0;
    for (const ShardRun& s : shards_) {
      if (s.stage != stage) continue;
      ++stage_total;
      stage_settled += (s.phase != Phase::waiting && s.phase != Phase::queued) ? 1 : 0;
    }
    std::string line = graph_.stages()[stage].name() + " " + std::to_string(stage_settled) + "/" +
                       std::to_string(stage_total) + ", all " + std::to_string(settled_) + "/" + std::to_string(to_settle_);
    const double elapsed = std::chrono::duration<double>(Clock::now() - started_).count();
    const int remaining = to_settle_ - settled_;
    if (summary_.ran > 0 && remaining > 0) {
      line += ", ETA " + Progress::format_duration(elapsed / summary_.ran * remaining);
    }
    return line;
  }

  void report_running() const {
    for (const auto& id : executor_.running()) {
      const auto slash = id.find('/');
      const fs::path log = ws_.log_file(id.substr(0, slash), id.substr(slash + 1));
      spdlog::info("{} running: {}", id, last_line(log));
    }
  }

  void stop() {
    spdlog::warn("tega run: stopping: cancelling {} unfinished shard(s)", executor_.unfinished());
    executor_.cancel_all();
    for (ShardRun& s : shards_) {
      if (s.phase != Phase::queued) continue;
      const Stage& stage = stage_of(s);
      const std::string& subject = subject_of(s);
      write_shard_state(ws_.state_file(stage.name(), subject),
                        {"interrupted", "stopped by a signal before it finished",
                         ws_.log_file(stage.name(), subject).string(), s.started, utc_now()});
    }
    summary_.interrupted = true;
  }

  const StageGraph& graph_;
  const PipelineConfig& config_;
  const RunRequest& request_;
  Executor& executor_;
  Workspace ws_;
  std::vector<bool> selected_, forced_, evaluated_;
  std::vector<ShardRun> shards_;
  std::map<std::string, size_t> job_shard_;  // job id -> its shard's index in shards_
  int settled_ = 0, to_settle_ = 0;
  Clock::time_point started_ = Clock::now();
  RunSummary summary_;
};

}  // namespace

RunSummary run_pipeline(const StageGraph& graph, const RunRequest& request, Executor& executor,
                        const std::atomic<bool>& stop_requested) {
  const WorkspaceLock lock(graph.config().workspace);
  Run run(graph, request, executor);
  return run.execute(stop_requested);
}

PipelineConfig recorded_config(const fs::path& root) {
  const Workspace ws(root);
  const fs::path file = ws.config_record();
  if (!fs::exists(file)) throw Error(root, "is not a tega workspace (it has no pipeline.json; `tega run` writes one)");
  try {
    const auto record = nlohmann::json::parse(read_text_file(file));
    PipelineConfig config = parse_pipeline_config(record.at("text"), record.at("config").get<std::string>(),
                                                  record.at("base_dir").get<std::string>());
    config.workspace = fs::absolute(root).lexically_normal();
    return config;
  } catch (const nlohmann::json::exception& e) {
    throw Error(file, std::string("is not a valid workspace record: ") + e.what());
  }
}

}  // namespace tega::pipeline
