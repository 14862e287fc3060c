#include "workspace_outputs.h"

#include <algorithm>

#include "tega/core/error.h"
#include "tega/pipeline/manifest.h"
#include "tega/pipeline/orchestrator.h"
#include "tega/pipeline/status.h"
#include "tega/pipeline/workspace.h"

namespace tega::report {
namespace fs = std::filesystem;

const StageOutput* SubjectOutputs::first_of_kind(const std::string& kind) const {
  for (const auto& stage : stages)
    if (stage.kind == kind) return &stage;
  return nullptr;
}

bool SubjectOutputs::virtual_studio() const {
  std::error_code ignored;
  return !truth.empty() && fs::is_directory(truth / "ground_truth", ignored);
}

std::vector<SubjectOutputs> workspace_outputs(const fs::path& workspace, const std::vector<std::string>& subjects,
                                              const std::string& tool_version) {
  pipeline::PipelineConfig config = pipeline::recorded_config(workspace);
  for (const auto& name : subjects) {
    const bool known = std::any_of(config.subjects.begin(), config.subjects.end(),
                                   [&](const pipeline::SubjectConfig& s) { return s.name == name; });
    if (!known) throw Error(workspace / "pipeline.json", "its config has no subject '" + name + "'");
  }
  // Whether this binary could run a stage does not change what its shards hold.
  const pipeline::StageGraph graph(std::move(config), [](const std::vector<std::string>&) { return true; });
  const pipeline::WorkspaceStatus status = pipeline::workspace_status(graph, tool_version);
  const pipeline::Workspace ws(graph.config().workspace);

  std::vector<SubjectOutputs> out;
  for (size_t j = 0; j < graph.config().subjects.size(); ++j) {
    const pipeline::SubjectConfig& subject = graph.config().subjects[j];
    if (!subjects.empty() && std::find(subjects.begin(), subjects.end(), subject.name) == subjects.end()) continue;
    SubjectOutputs outputs{subject.name, {}, subject.capture};
    for (size_t s = 0; s < graph.stages().size(); ++s) {
      const pipeline::Stage& stage = graph.stages()[s];
      const pipeline::ShardStatus& shard = status.stages[s].shards[j];
      StageOutput o{stage.name(), stage.kind->name, shard.state, shard.reason, false, {}};
      const fs::path dir = ws.shard_dir(stage.name(), subject.name);
      std::error_code ignored;
      o.committed = fs::exists(ws.manifest_file(stage.name(), subject.name), ignored);
      if (o.committed)
        for (const auto& [artifact, path] : stage.kind->provides) o.artifacts[artifact] = dir / path;
      if (const auto capture = o.artifacts.find("capture");
          capture != o.artifacts.end() && outputs.capture == subject.capture)
        outputs.capture = capture->second;
      if (const auto truth = o.artifacts.find("truth"); truth != o.artifacts.end()) outputs.truth = truth->second;
      outputs.stages.push_back(std::move(o));
    }
    if (outputs.truth.empty()) outputs.truth = outputs.capture;
    out.push_back(std::move(outputs));
  }
  return out;
}

}  // namespace tega::report
