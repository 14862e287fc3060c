#include "tega/core/dataset.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <set>

#include "json_file.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/image_header.h"

namespace tega {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* kManifest = "dataset.json";
constexpr const char* kFormat = "tega-dataset";
constexpr int kVersion = 1;

template <class T>
T field(const json& object, const char* key, const fs::path& file, const std::string& where) {
  if (!object.contains(key)) throw Error(file, where + " has no '" + key + "'");
  return detail::json_as<T>(object.at(key), where + ": " + key, file);
}

// An optional list of integers (vertex or face indices), checked element by element.
std::vector<int32_t> optional_indices(const json& manifest, const char* key, const fs::path& file) {
  if (!manifest.contains(key)) return {};
  const json& list = manifest.at(key);
  if (!list.is_array()) throw Error(file, std::string("'") + key + "' must be a list");
  std::vector<int32_t> out;
  out.reserve(list.size());
  for (const json& index : list) out.push_back(detail::json_as<int32_t>(index, key, file));
  return out;
}

RigidTransform pose_from_json(const json& rows, const fs::path& file, const std::string& where) {
  Eigen::Matrix<double, 3, 4> m;
  try {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) m(r, c) = rows.at(r).at(c).get<double>();
  } catch (const json::exception&) {
    throw Error(file, where + ": head_to_world must be 3 rows of 4 numbers");
  }
  const Eigen::Matrix3d R = m.leftCols<3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-4 || R.determinant() < 0) {
    throw Error(file, where + ": head_to_world rotation is not a rotation matrix");
  }
  return RigidTransform::from_matrix(m);
}

json pose_to_json(const RigidTransform& pose) {
  json rows = json::array();
  const auto m = pose.matrix();
  for (int r = 0; r < 3; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  return rows;
}

DatasetSplit split_from_json(const json& manifest, const char* name, const fs::path& file) {
  const auto split = field<json>(manifest, "split", file, "the manifest");
  const auto part = field<json>(split, name, file, "split");
  return {field<std::vector<std::string>>(part, "frames", file, std::string("split.") + name),
          field<std::vector<std::string>>(part, "cameras", file, std::string("split.") + name)};
}

void check_split_names(const Dataset& d, const DatasetSplit& split, const char* name, const fs::path& file) {
  std::set<std::string> frames;
  for (const auto& f : d.frames) frames.insert(f.id);
  for (const auto& id : split.frames) {
    if (!frames.count(id)) throw Error(file, std::string("split.") + name + " names unknown frame '" + id + "'");
  }
  for (const auto& cam : split.cameras) {
    if (!d.rig.contains(cam)) {
      throw Error(file, std::string("split.") + name + " names camera '" + cam + "', which is not in the rig");
    }
  }
}

// `missing_images` and `dropped_frames`: optional (absent from datasets made
// before degraded captures were ingested), checked against frames and rig.
json optional_list(const json& manifest, const char* key, const fs::path& file) {
  if (!manifest.contains(key)) return json::array();
  const json& list = manifest.at(key);
  if (!list.is_array()) throw Error(file, std::string("'") + key + "' must be a list");
  for (const auto& entry : list)
    if (!entry.is_object()) throw Error(file, std::string("every entry of '") + key + "' must be an object");
  return list;
}

std::string reason_of(const json& entry, const fs::path& file, const std::string& where) {
  return entry.contains("reason") ? field<std::string>(entry, "reason", file, where) : "";
}

void read_gaps(Dataset& d, const json& manifest, const fs::path& file) {
  std::set<std::string> frames;
  for (const auto& f : d.frames) frames.insert(f.id);
  std::set<std::pair<std::string, std::string>> seen;
  for (const auto& entry : optional_list(manifest, "missing_images", file)) {
    MissingImage missing{field<std::string>(entry, "camera", file, "a missing image"),
                         field<std::string>(entry, "frame", file, "a missing image"),
                         reason_of(entry, file, "a missing image")};
    const std::string where = "missing image (camera '" + missing.camera + "', frame '" + missing.frame + "')";
    if (!frames.count(missing.frame)) throw Error(file, where + " names an unknown frame");
    if (!d.rig.contains(missing.camera)) throw Error(file, where + " names a camera that is not in the rig");
    if (!seen.insert({missing.camera, missing.frame}).second) throw Error(file, where + " is recorded twice");
    d.missing_images.push_back(std::move(missing));
  }
  for (const auto& entry : optional_list(manifest, "dropped_frames", file)) {
    DroppedFrame dropped{field<std::string>(entry, "frame", file, "a dropped frame"),
                         reason_of(entry, file, "a dropped frame")};
    if (frames.count(dropped.frame)) throw Error(file, "frame '" + dropped.frame + "' is both kept and dropped");
    d.dropped_frames.push_back(std::move(dropped));
  }
}

}  // namespace

