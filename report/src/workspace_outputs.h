#pragma once
// What a workspace holds for one subject: every stage of the config of its
// latest run, in graph order, with the state `tega status` gives it and the
// paths of the artifacts its committed shard provides.

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace tega::report {

struct StageOutput {
  std::string stage, kind;
  std::string state;       // done, stale, pending, failed, ... (docs/pipeline.md#status)
  std::string reason;      // why it is not done
  bool committed = false;  // a committed shard exists (done or stale): its artifacts can be read
  std::map<std::string, std::filesystem::path> artifacts;  // artifact name -> path in the committed shard
};

struct SubjectOutputs {
  std::string subject;
  std::vector<StageOutput> stages;  // dependencies first
  // The subject's capture: a committed stage's `capture` artifact, else the
  // subject's configured capture; empty when there is none.
  std::filesystem::path capture;
  // Where the virtual studio's truth lies (its rig.json and ground_truth/):
  // a committed `truth` artifact (a synth_raw stage keeps it apart from the
  // capture), else the capture itself.
  std::filesystem::path truth;

  const StageOutput* first_of_kind(const std::string& kind) const;  // nullptr when the config has none
  bool virtual_studio() const;                                      // `truth` has the studio's ground_truth/
};

// Throws tega::Error when the workspace has no recorded config or a subject is unknown.
std::vector<SubjectOutputs> workspace_outputs(const std::filesystem::path& workspace,
                                              const std::vector<std::string>& subjects,
                                              const std::string& tool_version);

}  // namespace tega::report
