// The tega rig file (docs/rig-files.md#rig-json).
#include <nlohmann/json.hpp>

#include <algorithm>
#include <initializer_list>
#include <string>
#include <utility>

#include "json_file.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/rig.h"

namespace tega {
namespace {

using nlohmann::json;

constexpr const char* kFormat = "tega-rig";
constexpr int kVersion = 1;
constexpr const char* kUnits = "metres";

// Reads fields of one JSON object, every error naming the file and `context`
// ("the rig", "camera 'cam00'").
class ObjectReader {
 public:
  ObjectReader(const json& object, const std::filesystem::path& file, std::string context)
      : object_(object), file_(file), context_(std::move(context)) {}

  [[noreturn]] void fail(const std::string& what) const { throw Error(file_, context_ + ": " + what); }

  void reject_unknown_fields(std::initializer_list<const char*> known) const {
    for (const auto& [key, value] : object_.items()) {
      bool found = false;
      for (const char* k : known) found = found || key == k;
      if (!found) fail("unknown field '" + key + "'");
    }
  }

  const json& field(const char* key) const {
    const auto it = object_.find(key);
    if (it == object_.end()) fail(std::string("missing field '") + key + "'");
    return *it;
  }

  std::string string(const char* key) const {
    const json& v = field(key);
    if (!v.is_string()) fail(std::string("field '") + key + "' must be a string");
    return v.get<std::string>();
  }

  int integer(const char* key) const {
    const json& v = field(key);
    if (!detail::holds_integer<int>(v)) fail(std::string("field '") + key + "' must be an integer that fits an int");
    return v.get<int>();
  }

  template <int N>
  Eigen::Matrix<double, N, 1> vector(const char* key) const {
    const json& v = field(key);
    Eigen::Matrix<double, N, 1> out;
    if (!read_numbers<N>(v, out.data())) fail(shape_message(key, std::to_string(N) + " numbers"));
    return out;
  }

  Eigen::Matrix3d matrix3(const char* key) const {
    const json& v = field(key);
    Eigen::Matrix3d out;
    bool ok = v.is_array() && v.size() == 3;
    for (int r = 0; ok && r < 3; ++r) {
      Eigen::Vector3d row;
      ok = read_numbers<3>(v[r], row.data());
      out.row(r) = row.transpose();
    }
    if (!ok) fail(shape_message(key, "3x3 array of numbers (rows)"));
    return out;
  }

 private:
  template <int N>
  static bool read_numbers(const json& v, double* out) {
    if (!v.is_array() || v.size() != N) return false;
    for (int i = 0; i < N; ++i) {
      if (!v[i].is_number()) return false;
      out[i] = v[i].get<double>();
    }
    return true;
  }
  static std::string shape_message(const char* key, const std::string& shape) {
    return std::string("field '") + key + "' must be a " + shape;
  }

  const json& object_;
  const std::filesystem::path& file_;
  std::string context_;
};

Camera read_camera(const json& entry, size_t index, const std::filesystem::path& file) {
  const std::string position = "camera #" + std::to_string(index);
  if (!entry.is_object()) throw Error(file, position + ": expected a JSON object");
  Camera camera;
  camera.name = ObjectReader(entry, file, position).string("name");
  const ObjectReader fields(entry, file, "camera '" + camera.name + "'");
  fields.reject_unknown_fields({"name", "width", "height", "K", "distortion", "R", "t"});
  camera.width = fields.integer("width");
  camera.height = fields.integer("height");
  camera.K = fields.matrix3("K");
  const Eigen::Matrix<double, 5, 1> distortion = fields.vector<5>("distortion");
  std::copy(distortion.data(), distortion.data() + 5, camera.distortion.begin());
  camera.world_to_camera.R = fields.matrix3("R");
  camera.world_to_camera.t = fields.vector<3>("t");
  return camera;
}

json rows(const Eigen::Matrix3d& m) {
  json out = json::array();
  for (int r = 0; r < 3; ++r) out.push_back({m(r, 0), m(r, 1), m(r, 2)});
  return out;
}

}  // namespace

Rig read_rig_json(const std::filesystem::path& file) {
  json doc;
  try {
    doc = json::parse(read_text_file(file));
  } catch (const json::exception& e) {
    throw Error(file, std::string("not valid JSON: ") + e.what());
  }
  if (!doc.is_object()) throw Error(file, "expected a JSON object at the top level");
  const ObjectReader top(doc, file, "rig");
  top.reject_unknown_fields({"format", "version", "units", "cameras"});
  if (const std::string format = top.string("format"); format != kFormat)
    top.fail("field 'format' is '" + format + "', expected '" + kFormat + "'");
  if (const int version = top.integer("version"); version != kVersion)
    top.fail("unsupported version " + std::to_string(version) + " (this tega reads version " +
             std::to_string(kVersion) + ")");
  if (const std::string units = top.string("units"); units != kUnits)
    top.fail("field 'units' is '" + units + "', expected '" + kUnits + "'");
  const json& cameras = top.field("cameras");
  if (!cameras.is_array()) top.fail("field 'cameras' must be an array");

  Rig rig;
  for (size_t i = 0; i < cameras.size(); ++i) rig.cameras.push_back(read_camera(cameras[i], i, file));
  rig.validate(file);
  return rig;
}

void write_rig_json(const Rig& rig, const std::filesystem::path& file) {
  rig.validate(file);
  // Written by hand rather than json::dump(2) so that each matrix row stays on
  // one line; values still go through json for escaping and exact doubles.
  std::string text = "{\n  \"format\": " + json(kFormat).dump() +
                     ",\n  \"version\": " + std::to_string(kVersion) +
                     ",\n  \"units\": " + json(kUnits).dump() + ",\n  \"cameras\": [";
  for (size_t i = 0; i < rig.cameras.size(); ++i) {
    const Camera& c = rig.cameras[i];
    const Eigen::Vector3d& t = c.world_to_camera.t;
    text += i == 0 ? "\n" : ",\n";
    text += "    {\n";
    text += "      \"name\": " + json(c.name).dump() + ",\n";
    text += "      \"width\": " + std::to_string(c.width) + ",\n";
    text += "      \"height\": " + std::to_string(c.height) + ",\n";
    text += "      \"K\": " + rows(c.K).dump() + ",\n";
    text += "      \"distortion\": " + json(c.distortion).dump() + ",\n";
    text += "      \"R\": " + rows(c.world_to_camera.R).dump() + ",\n";
    text += "      \"t\": " + json({t.x(), t.y(), t.z()}).dump() + "\n";
    text += "    }";
  }
  text += "\n  ]\n}\n";
  write_text_atomic(file, text);
}

}  // namespace tega
