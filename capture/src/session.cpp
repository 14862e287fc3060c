#include "tega/capture/session.h"

#include "tega/capture/recorder.h"
#include "tega/core/error.h"
#include "tega/core/log.h"

namespace tega::capture {

void run_session(const SessionOptions& options, const std::filesystem::path& capture_root) {
  if (options.rig.empty()) throw Error("capture session: option `rig` names no rig config");
  if (options.takes.empty()) throw Error("capture session: option `takes` lists no takes");
  for (const auto& t : options.takes)
    if (t.frames <= 0 && t.seconds <= 0)
      throw Error("capture session: take '" + t.name + "' needs frames or seconds (an unattended session must end)");
  const RigConfig rig = load_rig_config(options.rig);
  for (const auto& t : options.takes) {
    TakeRequest request;
    request.name = t.name;
    request.kind = t.kind;
    request.frames = t.frames;
    request.seconds = t.seconds;
    request.trigger = parse_trigger(options.trigger);
    const TakeOutcome outcome = record_take(rig, request, capture_root, {});
    if (!outcome.error.empty()) throw Error(outcome.folder, "take stopped by a write error: " + outcome.error);
    logging::info("take %s: %d frame sets (%s)", t.name.c_str(), outcome.frames, outcome.stop_reason.c_str());
  }
}

}  // namespace tega::capture
