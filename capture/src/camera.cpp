#include "tega/capture/camera.h"

#include <arv.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <sstream>

#include "tega/core/error.h"

namespace tega::capture {

namespace {

// Owns a GError and turns it into text.
struct GErrorSlot {
  GError* error = nullptr;
  ~GErrorSlot() { g_clear_error(&error); }
  GError** operator&() { return &error; }
  explicit operator bool() const { return error != nullptr; }
  std::string take() {
    std::string text = error ? error->message : "";
    g_clear_error(&error);
    return text;
  }
};

std::string text_of(double value) {
  std::ostringstream s;
  s << value;
  return s.str();
}

bool close_enough(double wanted, double actual, double relative, double absolute) {
  return std::abs(wanted - actual) <= std::max(relative * std::abs(wanted), absolute);
}

}  // namespace

Trigger parse_trigger(const std::string& name) {
  if (name == "hardware") return Trigger::hardware;
  if (name == "software") return Trigger::software;
  if (name == "free") return Trigger::free_run;
  throw Error("trigger must be hardware, software or free, not '" + name + "'");
}

std::string to_string(Trigger trigger) {
  switch (trigger) {
    case Trigger::hardware: return "hardware";
    case Trigger::software: return "software";
    case Trigger::free_run: return "free";
  }
  return "?";
}

std::vector<CameraDescription> list_cameras() {
  arv_update_device_list();
  std::vector<CameraDescription> cameras;
  const auto text = [](const char* s) { return std::string(s ? s : ""); };
  for (unsigned i = 0; i < arv_get_n_devices(); ++i) {
    cameras.push_back({text(arv_get_device_id(i)), text(arv_get_device_vendor(i)), text(arv_get_device_model(i)),
                       text(arv_get_device_serial_nbr(i)), text(arv_get_device_protocol(i)),
                       text(arv_get_device_address(i))});
  }
  return cameras;
}

std::vector<CameraDescription> discover_cameras(const std::vector<std::string>& serials) {
  constexpr int kAttempts = 3;
  std::vector<CameraDescription> cameras;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    cameras = list_cameras();
    bool all = true;
    for (const auto& serial : serials)
      all = all && std::any_of(cameras.begin(), cameras.end(), [&](const auto& c) { return c.serial == serial; });
    if (all) break;
  }
  return cameras;
}

struct Camera::Aravis {
  ArvCamera* camera = nullptr;
  ArvStream* stream = nullptr;
  ArvFakeCamera* fake = nullptr;  // the simulated camera behind a fake device
  std::atomic<bool> control_lost{false};
  gulong control_lost_handler = 0;
  nlohmann::json read_back;
  double trigger_rate = 0;
  std::string serial, address;

  ~Aravis() {
    if (stream) {
      arv_stream_set_emit_signals(stream, FALSE);
      g_object_unref(stream);
    }
    if (camera) {
      if (control_lost_handler) g_signal_handler_disconnect(arv_camera_get_device(camera), control_lost_handler);
      g_object_unref(camera);
    }
  }
};

Camera::Camera(const CameraConfig& config, int index, const std::string& source,
               const std::vector<CameraDescription>& discovered)
    : arv_(std::make_unique<Aravis>()), config_(config), index_(index) {
  GErrorSlot error;
  arv_->serial = config.serial;
  if (source == "fake") {
    ArvDevice* device = arv_fake_device_new(config.serial.c_str(), &error);
    if (!device) throw Error("camera " + config.name + ": cannot create a simulated camera: " + error.take());
    arv_->fake = arv_fake_device_get_fake_camera(ARV_FAKE_DEVICE(device));
    arv_->camera = arv_camera_new_with_device(device, &error);
    g_object_unref(device);  // the camera holds its own reference
    arv_->address = "in-process";
  } else {
    std::string found;
    for (const auto& c : discovered) {
      if (c.serial == config.serial) {
        arv_->camera = arv_camera_new(c.id.c_str(), &error);
        arv_->address = c.address;
        break;
      }
      found += (found.empty() ? "" : ", ") + c.serial;
    }
    if (!arv_->camera && !error)
      throw Error("camera " + config.name + ": no camera with serial '" + config.serial + "' (Aravis sees: " +
                  (found.empty() ? "none" : found) + "; run `tega capture list`)");
  }
  if (!arv_->camera) throw Error("camera " + config.name + " (serial " + config.serial + "): cannot open: " + error.take());
  arv_->control_lost_handler = g_signal_connect(
      arv_camera_get_device(arv_->camera), "control-lost",
      G_CALLBACK(+[](ArvDevice*, gpointer flag) { static_cast<std::atomic<bool>*>(flag)->store(true); }),
      &arv_->control_lost);
}