bool Dataset::has_image(const std::string& camera, const std::string& frame_id) const {
  return std::none_of(missing_images.begin(), missing_images.end(),
                      [&](const MissingImage& m) { return m.camera == camera && m.frame == frame_id; });
}

fs::path Dataset::mesh_path(const std::string& frame_id) const { return root / "meshes" / (frame_id + ".bin"); }

fs::path Dataset::image_path(const std::string& camera, const std::string& frame_id) const {
  return root / "images" / camera / (frame_id + image_extension);
}

const DatasetFrame& Dataset::frame(const std::string& frame_id) const {
  auto it = std::find_if(frames.begin(), frames.end(), [&](const DatasetFrame& f) { return f.id == frame_id; });
  if (it == frames.end()) throw Error(root / kManifest, "has no frame '" + frame_id + "'");
  return *it;
}

Vertices Dataset::load_mesh(const std::string& frame_id) const {
  return read_vertices_bin(mesh_path(frame_id), template_mesh.num_vertices());
}

static Dataset read_dataset_fields(const fs::path& root) {
  const fs::path file = root / kManifest;
  if (!fs::exists(file)) throw Error(root, "is not a tega dataset (no dataset.json)");
  const json manifest = read_json_file(file);
  if (manifest.value("format", "") != kFormat) throw Error(file, "is not a tega dataset manifest (format)");
  const int version = manifest.contains("version") ? detail::json_as<int>(manifest.at("version"), "version", file) : 0;
  if (version != kVersion) {
    throw Error(file, "has dataset version " + std::to_string(version) + "; this tega reads version " +
                          std::to_string(kVersion));
  }

  Dataset d;
  d.root = root;
  d.rig = read_rig_json(root / field<std::string>(manifest, "rig", file, "the manifest"));
  d.template_mesh = read_obj(root / field<std::string>(manifest, "template", file, "the manifest"));
  if (!d.template_mesh.has_uvs()) throw Error(root / manifest["template"].get<std::string>(), "has no UVs");
  const std::string images = manifest.value("images", std::string("images/{camera}/{frame}.png"));
  if (images == "images/{camera}/{frame}.zst") d.image_extension = ".zst";
  else if (images != "images/{camera}/{frame}.png")
    throw Error(file, "names images '" + images + "'; tega reads images/{camera}/{frame}.png or .zst");
  d.eyeball_faces = optional_indices(manifest, "eyeball_faces", file);
  d.landmark_vertices = optional_indices(manifest, "landmark_vertices", file);
  for (int32_t f : d.eyeball_faces) {
    if (f < 0 || f >= d.template_mesh.num_faces()) {
      throw Error(file, "eyeball face " + std::to_string(f) + " is out of range (template has " +
                            std::to_string(d.template_mesh.num_faces()) + " triangles)");
    }
  }
  for (int32_t v : d.landmark_vertices) {
    if (v < 0 || v >= d.template_mesh.num_vertices()) {
      throw Error(file, "landmark vertex " + std::to_string(v) + " is out of range");
    }
  }

  std::set<std::string> ids;
  for (const auto& entry : field<json>(manifest, "frames", file, "the manifest")) {
    DatasetFrame frame;
    frame.id = field<std::string>(entry, "id", file, "a frame");
    const std::string where = "frame '" + frame.id + "'";
    frame.sequence = entry.value("sequence", "");
    frame.head_to_world = pose_from_json(field<json>(entry, "head_to_world", file, where), file, where);
    if (!ids.insert(frame.id).second) throw Error(file, "frame '" + frame.id + "' appears twice");
    d.frames.push_back(std::move(frame));
  }
  d.train = split_from_json(manifest, "train", file);
  d.test = split_from_json(manifest, "test", file);
  check_split_names(d, d.train, "train", file);
  check_split_names(d, d.test, "test", file);
  read_gaps(d, manifest, file);
  return d;
}

Dataset read_dataset(const fs::path& root) {
  // value() and at() throw nlohmann's exceptions for a value of the wrong
  // type (a manifest that is a number, "images": 5): the user gets tega's.
  try {
    return read_dataset_fields(root);
  } catch (const json::exception& e) {
    throw Error(root / kManifest, std::string("is malformed: ") + e.what());
  }
}

