// Calibration: per-camera RMS from the rig's report (rig.report.json), and in
// the virtual studio each camera against the studio's true rig.

#include <Eigen/Geometry>
#include <cmath>
#include <nlohmann/json.hpp>

#include "plot.h"
#include "report_context.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/rig.h"

namespace tega::report {
namespace fs = std::filesystem;

namespace {

// The CI bounds of docs/calibration.md#accuracy-and-speed (40 rendered poses):
// the stage states no other target.
constexpr double kCentreTargetMm = 1.0, kRotationTargetDeg = 0.5, kFocalTargetPercent = 0.2;

double rotation_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a * b.transpose()).angle() * 180 / M_PI;
}

// Each camera of `calibrated` against the same camera of `truth`. The two
// worlds are tied by the first camera (the calibration's default world), as
// the calibration's own tests and bench do.
void score_rig(const std::string& stage, const Rig& calibrated, const Rig& truth, const fs::path& rig_file,
               Section& section, ReportContext& context) {
  if (calibrated.cameras.empty() || truth.cameras.empty()) throw Error(rig_file, "has no cameras");
  const RigidTransform truth_to_calibrated =
      calibrated.cameras[0].world_to_camera.inverse() * truth.cameras[0].world_to_camera;
  Table table{{"camera", "focal error %", "principal point px", "centre mm", "rotation deg"}, {}};
  double worst_focal = 0, worst_principal = 0, worst_centre = 0, worst_rotation = 0;
  for (const Camera& want : truth.cameras) {
    if (!calibrated.contains(want.name)) throw Error(rig_file, "has no camera '" + want.name + "' of the studio's rig");
    const Camera& got = calibrated.camera(want.name);
    const RigidTransform want_pose = want.world_to_camera * truth_to_calibrated.inverse();
    const double focal =
        100 * std::max(std::abs(got.K(0, 0) / want.K(0, 0) - 1), std::abs(got.K(1, 1) / want.K(1, 1) - 1));
    const double principal = (got.K.block<2, 1>(0, 2) - want.K.block<2, 1>(0, 2)).norm();
    const Eigen::Vector3d want_centre = -want_pose.R.transpose() * want_pose.t;
    const double centre = 1000 * (got.center() - want_centre).norm();
    const double rotation = rotation_deg(got.world_to_camera.R, want_pose.R);
    table.rows.push_back({want.name, fixed(focal, 3), fixed(principal, 2), fixed(centre, 2), fixed(rotation, 3)});
    worst_focal = std::max(worst_focal, focal), worst_principal = std::max(worst_principal, principal);
    worst_centre = std::max(worst_centre, centre), worst_rotation = std::max(worst_rotation, rotation);
  }
  section.text("Against the virtual studio's true rig (the worlds tied by the first camera):");
  section.table(std::move(table));
  context.scores.push_back({stage, "worst focal length error", fixed(worst_focal, 3) + " %",
                            "< " + fixed(kFocalTargetPercent, 1) + " % (CI bound)",
                            verdict(worst_focal < kFocalTargetPercent)});
  context.scores.push_back({stage, "worst principal point error", fixed(worst_principal, 2) + " px", "", ""});
  context.scores.push_back({stage, "worst camera centre error", fixed(worst_centre, 2) + " mm",
                            "< " + fixed(kCentreTargetMm, 0) + " mm (CI bound)",
                            verdict(worst_centre < kCentreTargetMm)});
  context.scores.push_back({stage, "worst rotation error", fixed(worst_rotation, 3) + " deg",
                            "< " + fixed(kRotationTargetDeg, 1) + " deg (CI bound)",
                            verdict(worst_rotation < kRotationTargetDeg)});
}

}  // namespace

Section calibration_section(const StageOutput& stage, ReportContext& context) {
  Section section{"Calibration", {}};
  const fs::path rig_file = artifact(stage, "rig");
  const fs::path report_file = rig_file.parent_path() / (rig_file.stem().string() + ".report.json");
  nlohmann::json report;
  try {
    report = nlohmann::json::parse(read_text_file(report_file));
    Table table{{"camera", "views", "corners", "outliers", "RMS px", "coverage %"}, {}};
    BarChart chart{"reprojection RMS per camera, px", {}, {}};
    for (const auto& camera : report.at("cameras")) {
      const std::string name = camera.at("name");
      const double rms = camera.at("rms_px");
      table.rows.push_back({name, std::to_string(camera.at("views").get<int>()),
                            std::to_string(camera.at("corners").get<int>()),
                            std::to_string(camera.at("outliers").get<int>()), fixed(rms, 3),
                            fixed(100 * camera.at("coverage").get<double>(), 0)});
      chart.labels.push_back(name);
      chart.values.push_back(rms);
    }
    section.text("Rig " + context.link(rig_file) + ": " + std::to_string(chart.values.size()) + " cameras, total RMS " +
                 fixed(report.at("rms_px").get<double>(), 3) +
                 " px, world: " + report.value("world", std::string("?")) + ".");
    section.table(std::move(table));
    context.add_figure(section, "calibration_rms.png", draw_bar_chart(chart), "Reprojection RMS per camera");
    if (!report.at("cameras").empty()) {
      const fs::path residuals = report_file.parent_path() / report.at("cameras")[0].value("plot", "");
      if (fs::is_regular_file(residuals))
        section.image(context.link(residuals), "Reprojection errors of " +
                                                   report.at("cameras")[0].at("name").get<std::string>() +
                                                   " (every camera's: " + context.link(residuals.parent_path()) + "/)");
    }
  } catch (const nlohmann::json::exception& e) {
    throw Error(report_file, std::string("is not a calibration report: ") + e.what());
  }
  if (context.scoring()) {
    try {
      score_rig(stage.stage, read_rig_json(rig_file), read_rig_json(context.subject.truth / "rig.json"), rig_file,
                section, context);
    } catch (const std::exception& e) {
      context.score_errors.push_back(stage.stage + ": " + e.what());
    }
  }
  return section;
}

}  // namespace tega::report
