#pragma once
// Groups the frames of all cameras into frame sets by a key (a timestamp in
// ns, or a frame id) within a tolerance, and closes each set: complete, or
// incomplete when every missing camera has moved past it, when it waited
// longer than the timeout, or when a missing camera was lost. A set missing a
// camera whose first frame came after it (or has not come yet) is marked
// before_all_streaming. Sets come out oldest first. Not thread-safe: the
// recorder serialises calls.
#include <cstdint>
#include <vector>

#include "tega/capture/frame.h"

namespace tega::capture {

class FrameSetAssembler {
 public:
  FrameSetAssembler(int cameras, int64_t tolerance, int64_t set_timeout_ns);

  // Each returns the sets it closed, oldest first. `now_ns` is any monotonic clock.
  std::vector<FrameSet> add(Frame frame, int64_t key, int64_t now_ns);
  std::vector<FrameSet> tick(int64_t now_ns);
  // The camera delivers no more; sets stop waiting for it.
  std::vector<FrameSet> drop_camera(int camera, int64_t now_ns);
  std::vector<FrameSet> flush();  // closes every open set

  // Frames that matched a set already closed, or came for a camera already
  // dropped: they cannot be written into a set and are counted as drops.
  const std::vector<int64_t>& late_frames() const { return late_; }
  size_t open_sets() const { return open_.size(); }

 private:
  struct OpenSet {
    FrameSet set;
    int64_t opened_ns;
  };
  bool closable(const OpenSet& open, int64_t now_ns) const;
  std::vector<FrameSet> close_ready(int64_t now_ns);

  int cameras_;
  int64_t tolerance_, timeout_ns_;
  std::vector<OpenSet> open_;  // ascending key
  std::vector<bool> active_;
  std::vector<int64_t> latest_key_;  // per camera; INT64_MIN before its first frame
  std::vector<int64_t> first_key_;   // per camera; INT64_MAX before its first frame
  std::vector<int64_t> late_;
  bool emitted_any_ = false;
  int64_t last_emitted_key_ = 0;
};

// Turns a camera's frame counter, which may wrap (GigE Vision 1.x uses 16
// bits), into a monotonic id.
class FrameIdUnwrapper {
 public:
  explicit FrameIdUnwrapper(int bits) : period_(bits >= 64 ? 0 : (int64_t{1} << bits)) {}
  int64_t operator()(uint64_t raw);

 private:
  int64_t period_, offset_ = 0;
  bool seen_ = false;
  uint64_t last_ = 0;
};

}  // namespace tega::capture
