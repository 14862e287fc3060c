#pragma once
// The take's own files besides the images: take.json (the layout every stage
// reads), manifest.json (cameras, settings read back, counts, events) and
// frame_sets.csv (per frame set: what became of it, each camera's frame id
// and timestamps). See docs/capture.md#the-take-manifest.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tega/capture/frame.h"
#include "tega/capture/recorder.h"

namespace tega::capture {

class RigStream;
class TakeWriter;

struct SetRecord {
  int64_t key = 0;
  std::string status;  // complete, incomplete_kept, incomplete_dropped, writer_full_dropped, ...
  int frame = -1;      // index in the take; -1 = not written
  struct Stamp {
    uint64_t frame_id, device_ns, host_ns;
  };
  std::vector<std::optional<Stamp>> cameras;
};

class TakeFiles {
 public:
  explicit TakeFiles(size_t cameras) : cameras_(cameras) {}
  SetRecord record(const FrameSet& set) const;
  void add(SetRecord record) { sets_.push_back(std::move(record)); }
  void event(double t, std::string message) { events_.push_back({t, std::move(message)}); }

  // Writes take.json, manifest.json and frame_sets.csv into `folder`; fills
  // each camera's frames_written. Returns the take's frame count.
  int finalise(const std::filesystem::path& folder, const RigConfig& rig, const TakeRequest& request,
               const RigStream& stream, const TakeWriter& writer, TakeOutcome& outcome);

  // Space held back on the take's disk from the start, so that the final
  // files still fit after a full disk stopped the take.
  class Reserve {
   public:
    explicit Reserve(const std::filesystem::path& folder);
    ~Reserve() { release(); }
    void release();

   private:
    std::filesystem::path file_;
  };

 private:
  struct Event {
    double t;
    std::string message;
  };
  size_t cameras_;
  std::vector<SetRecord> sets_;
  std::vector<Event> events_;
};

}  // namespace tega::capture
