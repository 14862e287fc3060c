#include "tega/core/take.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <optional>
#include <set>

#include "json_file.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/image_header.h"

namespace tega {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* kTakeFile = "take.json";
constexpr const char* kCaptureFile = "capture.json";
constexpr const char* kCaptureFormat = "tega-capture";
constexpr int kCaptureVersion = 1;

// `where` names the enclosing entry in messages, e.g. "takes[2]"; "" at the top level.
template <class T>
T field(const json& object, const char* key, const fs::path& file, const std::string& where = "") {
  const std::string name = where.empty() ? key : where + "." + key;
  if (!object.is_object() || !object.contains(key)) throw Error(file, "has no '" + name + "'");
  return detail::json_as<T>(object.at(key), name, file);
}

template <class T>
T optional_field(const json& object, const char* key, const fs::path& file, T fallback) {
  return object.is_object() && object.contains(key) ? field<T>(object, key, file) : fallback;
}

void check_capture_format(const json& capture, const fs::path& file) {
  if (optional_field<std::string>(capture, "format", file, "") != kCaptureFormat) {
    throw Error(file, std::string("is not a tega capture manifest (format is not '") + kCaptureFormat + "')");
  }
  const int version = optional_field(capture, "version", file, 0);
  if (version != kCaptureVersion) {
    throw Error(file, "has capture version " + std::to_string(version) + "; this tega reads version " +
                          std::to_string(kCaptureVersion));
  }
}

void replace_all(std::string& text, const std::string& token, const std::string& value) {
  for (auto at = text.find(token); at != std::string::npos; at = text.find(token, at + value.size())) {
    text.replace(at, token.size(), value);
  }
}

}  // namespace

int TakeInfo::channels() const {
  const auto is = [&](const char* prefix) { return pixel_format.rfind(prefix, 0) == 0; };
  return is("RGB") || is("BGR") ? 3 : 1;
}

fs::path TakeInfo::image_path(const std::string& camera, int frame) const {
  char padded[16];
  std::snprintf(padded, sizeof padded, "%06d", frame);
  std::string relative = images;
  replace_all(relative, "{camera}", camera);
  replace_all(relative, "{frame:06d}", padded);
  replace_all(relative, "{frame}", std::to_string(frame));
  return folder / relative;
}

bool TakeInfo::has_image(const std::string& camera, int frame) const {
  const auto gaps = missing.find(camera);
  return gaps == missing.end() || !std::binary_search(gaps->second.begin(), gaps->second.end(), frame);
}

TakeInfo read_take(const fs::path& take_folder) {
  const fs::path file = take_folder / kTakeFile;
  const json j = read_json_file(file);
  TakeInfo t;
  t.name = field<std::string>(j, "name", file);
  t.kind = field<std::string>(j, "kind", file);
  t.cameras = field<std::vector<std::string>>(j, "cameras", file);
  t.frames = field<int>(j, "frames", file);
  t.fps = field<double>(j, "fps", file);
  t.images = field<std::string>(j, "images", file);
  // Takes written before recorded takes existed (virtual studio) lack these.
  t.pixel_format = optional_field(j, "pixel_format", file, t.pixel_format);
  t.bit_depth = optional_field(j, "bit_depth", file, t.bit_depth);
  t.missing = optional_field(j, "missing", file, t.missing);
  t.folder = take_folder;
  return t;
}

void write_take(const TakeInfo& take, const fs::path& take_folder) {
  json j = {{"name", take.name},
            {"kind", take.kind},
            {"cameras", take.cameras},
            {"frames", take.frames},
            {"fps", take.fps},
            {"images", take.images},
            {"pixel_format", take.pixel_format},
            {"bit_depth", take.bit_depth}};
  if (!take.missing.empty()) j["missing"] = take.missing;
  write_text_atomic(take_folder / kTakeFile, j.dump(2) + "\n");
}

