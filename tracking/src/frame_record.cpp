#include "frame_record.h"

#include <nlohmann/json.hpp>

#include "tega/core/error.h"
#include "tega/core/mesh.h"
#include "tega/core/tracked.h"

namespace tega::tracking {
namespace fs = std::filesystem;

namespace {

nlohmann::json residuals_json(const FrameResiduals& r) {
  nlohmann::json j = {{"surface_median_mm", 1000 * r.surface_median_m},
                      {"surface_p90_mm", 1000 * r.surface_p90_m},
                      {"surface_capped_mean_mm", 1000 * r.surface_capped_mean_m},
                      {"inlier_fraction", r.inlier_fraction}};
  if (r.landmark_count > 0) j["landmark_rms_px"] = r.landmark_rms_px, j["landmarks"] = r.landmark_count;
  if (r.flow_count > 0) j["flow_rms_px"] = r.flow_rms_px, j["flow_points"] = r.flow_count;
  if (!r.eyelids_covered.empty()) j["eyelids_covered"] = r.eyelids_covered;
  return j;
}

FrameResiduals residuals_of(const nlohmann::json& j) {
  FrameResiduals r;
  r.surface_median_m = j.at("surface_median_mm").get<double>() / 1000;
  r.surface_p90_m = j.at("surface_p90_mm").get<double>() / 1000;
  r.surface_capped_mean_m = j.value("surface_capped_mean_mm", -1000.0) / 1000;  // -1: a record from before it
  r.inlier_fraction = j.at("inlier_fraction");
  r.landmark_rms_px = j.value("landmark_rms_px", -1.0);
  r.landmark_count = j.value("landmarks", 0);
  r.flow_rms_px = j.value("flow_rms_px", -1.0);
  r.flow_count = j.value("flow_points", 0);
  if (j.contains("eyelids_covered")) r.eyelids_covered = j.at("eyelids_covered").get<std::map<std::string, double>>();
  return r;
}

}  // namespace

void write_frame_record(const fs::path& take_dir, const FrameRecord& record, const Vertices* vertices,
                        const HeadModel& model) {
  TrackedFrame frame;
  frame.frame = record.frame;
  frame.status = record.status;
  frame.reason = record.reason;
  frame.fitted_afresh = record.fitted_afresh;
  frame.head_to_world = record.state.head_to_world;
  for (size_t k = 0; k < record.state.expression.size(); ++k)
    frame.expression[model.shapes.expression_names[k]] = record.state.expression[k];
  frame.residuals = residuals_json(record.residuals);
  write_tracked_frame(take_dir, frame, vertices);
}

std::optional<StoredFrame> read_frame_record(const fs::path& take_dir, int frame, const HeadModel& model,
                                             const SubjectIdentity* subject) {
  const fs::path file = tracked_frame_file(take_dir, frame, ".json");
  if (!fs::exists(file)) return std::nullopt;
  StoredFrame stored;
  FrameRecord& record = stored.record;
  const TrackedFrame tracked = read_tracked_frame(file);
  record.frame = tracked.frame;
  record.status = tracked.status;
  record.reason = tracked.reason;
  if (record.status != "skipped") {
    record.state.head_to_world = tracked.head_to_world;
    for (const auto& name : model.shapes.expression_names) {
      if (!tracked.expression.count(name))
        throw Error(file, "has no coefficient for expression " + name + " of the model " + model.directory.string());
      record.state.expression.push_back(tracked.expression.at(name));
    }
    try {
      record.residuals = residuals_of(tracked.residuals);
    } catch (const nlohmann::json::exception& e) {
      throw Error(file, std::string("is not a valid frame record: ") + e.what());
    }
    record.fitted_afresh = tracked.fitted_afresh;
  }
  stored.state = record.state;
  if (record.status == "tracked" && subject) {
    const Vertices world = read_vertices_bin(tracked_frame_file(take_dir, frame, ".bin"), model.num_vertices());
    HeadState shaped = record.state;
    shaped.corrections.resize(0, 3);
    const Vertices without = pose_vertices(model, *subject, shaped);
    const Eigen::Matrix3f Rt = record.state.head_to_world.R.transpose().cast<float>();
    stored.state.corrections = (world - without) * Rt.transpose();
  }
  return stored;
}

}  // namespace tega::tracking