Camera::~Camera() {
  if (arv_ && arv_->camera && arv_->stream) stop();
}

std::string Camera::description() const {
  GErrorSlot e1, e2;
  const char* vendor = arv_camera_get_vendor_name(arv_->camera, &e1);
  const char* model = arv_camera_get_model_name(arv_->camera, &e2);
  return std::string(vendor ? vendor : "?") + " " + (model ? model : "?") + ", serial " + arv_->serial + ", " +
         arv_->address;
}

std::vector<std::string> Camera::configure(const CameraSettings& s, Trigger trigger) {
  ArvCamera* cam = arv_->camera;
  std::vector<std::string> problems;
  auto& read_back = arv_->read_back;
  read_back = nlohmann::json::object();
  const auto refused = [&](const std::string& feature, const std::string& wanted, GErrorSlot& error) {
    if (!error) return false;
    problems.push_back(feature + ": wanted " + wanted + ", camera refused: " + error.take());
    return true;
  };
  const auto compare = [&](const std::string& feature, const std::string& wanted, const std::string& actual, bool ok) {
    read_back[feature] = actual;
    if (!ok) problems.push_back(feature + ": wanted " + wanted + ", camera reports " + actual);
  };

  trigger_ = trigger;
  GErrorSlot error;
  // Triggers first: some cameras lock the frame rate or ROI while triggered.
  if (trigger == Trigger::free_run) {
    arv_camera_clear_triggers(cam, &error);
    refused("TriggerMode", "Off", error);
  } else {
    const std::string source = trigger == Trigger::software ? "Software" : s.trigger_source;
    arv_camera_set_trigger(cam, source.c_str(), &error);
    if (!refused("TriggerSource", source, error)) {
      const char* actual = arv_camera_get_trigger_source(cam, &error);
      if (!refused("TriggerSource", source, error)) compare("TriggerSource", source, actual ? actual : "", actual && source == actual);
    }
    if (trigger == Trigger::hardware && arv_camera_is_feature_available(cam, "TriggerActivation", nullptr)) {
      arv_camera_set_string(cam, "TriggerActivation", s.trigger_activation.c_str(), &error);
      if (!refused("TriggerActivation", s.trigger_activation, error)) {
        const char* actual = arv_camera_get_string(cam, "TriggerActivation", &error);
        compare("TriggerActivation", s.trigger_activation, actual ? actual : "", actual && s.trigger_activation == actual);
      }
    }
  }

  guint n_formats = 0;
  const char** formats = arv_camera_dup_available_pixel_formats_as_strings(cam, &n_formats, &error);
  std::string offered;
  bool available = false;
  for (guint i = 0; formats && i < n_formats; ++i) {
    offered += (i ? ", " : "") + std::string(formats[i]);
    available = available || s.pixel_format == formats[i];
  }
  g_free(formats);
  if (formats && !available) {
    problems.push_back("PixelFormat: wanted " + s.pixel_format + ", camera offers " + offered);
  } else {
    arv_camera_set_pixel_format_from_string(cam, s.pixel_format.c_str(), &error);
    if (!refused("PixelFormat", s.pixel_format, error)) {
      const char* actual = arv_camera_get_pixel_format_as_string(cam, &error);
      compare("PixelFormat", s.pixel_format, actual ? actual : "", actual && s.pixel_format == actual);
    }
  }
  format_ = pixel_format_info(s.pixel_format);

  gint min_w = 0, max_w = 0, min_h = 0, max_h = 0;
  arv_camera_get_width_bounds(cam, &min_w, &max_w, &error);
  if (!error) arv_camera_get_height_bounds(cam, &min_h, &max_h, &error);
  if (!refused("Width/Height bounds", "readable", error)) {
    const int w = s.width > 0 ? s.width : max_w - s.offset_x;
    const int h = s.height > 0 ? s.height : max_h - s.offset_y;
    const std::string wanted = std::to_string(w) + "x" + std::to_string(h) + "+" + std::to_string(s.offset_x) + "+" +
                               std::to_string(s.offset_y);
    if (s.offset_x + w > max_w || s.offset_y + h > max_h) {
      problems.push_back("region: wanted " + wanted + ", sensor is at most " + std::to_string(max_w) + "x" +
                         std::to_string(max_h));
    } else {
      arv_camera_set_region(cam, s.offset_x, s.offset_y, w, h, &error);
      if (!refused("region", wanted, error)) {
        gint x = 0, y = 0;
        arv_camera_get_region(cam, &x, &y, &width_, &height_, &error);
        const std::string actual = std::to_string(width_) + "x" + std::to_string(height_) + "+" + std::to_string(x) +
                                   "+" + std::to_string(y);
        compare("region", wanted, actual, actual == wanted);
      }
    }
  }

  // Cameras quantise exposure to whole sensor lines and gain to their own steps: 1% is "taken".
  arv_camera_set_exposure_time(cam, s.exposure_us, &error);
  if (!refused("ExposureTime", text_of(s.exposure_us) + " us", error)) {
    const double actual = arv_camera_get_exposure_time(cam, &error);
    if (!refused("ExposureTime", text_of(s.exposure_us) + " us", error))
      compare("ExposureTime", text_of(s.exposure_us) + " us", text_of(actual) + " us",
              close_enough(s.exposure_us, actual, 0.01, 1.0));
    read_back["ExposureTime"] = actual;
  }
  arv_camera_set_gain(cam, s.gain, &error);
  if (!refused("Gain", text_of(s.gain), error)) {
    const double actual = arv_camera_get_gain(cam, &error);
    if (!refused("Gain", text_of(s.gain), error))
      compare("Gain", text_of(s.gain), text_of(actual), close_enough(s.gain, actual, 0.01, 0.01));
    read_back["Gain"] = actual;
  }
  if (trigger == Trigger::free_run) {
    arv_camera_set_frame_rate(cam, s.frame_rate, &error);
    if (!refused("AcquisitionFrameRate", text_of(s.frame_rate), error)) {
      const double actual = arv_camera_get_frame_rate(cam, &error);
      if (!refused("AcquisitionFrameRate", text_of(s.frame_rate), error))
        compare("AcquisitionFrameRate", text_of(s.frame_rate), text_of(actual),
                close_enough(s.frame_rate, actual, 0.01, 0.01));
      read_back["AcquisitionFrameRate"] = actual;
    }
  }
  arv_->trigger_rate = s.frame_rate;

  if (arv_camera_is_gv_device(cam)) {
    if (!s.packet_socket) arv_camera_gv_set_stream_options(cam, ARV_GV_STREAM_OPTION_PACKET_SOCKET_DISABLED);
    if (s.packet_size > 0) {
      arv_camera_gv_set_packet_size(cam, s.packet_size, &error);
    } else {
      arv_camera_gv_auto_packet_size(cam, &error);
    }
    if (!refused("GevSCPSPacketSize", s.packet_size > 0 ? std::to_string(s.packet_size) : "auto", error)) {
      const guint actual = arv_camera_gv_get_packet_size(cam, &error);
      if (s.packet_size > 0)
        compare("GevSCPSPacketSize", std::to_string(s.packet_size), std::to_string(actual),
                close_enough(s.packet_size, actual, 0, 4));  // some cameras round to 4 bytes
      read_back["GevSCPSPacketSize"] = actual;
    }
    if (s.packet_delay_ns > 0) {
      arv_camera_gv_set_packet_delay(cam, s.packet_delay_ns, &error);
      if (!refused("GevSCPD", std::to_string(s.packet_delay_ns) + " ns", error))
        read_back["GevSCPD_ns"] = arv_camera_gv_get_packet_delay(cam, &error);
    }
  }
  return problems;
}