void validate_take(const TakeInfo& t) {
  const fs::path file = t.folder / kTakeFile;
  if (t.kind != "clean_plate" && t.kind != "calibration" && t.kind != "performance") {
    throw Error(file, "has kind '" + t.kind + "'; a take is clean_plate, calibration or performance");
  }
  if (t.frames < 0) throw Error(file, "has a negative frame count (" + std::to_string(t.frames) + ")");
  if (t.bit_depth != 8 && t.bit_depth != 16) {
    throw Error(file, "has bit_depth " + std::to_string(t.bit_depth) + "; images are 8 or 16 bits");
  }
  const std::string extension = fs::path(t.images).extension().string();
  if (extension != ".png" && extension != ".tif" && extension != ".tiff") {
    throw Error(file, "has images '" + t.images + "'; takes hold .png, .tif or .tiff images");
  }
  // Without both placeholders several images would share one file.
  if (t.images.find("{camera}") == std::string::npos ||
      (t.images.find("{frame}") == std::string::npos && t.images.find("{frame:06d}") == std::string::npos)) {
    throw Error(file, "has images '" + t.images + "'; the pattern needs {camera} and {frame:06d} (or {frame})");
  }
  std::set<std::string> cameras;
  for (const auto& camera : t.cameras) {
    if (!cameras.insert(camera).second) throw Error(file, "lists camera '" + camera + "' twice");
  }
  for (const auto& [camera, frames] : t.missing) {
    if (!cameras.count(camera)) throw Error(file, "lists missing frames of camera '" + camera + "', which it does not have");
    for (size_t i = 0; i < frames.size(); ++i) {
      if (frames[i] < 0 || frames[i] >= t.frames) {
        throw Error(file, "lists missing frame " + std::to_string(frames[i]) + " of camera '" + camera +
                              "'; the take has frames 0 to " + std::to_string(t.frames - 1));
      }
      // has_image() binary-searches them.
      if (i > 0 && frames[i] <= frames[i - 1]) {
        throw Error(file, "lists the missing frames of camera '" + camera + "' out of order or twice");
      }
    }
  }

  const bool png = extension == ".png";
  for (const auto& camera : t.cameras) {
    std::optional<ImageHeader> first;
    for (int frame = 0; frame < t.frames; ++frame) {
      if (!t.has_image(camera, frame)) continue;
      const fs::path image = t.image_path(camera, frame);
      if (!fs::exists(image)) {
        throw Error(image, "is missing (camera '" + camera + "', frame " + std::to_string(frame) +
                               "; take.json does not list it as missing)");
      }
      if (!png) continue;
      const ImageHeader header = read_image_header(image);
      if (header.channels != t.channels() || header.bit_depth != t.bit_depth) {
        throw Error(image, "has " + std::to_string(header.channels) + " channel(s) of " +
                               std::to_string(header.bit_depth) + " bits; take.json says " + t.pixel_format + ", " +
                               std::to_string(t.channels()) + " channel(s) of " + std::to_string(t.bit_depth) +
                               " bits");
      }
      if (!first) {
        first = header;
      } else if (header.width != first->width || header.height != first->height) {
        throw Error(image, "is " + std::to_string(header.width) + "x" + std::to_string(header.height) +
                               "; the first image of camera '" + camera + "' is " + std::to_string(first->width) +
                               "x" + std::to_string(first->height));
      }
    }
  }
}

std::filesystem::path CaptureInfo::rig_file(const std::filesystem::path& chosen) const {
  if (!chosen.empty()) return chosen;
  return root / (rig.empty() ? std::string("rig.json") : rig);
}

std::vector<std::string> CaptureInfo::performance_takes(const std::vector<std::string>& chosen,
                                                        const std::string& purpose) const {
  std::vector<std::string> names = chosen;
  if (names.empty())
    for (const auto& take : takes)
      if (take.kind == "performance") names.push_back(take.name);
  if (names.empty()) throw Error(root / "capture.json", "lists no performance take " + purpose);
  return names;
}

