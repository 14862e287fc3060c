#include "tega/capture/options.h"

#include <yaml-cpp/yaml.h>

#include <set>

#include "tega/capture/pixel_format.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/options.h"

namespace tega::capture {

namespace {

void require(bool ok, const RigConfig& rig, const std::string& message) {
  if (!ok) throw Error(rig.file, message);
}

void validate_settings(const CameraSettings& s, const RigConfig& rig, const std::string& where) {
  try {
    pixel_format_info(s.pixel_format);
  } catch (const Error& e) {
    throw Error(rig.file, where + ": " + e.what());
  }
  require(s.width >= 0 && s.height >= 0 && s.offset_x >= 0 && s.offset_y >= 0, rig,
          where + ": width, height and offsets must not be negative");
  require(s.exposure_us > 0, rig, where + ": exposure_us must be positive");
  require(s.frame_rate > 0, rig, where + ": frame_rate must be positive");
  require(s.packet_size >= 0 && s.packet_delay_ns >= 0, rig, where + ": packet_size and packet_delay_ns must not be negative");
  require(s.trigger_activation == "RisingEdge" || s.trigger_activation == "FallingEdge", rig,
          where + ": trigger_activation must be RisingEdge or FallingEdge, not '" + s.trigger_activation + "'");
}

}  // namespace

void validate_rig_config(const RigConfig& rig) {
  require(rig.source == "aravis" || rig.source == "fake", rig, "source must be aravis or fake, not '" + rig.source + "'");
  require(!rig.cameras.empty(), rig, "the rig has no cameras (list them under `cameras`)");
  std::set<std::string> names, serials;
  for (size_t i = 0; i < rig.cameras.size(); ++i) {
    const auto& c = rig.cameras[i];
    const std::string where = "cameras[" + std::to_string(i) + "]";
    require(!c.name.empty() && !c.serial.empty(), rig, where + " needs a name and a serial");
    require(c.name.find_first_of("/\\ ") == std::string::npos && c.name != "." && c.name != "..", rig,
            where + ": name '" + c.name + "' must be usable as a folder name");
    require(names.insert(c.name).second, rig, where + ": camera name '" + c.name + "' appears twice");
    require(serials.insert(c.serial).second, rig, where + ": serial '" + c.serial + "' appears twice");
    validate_settings(c.settings, rig, where + " (" + c.name + ")");
  }
  const auto& s = rig.sync;
  require(s.group_by == "timestamp" || s.group_by == "frame_id", rig,
          "sync.group_by must be timestamp or frame_id, not '" + s.group_by + "'");
  require(s.timestamp_source == "host" || s.timestamp_source == "device", rig,
          "sync.timestamp_source must be host or device, not '" + s.timestamp_source + "'");
  require(s.incomplete_sets == "drop" || s.incomplete_sets == "keep", rig,
          "sync.incomplete_sets must be drop or keep, not '" + s.incomplete_sets + "'");
  require(s.tolerance_ms >= 0 && s.set_timeout_ms > 0 && s.camera_timeout_ms > 0, rig,
          "sync: tolerance_ms must not be negative, set_timeout_ms and camera_timeout_ms must be positive");
  const auto& w = rig.writer;
  require(w.format == "png" || w.format == "tiff", rig, "writer.format must be png or tiff, not '" + w.format + "'");
  require(w.png_compression >= 0 && w.png_compression <= 9, rig, "writer.png_compression must be 0..9");
  require(w.threads >= 0 && w.queue_depth >= 1, rig, "writer.threads must be >= 0 and writer.queue_depth >= 1");
  require(w.min_free_mb >= 0, rig, "writer.min_free_mb must not be negative");
}

RigConfig load_rig_config(const std::filesystem::path& file) {
  RigConfig rig;
  rig.file = file;
  const std::string text = read_text_file(file);
  load_options_from_string(rig, text, "", file.string());
  // A camera's `settings` holds only what differs from the rig's: lay those
  // keys over the rig's settings rather than over the defaults.
  const YAML::Node cameras = YAML::Load(text)["cameras"];
  for (size_t i = 0; i < rig.cameras.size(); ++i) {
    rig.cameras[i].settings = rig.settings;
    if (const YAML::Node own = cameras[i]["settings"]; own && own.IsMap()) {
      load_options_from_string(rig.cameras[i].settings, YAML::Dump(own), "",
                               file.string() + " cameras[" + std::to_string(i) + "].settings");
    }
  }
  validate_rig_config(rig);
  return rig;
}

}  // namespace tega::capture
