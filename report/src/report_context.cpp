#include "report_context.h"

#include <cmath>
#include <cstdio>

#include "tega/core/error.h"
#include "tega/core/rig.h"

namespace tega::report {
namespace fs = std::filesystem;

std::string ReportContext::link(const fs::path& file) const {
  return fs::absolute(file)
      .lexically_normal()
      .lexically_relative(fs::absolute(page_dir).lexically_normal())
      .generic_string();
}

void ReportContext::add_figure(Section& section, std::string file, Image8 image, std::string caption) {
  section.image(file, std::move(caption));
  figures.push_back({std::move(file), std::move(image)});
}

std::string fixed(double value, int decimals) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

std::string verdict(bool met) { return met ? "met" : "missed"; }

std::vector<size_t> spread(size_t n, size_t count) {
  std::vector<size_t> out;
  if (n == 0 || count == 0) return out;
  if (count >= n) {
    for (size_t i = 0; i < n; ++i) out.push_back(i);
    return out;
  }
  if (count == 1) return {n / 2};
  for (size_t k = 0; k < count; ++k) out.push_back(k * (n - 1) / (count - 1));
  return out;
}

RigidTransform calibrated_to_truth_world(const SubjectOutputs& subject) {
  const StageOutput* calibrate = subject.first_of_kind("calibrate");
  if (!calibrate || !calibrate->committed) return {};
  const Rig calibrated = read_rig_json(artifact(*calibrate, "rig"));
  const Rig truth = read_rig_json(subject.truth / "rig.json");
  if (calibrated.cameras.empty() || truth.cameras.empty()) throw Error(artifact(*calibrate, "rig"), "has no cameras");
  int shared = 0;
  for (const Camera& camera : calibrated.cameras) shared += truth.contains(camera.name);
  if (shared < 3) return truth.cameras[0].world_to_camera.inverse() * calibrated.cameras[0].world_to_camera;
  try {
    return align_camera_centres(calibrated, truth);
  } catch (const Error& e) {
    throw Error(artifact(*calibrate, "rig"), std::string("cannot be tied to the studio's rig: ") + e.what());
  }
}

const fs::path& artifact(const StageOutput& stage, const std::string& name) {
  const auto it = stage.artifacts.find(name);
  if (it == stage.artifacts.end()) throw Error("stage " + stage.stage + " (" + stage.kind + ") provides no " + name);
  return it->second;
}

}  // namespace tega::report