nlohmann::json Camera::settings_read_back() const { return arv_->read_back; }

void Camera::start(int buffers) {
  GErrorSlot error;
  ArvCamera* cam = arv_->camera;
  arv_->stream = arv_camera_create_stream(cam, nullptr, nullptr, &error);
  if (!arv_->stream) throw Error("camera " + config_.name + ": cannot open a stream: " + error.take());
  const guint payload = arv_camera_get_payload(cam, &error);
  if (error) throw Error("camera " + config_.name + ": cannot read the payload size: " + error.take());
  for (int i = 0; i < buffers; ++i) arv_stream_push_buffer(arv_->stream, arv_buffer_new(payload, nullptr));
  // The in-process simulated camera has no trigger line: pulse it at the configured rate instead.
  if (arv_->fake && trigger_ != Trigger::free_run) arv_fake_camera_set_trigger_frequency(arv_->fake, arv_->trigger_rate);
  arv_camera_start_acquisition(cam, &error);
  if (error) throw Error("camera " + config_.name + ": cannot start acquisition: " + error.take());
}

void Camera::stop() {
  if (!arv_->stream) return;
  GErrorSlot error;
  arv_camera_stop_acquisition(arv_->camera, &error);  // a lost camera cannot answer; nothing more to do
}

std::optional<Frame> Camera::next_frame(int timeout_ms) {
  ArvStream* stream = arv_->stream;
  ArvBuffer* buffer = arv_stream_timeout_pop_buffer(stream, guint64(timeout_ms) * 1000);
  if (!buffer) return std::nullopt;
  if (arv_buffer_get_status(buffer) != ARV_BUFFER_STATUS_SUCCESS) {  // Aravis counts it in its failures
    arv_stream_push_buffer(stream, buffer);
    return std::nullopt;
  }
  Frame frame;
  frame.camera = index_;
  frame.frame_id = arv_buffer_get_frame_id(buffer);
  frame.device_ns = arv_buffer_get_timestamp(buffer);
  frame.host_ns = arv_buffer_get_system_timestamp(buffer);
  frame.width = arv_buffer_get_image_width(buffer);
  frame.height = arv_buffer_get_image_height(buffer);
  size_t size = 0;
  frame.pixels = static_cast<const uint8_t*>(arv_buffer_get_data(buffer, &size));
  frame.size = size;
  g_object_ref(stream);
  frame.owner = std::shared_ptr<const void>(buffer, [stream](const void* b) {
    arv_stream_push_buffer(stream, static_cast<ArvBuffer*>(const_cast<void*>(b)));
    g_object_unref(stream);
  });
  return frame;
}

void Camera::software_trigger() {
  GErrorSlot error;
  arv_camera_software_trigger(arv_->camera, &error);  // a lost camera shows up through control_lost / timeouts
}

bool Camera::control_lost() const { return arv_->control_lost.load(); }

Camera::Statistics Camera::statistics() const {
  Statistics s;
  if (arv_->stream) {
    guint64 completed = 0, failures = 0, underruns = 0;
    arv_stream_get_statistics(arv_->stream, &completed, &failures, &underruns);
    s = {completed, failures, underruns};
  }
  return s;
}

}  // namespace tega::capture
