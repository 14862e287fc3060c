#include "tega/core/dataset_gaps.h"

#include <algorithm>
#include <map>
#include <set>
#include <sstream>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/log.h"

namespace tega {

namespace {

std::string number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

std::string plural(size_t n, const std::string& noun) { return std::to_string(n) + " " + noun + (n == 1 ? "" : "s"); }

std::string limit(const char* name, double value) { return "missing_images." + std::string(name) + " = " + number(value); }

bool contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

// The dataset's cameras: those of either split, each once.
std::vector<std::string> split_cameras(const Dataset& d) {
  std::vector<std::string> cameras = d.train.cameras;
  for (const auto& c : d.test.cameras)
    if (!contains(cameras, c)) cameras.push_back(c);
  return cameras;
}

// Frames whose usable cameras are too few move to dropped_frames.
void drop_frames(Dataset& d, const MissingImageLimits& limits) {
  const std::vector<std::string> cameras = split_cameras(d);
  std::map<std::string, std::vector<const MissingImage*>> missing_of;
  for (const auto& m : d.missing_images)
    if (contains(cameras, m.camera)) missing_of[m.frame].push_back(&m);
  std::set<std::string> dropped;
  for (const auto& frame : d.frames) {
    const auto it = missing_of.find(frame.id);
    if (it == missing_of.end()) continue;
    const size_t usable = cameras.size() - it->second.size();
    if (usable > 0 && static_cast<double>(usable) >= limits.min_camera_fraction_per_frame * cameras.size()) continue;
    d.dropped_frames.push_back({frame.id, "usable images from " + std::to_string(usable) + " of " +
                                              std::to_string(cameras.size()) + " cameras (" +
                                              limit("min_camera_fraction_per_frame",
                                                    limits.min_camera_fraction_per_frame) +
                                              "); first left out: camera " + it->second.front()->camera + ": " +
                                              it->second.front()->reason});
    dropped.insert(frame.id);
  }
  std::erase_if(d.frames, [&](const DatasetFrame& f) { return dropped.count(f.id) > 0; });
  std::erase_if(d.train.frames, [&](const std::string& f) { return dropped.count(f) > 0; });
  std::erase_if(d.test.frames, [&](const std::string& f) { return dropped.count(f) > 0; });
  std::erase_if(d.missing_images, [&](const MissingImage& m) { return dropped.count(m.frame) > 0; });
}

void check_dropped(const Dataset& d, const std::vector<std::string>& planned, const char* split,
                   const MissingImageLimits& limits, const std::filesystem::path& source, const std::string& remedy) {
  std::vector<const DroppedFrame*> dropped;
  for (const auto& f : d.dropped_frames)
    if (contains(planned, f.frame)) dropped.push_back(&f);
  if (dropped.empty()) return;
  const std::string first = "first: frame " + dropped.front()->frame + ", " + dropped.front()->reason;
  if (dropped.size() == planned.size())
    throw Error(source, std::string("every ") + split + " frame (" + std::to_string(planned.size()) +
                            ") lacks too many images to be kept, leaving nothing to " +
                            (std::string(split) == "train" ? "train on" : "test on") + " (" + first + "); " + remedy);
  if (static_cast<double>(dropped.size()) > limits.max_dropped_frame_fraction * planned.size())
    throw Error(source, std::to_string(dropped.size()) + " of " + std::to_string(planned.size()) + " " + split +
                            " frames lack too many images to be kept, more than " +
                            limit("max_dropped_frame_fraction", limits.max_dropped_frame_fraction) + " allows (" +
                            first + "); " + remedy + ", or raise missing_images.max_dropped_frame_fraction");
}

void check_cameras(const Dataset& d, const MissingImageLimits& limits, const std::filesystem::path& source,
                   const std::string& remedy) {
  for (const auto& camera : split_cameras(d)) {
    std::vector<const MissingImage*> missing;
    for (const auto& m : d.missing_images)
      if (m.camera == camera) missing.push_back(&m);
    if (missing.empty() ||
        static_cast<double>(missing.size()) <= limits.max_missing_fraction_per_camera * d.frames.size())
      continue;
    throw Error(source, "camera " + camera + " has no usable image of " + std::to_string(missing.size()) + " of the " +
                            std::to_string(d.frames.size()) + " frames, more than " +
                            limit("max_missing_fraction_per_camera", limits.max_missing_fraction_per_camera) +
                            " allows (first: frame " + missing.front()->frame + ", " + missing.front()->reason +
                            "); " + remedy + ", or raise missing_images.max_missing_fraction_per_camera");
  }
}

}  // namespace

void check_missing_image_limits(const MissingImageLimits& limits, const std::string& stage) {
  const auto check = [&](const char* name, double value) {
    if (!(value >= 0 && value <= 1)) throw Error(stage + " options: missing_images." + name + " must be in 0 .. 1");
  };
  check("min_camera_fraction_per_frame", limits.min_camera_fraction_per_frame);
  check("max_missing_fraction_per_camera", limits.max_missing_fraction_per_camera);
  check("max_dropped_frame_fraction", limits.max_dropped_frame_fraction);
}

void apply_missing_image_limits(Dataset& dataset, const MissingImageLimits& limits,
                                const std::filesystem::path& source, const std::string& remedy) {
  const std::vector<std::string> train = dataset.train.frames, test = dataset.test.frames;
  drop_frames(dataset, limits);
  check_dropped(dataset, train, "train", limits, source, remedy);
  check_dropped(dataset, test, "test", limits, source, remedy);
  check_cameras(dataset, limits, source, remedy);
}

void drop_frames_lacking_images(Dataset& dataset, const MissingImageLimits& limits,
                                const std::filesystem::path& source, const std::string& remedy,
                                const std::string& stage) {
  apply_missing_image_limits(dataset, limits, source, remedy);
  for (const DroppedFrame& dropped : dataset.dropped_frames) {
    logging::warn("%s: dropping frame %s: %s", stage.c_str(), dropped.frame.c_str(), dropped.reason.c_str());
    remove_tree(dataset.mesh_path(dropped.frame));
    for (const Camera& camera : dataset.rig.cameras) remove_tree(dataset.image_path(camera.name, dropped.frame));
  }
}

std::string dataset_gap_summary(const Dataset& dataset) {
  std::vector<std::string> parts;
  if (!dataset.missing_images.empty()) {
    std::map<std::string, int> per_camera;
    for (const auto& m : dataset.missing_images) ++per_camera[m.camera];
    std::string counts;
    for (const auto& [camera, n] : per_camera) counts += (counts.empty() ? "" : ", ") + camera + ": " + std::to_string(n);
    parts.push_back(plural(dataset.missing_images.size(), "missing image") + " (" + counts + ")");
  }
  if (!dataset.dropped_frames.empty()) parts.push_back(plural(dataset.dropped_frames.size(), "dropped frame"));
  std::string summary;
  for (const auto& p : parts) summary += (summary.empty() ? "" : ", ") + p;
  return summary;
}

}  // namespace tega
