// `tega run CONFIG`: runs a pipeline config's stage graph (docs/pipeline.md).

#include <signal.h>

#include <atomic>
#include <iostream>
#include <memory>
#include <optional>

#include "available_commands.h"
#include "commands.h"
#include "tega/core/error.h"
#include "tega/core/log.h"
#include "tega/core/thread_pool.h"
#include "tega/pipeline/gpus.h"
#include "tega/pipeline/local_executor.h"
#include "tega/pipeline/orchestrator.h"
#include "tega/pipeline/slurm_executor.h"

namespace tega::cli {
namespace {

namespace fs = std::filesystem;

std::atomic<bool> stop_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free, "set from a signal handler");

void request_stop(int) { stop_requested = true; }

// SIGINT and SIGTERM ask the run to stop: no new shards, running ones are
// terminated, and the next run picks up from the committed shards.
class StopOnSignals {
 public:
  StopOnSignals() {
    struct sigaction action {};
    action.sa_handler = request_stop;
    sigemptyset(&action.sa_mask);
    ::sigaction(SIGINT, &action, &previous_int_);
    ::sigaction(SIGTERM, &action, &previous_term_);
  }
  ~StopOnSignals() {
    ::sigaction(SIGINT, &previous_int_, nullptr);
    ::sigaction(SIGTERM, &previous_term_, nullptr);
  }

 private:
  struct sigaction previous_int_ {}, previous_term_ {};
};

struct RunArguments {
  std::string config, workspace;
  std::vector<std::string> only, from, force;
  int jobs = 0;
  std::optional<std::string> gpus;
  std::string executor = "local";
  pipeline::SlurmOptions slurm;
};

// --gpus, else the config's `gpus`, else every GPU of the machine.
std::vector<std::string> local_gpus(const RunArguments& args, const pipeline::PipelineConfig& config) {
  if (args.gpus) return pipeline::parse_gpu_list(*args.gpus, "--gpus");
  if (config.gpus) return *config.gpus;
  return pipeline::machine_gpus();
}

std::unique_ptr<pipeline::Executor> make_executor(const RunArguments& args, const CLI::App& cmd,
                                                  const pipeline::PipelineConfig& config) {
  if (args.executor == "slurm") {
    for (const char* local_only : {"--jobs", "--gpus"}) {
      if (cmd.count(local_only) > 0)
        throw Error(std::string(local_only) + " applies to --executor local only (Slurm decides where jobs run)");
    }
    return std::make_unique<pipeline::SlurmExecutor>(args.slurm);
  }
  for (const char* slurm_only : {"--partition", "--gpus-per-job", "--max-requeues"}) {
    if (cmd.count(slurm_only) > 0) throw Error(std::string(slurm_only) + " applies to --executor slurm only");
  }
  const int jobs = args.jobs > 0 ? args.jobs : default_thread_count();
  std::vector<std::string> gpus = local_gpus(args, config);
  if (!gpus.empty()) {
    std::string listed;
    for (const auto& gpu : gpus) listed += (listed.empty() ? "" : ", ") + gpu;
    logging::info("tega run: GPU shards spread over GPU %s", listed.c_str());
  }
  return std::make_unique<pipeline::LocalExecutor>(jobs, std::move(gpus));
}

void run(const RunArguments& args, const CLI::App& cmd, const CLI::App& root) {
  pipeline::PipelineConfig config = pipeline::load_pipeline_config(args.config);
  if (!args.workspace.empty()) config.workspace = fs::absolute(args.workspace).lexically_normal();
  const std::unique_ptr<pipeline::Executor> executor = make_executor(args, cmd, config);
  const pipeline::StageGraph graph(std::move(config),
                                   [&](const std::vector<std::string>& path) { return has_subcommand(root, path); });

  pipeline::RunRequest request;
  request.only = args.only;
  request.from = args.from;
  request.force = args.force;
  request.tega_executable = fs::read_symlink("/proc/self/exe");
  request.tool_version = std::string("tega ") + TEGA_VERSION;

  const StopOnSignals stop_on_signals;
  const pipeline::RunSummary summary = pipeline::run_pipeline(graph, request, *executor, stop_requested);

  for (const auto& problem : summary.problems) std::cerr << "tega run: " << problem << "\n";
  std::cout << "tega run: " << summary.ran << " shard(s) ran, " << summary.up_to_date << " up to date, "
            << summary.failed << " failed, " << summary.blocked << " blocked, " << summary.unavailable
            << " unavailable; workspace " << graph.config().workspace.string() << "\n";
  if (summary.interrupted) std::cerr << "tega run: interrupted; run it again to continue from the committed shards\n";
  if (summary.exit_code() != 0) throw CLI::RuntimeError(summary.exit_code());
}

}  // namespace

void add_run_command(CLI::App& app) {
  auto args = std::make_shared<RunArguments>();
  auto* cmd = app.add_subcommand(
      "run", "Run a pipeline config's stages (docs/pipeline.md): shards whose manifest matches are skipped, so an "
             "interrupted or failed run continues where it stopped.");
  cmd->add_option("config", args->config, "Pipeline config (YAML), e.g. studio_configs/demo.yaml.")->required();
  cmd->add_option("--only", args->only, "Run just this stage (repeatable); the stages it needs must be done.");
  cmd->add_option("--from", args->from, "Re-run this stage and every stage downstream of it (repeatable).");
  cmd->add_option("--force", args->force, "Re-run this stage even where it is done (repeatable).");
  cmd->add_option("--jobs", args->jobs, "CPU shards run in parallel (default: one per hardware thread); "
                                        "GPU shards run one at a time per GPU.");
  cmd->add_option("--gpus", args->gpus,
                  "GPUs the GPU shards (a stage's device: cuda) spread over, each shard pinned to one with "
                  "CUDA_VISIBLE_DEVICES: indices or UUIDs, e.g. 0,1,3 (default: the config's `gpus`, else every GPU "
                  "of the machine; docs/pipeline.md#several-gpus).");
  cmd->add_option("--workspace", args->workspace, "Use this workspace instead of the config's.");
  cmd->add_option("--executor", args->executor,
                  "Where shards run: local (child processes) or slurm (a batch job each; the workspace must be on "
                  "storage the compute nodes share; docs/pipeline.md#running-on-a-slurm-cluster).")
      ->check(CLI::IsMember({"local", "slurm"}))
      ->default_str("local");
  cmd->add_option("--partition", args->slurm.partition, "Slurm partition for the jobs (default: the cluster's).");
  cmd->add_option("--gpus-per-job", args->slurm.gpus_per_job,
                  "GPUs a Slurm job of a GPU stage asks for (--gres=gpu:N; a train stage's gpus_per_job when larger).")
      ->capture_default_str();
  cmd->add_option("--max-requeues", args->slurm.max_requeues,
                  "How often a Slurm job lost to the cluster (node failure, preemption, killed) is submitted again.")
      ->capture_default_str();
  const CLI::App* root = &app;
  cmd->callback([args, cmd, root] { run(*args, *cmd, *root); });
}

}  // namespace tega::cli
