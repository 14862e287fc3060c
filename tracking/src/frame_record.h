#pragma once
// One tracked frame on disk: <frame>.json (status, pose, expression by name,
// residuals) and, for a tracked frame, <frame>.bin (world-space vertices).
// The .bin is written first and the .json last, so a frame with a .json is
// complete.

#include <filesystem>
#include <optional>
#include <string>

#include "tega/tracking/head_model.h"
#include "tega/tracking/tracker.h"

namespace tega::tracking {

struct FrameRecord {
  int frame = 0;
  std::string status;  // tracked | failed | skipped
  std::string reason;  // why not tracked
  HeadState state;     // tracked or failed frames
  FrameResiduals residuals;
  bool fitted_afresh = false;  // see FrameFit
};

void write_frame_record(const std::filesystem::path& take_dir, const FrameRecord& record, const Vertices* vertices,
                        const HeadModel& model);

struct StoredFrame {
  FrameRecord record;
  HeadState state;  // with the corrections recovered from the .bin (tracked frames)
};

// nullopt when the frame has no record yet. Throws tega::Error naming the
// file when it is damaged or belongs to another model.
std::optional<StoredFrame> read_frame_record(const std::filesystem::path& take_dir, int frame, const HeadModel& model,
                                             const SubjectIdentity* subject = nullptr);

}  // namespace tega::tracking