void validate_dataset(const Dataset& d) {
  // The avatar's rasterizer is a pinhole camera: datasets hold undistorted images.
  for (const auto& camera : d.rig.cameras) {
    if (camera.has_distortion()) {
      throw Error(d.root / "rig.json", "camera '" + camera.name +
                                           "' has lens distortion; dataset images must be undistorted and "
                                           "their cameras distortion-free");
    }
  }
  const auto check_frame = [&](const std::string& frame_id, const std::vector<std::string>& cameras) {
    const fs::path mesh = d.mesh_path(frame_id);
    if (!fs::exists(mesh)) throw Error(mesh, "is missing (tracked mesh of frame '" + frame_id + "')");
    const auto bytes = fs::file_size(mesh);
    const auto expected = static_cast<uintmax_t>(d.template_mesh.num_vertices()) * 3 * sizeof(float);
    if (bytes != expected) {
      throw Error(mesh, "has " + std::to_string(bytes / 12) + " vertices (" + std::to_string(bytes) +
                            " bytes); the template has " + std::to_string(d.template_mesh.num_vertices()));
    }
    for (const auto& cam : cameras) {
      const Camera& camera = d.rig.camera(cam);
      if (!d.has_image(cam, frame_id)) continue;  // its producer left it out and said so
      const fs::path image = d.image_path(cam, frame_id);
      if (!fs::exists(image))
        throw Error(image, "is missing (camera '" + cam + "', frame '" + frame_id +
                               "'), and dataset.json's missing_images does not record it");
      const ImageHeader header = read_image_header(image);
      if (header.width != camera.width || header.height != camera.height) {
        throw Error(image, "is " + std::to_string(header.width) + "x" + std::to_string(header.height) +
                               "; the rig says camera '" + cam + "' is " + std::to_string(camera.width) + "x" +
                               std::to_string(camera.height));
      }
      if (header.channels != 4) {
        throw Error(image, "has " + std::to_string(header.channels) + " channels; dataset images are RGBA");
      }
    }
  };
  // Evaluation reads train frames from test cameras and test frames from
  // train cameras, so every frame of either split needs every camera (but
  // the images recorded missing).
  std::vector<std::string> all_cameras = d.train.cameras;
  all_cameras.insert(all_cameras.end(), d.test.cameras.begin(), d.test.cameras.end());
  for (const auto& id : d.train.frames) check_frame(id, all_cameras);
  for (const auto& id : d.test.frames) check_frame(id, all_cameras);
}

void write_dataset_manifest(const Dataset& d) {
  write_rig_json(d.rig, d.root / "rig.json");
  write_obj(d.template_mesh, d.root / "template.obj");
  json frames = json::array();
  for (const auto& f : d.frames) {
    frames.push_back({{"id", f.id}, {"sequence", f.sequence}, {"head_to_world", pose_to_json(f.head_to_world)}});
  }
  json missing_images = json::array();
  for (const auto& m : d.missing_images)
    missing_images.push_back({{"camera", m.camera}, {"frame", m.frame}, {"reason", m.reason}});
  json dropped_frames = json::array();
  for (const auto& f : d.dropped_frames) dropped_frames.push_back({{"frame", f.frame}, {"reason", f.reason}});
  const json manifest = {
      {"format", kFormat},
      {"version", kVersion},
      {"rig", "rig.json"},
      {"template", "template.obj"},
      {"meshes", "meshes/{frame}.bin"},
      {"images", "images/{camera}/{frame}" + d.image_extension},
      {"eyeball_faces", d.eyeball_faces},
      {"landmark_vertices", d.landmark_vertices},
      {"frames", frames},
      {"split",
       {{"train", {{"frames", d.train.frames}, {"cameras", d.train.cameras}}},
        {"test", {{"frames", d.test.frames}, {"cameras", d.test.cameras}}}}},
      {"missing_images", missing_images},
      {"dropped_frames", dropped_frames},
  };
  write_text_atomic(d.root / kManifest, manifest.dump(1));
}

std::vector<size_t> evenly_spaced_indices(size_t total, int count) {
  std::vector<size_t> picked;
  if (count <= 0 || static_cast<size_t>(count) >= total) {
    for (size_t i = 0; i < total; ++i) picked.push_back(i);
    return picked;
  }
  for (int i = 0; i < count; ++i) picked.push_back(static_cast<size_t>((i + 0.5) * total / count));
  return picked;
}

std::vector<std::string> spread_test_cameras(const Rig& rig, int count) {
  const int n = static_cast<int>(rig.cameras.size());
  if (n == 0) return {};
  const int held_out = n == 1 ? 1 : std::clamp(count, 1, n - 1);
  std::vector<std::string> names;
  for (int i = 0; i < held_out; ++i) names.push_back(rig.cameras[(n - 1) - i * (n / held_out) % n].name);
  return names;
}

}  // namespace tega
