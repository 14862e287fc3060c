#pragma once
// A frame as a camera delivered it, and a frame set: one frame per camera
// taken at the same instant (or fewer, when a camera missed it).
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

namespace tega::capture {

struct Frame {
  int camera = 0;             // index into the rig's cameras
  uint64_t frame_id = 0;      // the camera's frame counter
  uint64_t device_ns = 0;     // camera clock
  uint64_t host_ns = 0;       // arrival on this computer (CLOCK_REALTIME)
  int width = 0, height = 0;
  const uint8_t* pixels = nullptr;  // width * height * bytes per pixel, rows packed
  size_t size = 0;
  // Keeps `pixels` alive; releasing it hands the buffer back to the camera's
  // stream, which is what bounds the memory a slow writer can use.
  std::shared_ptr<const void> owner;
};

struct FrameSet {
  int64_t key = 0;  // the timestamp (ns) or frame id the set was grouped by
  std::vector<std::optional<Frame>> frames;  // one slot per camera; empty = missing
  // Closed while a camera it lacks had not started streaming yet: the rig's
  // cameras start one after another, so a take's first instants miss the
  // last ones. Such a set says nothing about synchronisation.
  bool before_all_streaming = false;
  bool complete() const {
    for (const auto& f : frames)
      if (!f) return false;
    return true;
  }
};

}  // namespace tega::capture
