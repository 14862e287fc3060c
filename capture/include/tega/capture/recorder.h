#pragma once
// Records one take from the rig into CAPTURE/takes/<take>/ (docs/capture.md):
// opens every camera, applies and reads back the settings (refusing to start
// when one does not take them), streams, groups frames into frame sets,
// writes them, and finalises the take, its manifest and capture.json, also
// when it stops early (Ctrl-C, a write error, a lost camera).
#include <atomic>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tega/capture/camera.h"
#include "tega/capture/options.h"

namespace tega::capture {

struct TakeRequest {
  std::string name;
  std::string kind = "performance";  // performance | calibration | clean_plate
  int frames = 0;                    // frame sets to write; 0 = no limit
  double seconds = 0;                // 0 = no limit; with neither, the take runs until stopped (Ctrl-C)
  Trigger trigger = Trigger::hardware;
  std::filesystem::path preview;     // contact sheet of the latest frame set, rewritten every few seconds; "" = none
  bool live_status = true;           // per-camera fps, drops and queue depth on stderr
};

struct CameraOutcome {
  std::string name;
  uint64_t frames_received = 0, frames_written = 0;
  uint64_t stream_failures = 0, stream_underruns = 0, late_frames = 0;
  bool lost = false;
  std::string lost_reason;
  int lost_from_frame = -1;  // first frame index of the take it has no image for
};

struct TakeOutcome {
  std::filesystem::path folder;  // CAPTURE/takes/<take>
  int frames = 0;                // frames of the take (frame sets written)
  int64_t sets_seen = 0, incomplete_sets = 0, incomplete_dropped = 0, writer_full_dropped = 0;
  int64_t before_all_streaming = 0;  // sets discarded while the cameras were still starting
  std::string stop_reason;       // why the take ended
  std::string error;             // the write error that stopped it; "" = none
  double seconds = 0;
  uint64_t bytes = 0;
  std::vector<CameraOutcome> cameras;
};

struct RecordHooks {
  std::atomic<bool>* stop = nullptr;  // set to stop the take (besides Ctrl-C)
  std::function<void(const std::filesystem::path&)> before_write;  // see TakeWriter::before_write
};

// Throws tega::Error, writing nothing, when the rig cannot start (a camera is
// missing or refuses a setting, the take exists, the disk is nearly full).
// Once recording, every stop finalises the take; `error` says whether a
// write error ended it.
TakeOutcome record_take(const RigConfig& rig, const TakeRequest& request, const std::filesystem::path& capture_root,
                        const RecordHooks& hooks = {});

// `tega capture check`: opens every camera, applies and reads back the
// settings, grabs one frame set. Throws tega::Error on a refused setting;
// the report names each camera's read-back settings and the set's spread.
nlohmann::json check_rig(const RigConfig& rig, Trigger trigger);

}  // namespace tega::capture
