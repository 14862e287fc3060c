#pragma once
// A capture session as one pipeline stage (`tega capture session`, stage
// kind `capture`): the takes of a subject recorded one after another into
// one capture folder.
#include <filesystem>
#include <string>
#include <vector>

namespace tega::capture {

struct SessionTake {
  std::string name;
  std::string kind = "performance";
  int frames = 0;
  double seconds = 0;
  template <class V>
  void visit(V& v) {
    v("name", name, "Take name: its folder under takes/.");
    v("kind", kind, "performance, calibration or clean_plate.");
    v("frames", frames, "Frame sets to record; 0 = use seconds.");
    v("seconds", seconds, "Seconds to record when frames is 0.");
  }
};

struct SessionOptions {
  std::string rig;  // the rig config (docs/capture.md#the-rig-config)
  std::string trigger = "hardware";
  std::vector<SessionTake> takes;
  template <class V>
  void visit(V& v) {
    v("rig", rig, "Rig config file (docs/capture.md#the-rig-config).");
    v("trigger", trigger, "hardware, software or free.");
    v("takes", takes, "The takes to record, in order; each needs frames or seconds.");
  }
};

// Records every take into `capture_root`; throws tega::Error (naming the
// take) when one cannot start or stops on a write error.
void run_session(const SessionOptions& options, const std::filesystem::path& capture_root);

}  // namespace tega::capture
