#pragma once
// One GenICam camera through Aravis: open by serial, apply and read back the
// settings, stream frames. Aravis' types stay inside camera.cpp.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tega/capture/frame.h"
#include "tega/capture/options.h"
#include "tega/capture/pixel_format.h"

namespace tega::capture {

// A camera Aravis can see (`tega capture list`).
struct CameraDescription {
  std::string id, vendor, model, serial, interface, address;
};
std::vector<CameraDescription> list_cameras();
// Discovery again while a wanted serial is missing: GigE Vision discovery is
// UDP broadcast, and a reply can get lost.
std::vector<CameraDescription> discover_cameras(const std::vector<std::string>& serials);

enum class Trigger { hardware, software, free_run };
Trigger parse_trigger(const std::string& name);  // hardware | software | free
std::string to_string(Trigger trigger);

class Camera {
 public:
  // source "aravis": the camera with config.serial among `discovered` (an
  // Error lists the serials found otherwise); "fake": a new in-process Aravis
  // simulated camera with that serial.
  Camera(const CameraConfig& config, int index, const std::string& source,
         const std::vector<CameraDescription>& discovered);
  ~Camera();
  Camera(const Camera&) = delete;
  Camera& operator=(const Camera&) = delete;

  // Applies every setting and reads each back. Returns one line per setting
  // the camera refused or changed: "feature: wanted W, camera reports A".
  std::vector<std::string> configure(const CameraSettings& settings, Trigger trigger);
  nlohmann::json settings_read_back() const;  // after configure()
  const PixelFormatInfo& format() const { return format_; }
  int width() const { return width_; }
  int height() const { return height_; }
  const std::string& name() const { return config_.name; }
  std::string description() const;  // vendor, model, serial, address

  void start(int buffers);  // allocates stream buffers and starts acquiring
  void stop();
  // The next complete frame, or nothing after `timeout_ms`. Incomplete
  // buffers go back to the stream and count in statistics().failures.
  std::optional<Frame> next_frame(int timeout_ms);
  void software_trigger();
  bool control_lost() const;
  struct Statistics {
    uint64_t completed = 0, failures = 0, underruns = 0;
  };
  Statistics statistics() const;

 private:
  struct Aravis;
  std::unique_ptr<Aravis> arv_;
  CameraConfig config_;
  int index_;
  PixelFormatInfo format_;
  int width_ = 0, height_ = 0;
  Trigger trigger_ = Trigger::free_run;
};

}  // namespace tega::capture
