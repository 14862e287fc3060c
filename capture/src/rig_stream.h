#pragma once
// Every camera of the rig streaming at once: opens and configures them (an
// Error lists every refused setting of every camera), runs one grabber
// thread per camera and, for the software trigger, a trigger thread per camera; groups
// the frames into frame sets and declares a camera lost when its control
// channel drops or it sends nothing for sync.camera_timeout_ms.
#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "tega/capture/camera.h"
#include "tega/capture/frame_set_assembler.h"

namespace tega::capture {

class RigStream {
 public:
  using SetCallback = std::function<void(FrameSet)>;
  using LostCallback = std::function<void(int camera, const std::string& reason)>;

  RigStream(const RigConfig& rig, Trigger trigger);
  ~RigStream();  // stop()

  void start(SetCallback on_set, LostCallback on_lost);
  // Closes timed-out sets and detects lost cameras; call every few ms.
  void tick();
  // Stops triggers and acquisition and joins the threads. Sets still open
  // (frames that arrived as the take ended) are discarded, not reported.
  void stop();

  struct Statistics {
    uint64_t received = 0, failures = 0, underruns = 0, late = 0;
  };
  Statistics statistics(int camera) const;
  int active_cameras() const;
  std::string silent_cameras() const;  // names of cameras that delivered nothing
  const PixelFormatInfo& format(int camera) const { return cameras_[camera]->format(); }
  std::vector<PixelFormatInfo> formats() const;
  int width(int camera) const { return cameras_[camera]->width(); }
  int height(int camera) const { return cameras_[camera]->height(); }
  std::string description(int camera) const { return cameras_[camera]->description(); }
  nlohmann::json read_back(int camera) const { return cameras_[camera]->settings_read_back(); }

 private:
  void grab(int camera);
  void fire_software_triggers(int camera, std::chrono::steady_clock::time_point first);
  int64_t key_of(const Frame& frame);
  void deliver(std::vector<FrameSet> sets);
  void lose(int camera, const std::string& reason);

  const RigConfig& rig_;
  Trigger trigger_;
  std::vector<std::unique_ptr<Camera>> cameras_;
  std::vector<FrameIdUnwrapper> unwrappers_;
  std::unique_ptr<FrameSetAssembler> assembler_;
  std::mutex mutex_;  // assembler_, unwrappers_; the callbacks run under it, one at a time
  SetCallback on_set_;
  LostCallback on_lost_;
  std::vector<std::thread> threads_;
  std::atomic<bool> running_{false};
  int64_t started_ns_ = 0;
  std::vector<std::unique_ptr<std::atomic<int64_t>>> last_frame_ns_;  // 0 = none yet
  std::vector<std::unique_ptr<std::atomic<uint64_t>>> received_, late_;
  std::unique_ptr<std::atomic<bool>[]> lost_;  // read by the trigger thread
};

}  // namespace tega::capture