CaptureInfo read_capture(const fs::path& capture_root) {
  const fs::path file = capture_root / kCaptureFile;
  if (!fs::exists(file)) throw Error(capture_root, "is not a tega capture (no capture.json)");
  const json j = read_json_file(file);
  check_capture_format(j, file);
  CaptureInfo c;
  c.root = capture_root;
  c.cameras = field<std::vector<std::string>>(j, "cameras", file);
  c.width = field<int>(j, "width", file);
  c.height = field<int>(j, "height", file);
  c.rig = optional_field<std::string>(j, "rig", file, "");
  c.generator = optional_field<std::string>(j, "generator", file, "");
  const json takes = field<json>(j, "takes", file);
  if (!takes.is_array()) throw Error(file, "'takes' has the wrong type");
  for (size_t i = 0; i < takes.size(); ++i) {
    const std::string where = "takes[" + std::to_string(i) + "]";
    c.takes.push_back({field<std::string>(takes[i], "name", file, where), field<std::string>(takes[i], "kind", file, where),
                       field<int>(takes[i], "frames", file, where)});
  }
  return c;
}

void validate_capture(const fs::path& capture_root) {
  const CaptureInfo capture = read_capture(capture_root);
  const fs::path file = capture_root / kCaptureFile;
  if (!capture.rig.empty() && !fs::exists(capture_root / capture.rig)) {
    throw Error(file, "names rig '" + capture.rig + "', which does not exist");
  }
  const std::set<std::string> cameras(capture.cameras.begin(), capture.cameras.end());
  std::set<std::string> names;
  for (const auto& entry : capture.takes) {
    if (!names.insert(entry.name).second) throw Error(file, "lists take '" + entry.name + "' twice");
    const TakeInfo take = read_take(capture_root / "takes" / entry.name);
    const fs::path take_file = take.folder / kTakeFile;
    if (take.kind != entry.kind) {
      throw Error(take_file, "has kind '" + take.kind + "'; capture.json says '" + entry.kind + "'");
    }
    if (take.frames != entry.frames) {
      throw Error(take_file, "has " + std::to_string(take.frames) + " frames; capture.json says " +
                                 std::to_string(entry.frames));
    }
    for (const auto& camera : take.cameras) {
      if (!cameras.count(camera)) throw Error(take_file, "lists camera '" + camera + "', which capture.json does not");
    }
    validate_take(take);
  }
}

void record_take_in_capture(const fs::path& capture_root, const TakeInfo& take, int width, int height,
                            const std::string& generator) {
  const fs::path file = capture_root / kCaptureFile;
  json capture;
  if (fs::exists(file)) {
    capture = read_json_file(file);
    check_capture_format(capture, file);
  } else {
    capture = {{"format", kCaptureFormat}, {"version", kCaptureVersion}, {"generator", generator},
               {"cameras", json::array()}, {"width", width},           {"height", height},
               {"takes", json::array()}};
  }
  auto cameras = field<std::vector<std::string>>(capture, "cameras", file);
  for (const auto& camera : take.cameras) {
    if (std::find(cameras.begin(), cameras.end(), camera) == cameras.end()) cameras.push_back(camera);
  }
  capture["cameras"] = cameras;
  json takes = optional_field(capture, "takes", file, json::array());
  if (!takes.is_array()) throw Error(file, "'takes' has the wrong type");
  const json entry = {{"name", take.name}, {"kind", take.kind}, {"frames", take.frames}};
  const auto same = std::find_if(takes.begin(), takes.end(),
                                 [&](const json& t) { return t.is_object() && t.value("name", json()) == take.name; });
  if (same != takes.end()) {
    *same = entry;
  } else {
    takes.push_back(entry);
  }
  capture["takes"] = takes;
  write_text_atomic(file, capture.dump(2) + "\n");
}

void parse_frame_range(const std::string& text, int& first, int& end) {
  const auto number = [&](const std::string& s) {
    size_t used = 0;
    int value = -1;
    try {
      value = std::stoi(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != s.size() || value < 0) throw Error("--frames '" + text + "': expected A:B, A: or A (frame numbers)");
    return value;
  };
  const size_t colon = text.find(':');
  if (colon == std::string::npos) {
    first = number(text);
    end = first + 1;
    return;
  }
  first = number(text.substr(0, colon));
  end = colon + 1 == text.size() ? -1 : number(text.substr(colon + 1));
  if (end != -1 && end <= first) throw Error("--frames '" + text + "': the range is empty");
}

}  // namespace tega
