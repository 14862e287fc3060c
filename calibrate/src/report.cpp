#include "tega/calibrate/report.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "tega/core/files.h"
#include "tega/core/image.h"
#include "tega/core/rig.h"

namespace tega::calibrate {

namespace fs = std::filesystem;

namespace {

constexpr int kPlotWidth = 800;
constexpr double kLongestArrowPx = 40;  // the largest residual's arrow on the plot

fs::path beside(const fs::path& rig_file, const std::string& suffix) {
  return rig_file.parent_path() / (rig_file.stem().string() + suffix);
}

void draw_line(Image8& image, Eigen::Vector2d a, Eigen::Vector2d b, const std::array<uint8_t, 3>& colour) {
  const int steps = std::max(1, int(std::ceil((b - a).cwiseAbs().maxCoeff())));
  for (int i = 0; i <= steps; ++i) {
    const Eigen::Vector2d p = a + (b - a) * (double(i) / steps);
    const int x = int(std::lround(p.x())), y = int(std::lround(p.y()));
    if (x < 0 || y < 0 || x >= image.width || y >= image.height) continue;
    for (int c = 0; c < 3; ++c) image.at(x, y, c) = colour[c];
  }
}

// Returns the magnification used.
double plot_residuals(const CameraReport& camera, int width, int height, const fs::path& file) {
  const double scale = std::min(1.0, double(kPlotWidth) / width);
  Image8 plot(std::max(1, int(width * scale)), std::max(1, int(height * scale)), 3, 255);
  double largest = 1e-9;
  for (const auto& r : camera.residuals) largest = std::max(largest, r.residual.norm());
  const double magnify = kLongestArrowPx / largest;
  for (const auto& r : camera.residuals) {
    const Eigen::Vector2d from = r.pixel * scale;
    const Eigen::Vector2d to = from + r.residual * magnify;
    draw_line(plot, from, to, r.outlier ? std::array<uint8_t, 3>{220, 30, 30} : std::array<uint8_t, 3>{30, 60, 200});
    draw_line(plot, from - Eigen::Vector2d(1, 0), from + Eigen::Vector2d(1, 0), {0, 0, 0});
    draw_line(plot, from - Eigen::Vector2d(0, 1), from + Eigen::Vector2d(0, 1), {0, 0, 0});
  }
  write_image(plot, file);
  return magnify;
}

}  // namespace

void write_calibration(const Calibration& calibration, const fs::path& rig_file) {
  const Rig& rig = calibration.rig;
  if (!rig_file.parent_path().empty()) fs::create_directories(rig_file.parent_path());
  write_colmap_text(rig, beside(rig_file, ".colmap"));
  write_krt(rig, beside(rig_file, ".krt"));
  const fs::path plots = beside(rig_file, ".residuals");
  fs::create_directories(plots);

  nlohmann::json cameras = nlohmann::json::array();
  for (size_t c = 0; c < calibration.cameras.size(); ++c) {
    const auto& r = calibration.cameras[c];
    const Camera& camera = rig.cameras[c];
    const double magnify = plot_residuals(r, camera.width, camera.height, plots / (r.name + ".png"));
    nlohmann::json j = {{"name", r.name},         {"views", r.views},        {"corners", r.corners},
                        {"outliers", r.outliers}, {"rms_px", r.rms_px},      {"coverage", r.coverage},
                        {"plot", (plots.filename() / (r.name + ".png")).string()},
                        {"plot_magnification", magnify}};
    if (r.moved_mm) j["moved_mm"] = *r.moved_mm;
    if (r.rotated_deg) j["rotated_deg"] = *r.rotated_deg;
    cameras.push_back(j);
  }
  nlohmann::json boards = nlohmann::json::array();
  for (const auto& [frame, pose] : calibration.board_to_world) {
    nlohmann::json rows = nlohmann::json::array();
    for (int r = 0; r < 3; ++r) rows.push_back({pose.R(r, 0), pose.R(r, 1), pose.R(r, 2), pose.t(r)});
    boards.push_back({{"frame", frame}, {"board_to_world", rows}});
  }
  const nlohmann::json report = {{"format", "tega-calibration-report"},
                                 {"version", 1},
                                 {"rig", rig_file.filename().string()},
                                 {"world", calibration.world},
                                 {"rms_px", calibration.rms_px},
                                 {"outliers", calibration.outliers},
                                 {"seconds", calibration.seconds},
                                 {"cameras", cameras},
                                 {"boards", boards}};
  write_text_atomic(beside(rig_file, ".report.json"), report.dump(2) + "\n");
  write_rig_json(rig, rig_file);  // last: its presence means the calibration is complete
}

std::string calibration_summary(const Calibration& calibration) {
  std::string text;
  char line[256];
  std::snprintf(line, sizeof line, "%-10s %6s %8s %9s %9s %9s %10s %9s\n", "camera", "views", "corners", "outliers",
                "rms px", "coverage", "moved mm", "turn deg");
  text += line;
  for (const auto& r : calibration.cameras) {
    std::snprintf(line, sizeof line, "%-10s %6d %8d %9d %9.3f %8.0f%% %10s %9s\n", r.name.c_str(), r.views, r.corners,
                  r.outliers, r.rms_px, 100 * r.coverage,
                  r.moved_mm ? std::to_string(*r.moved_mm).substr(0, 6).c_str() : "-",
                  r.rotated_deg ? std::to_string(*r.rotated_deg).substr(0, 6).c_str() : "-");
    text += line;
  }
  std::snprintf(line, sizeof line, "rms %.3f px over all cameras, %d outliers removed, world: %s, %.1f s\n",
                calibration.rms_px, calibration.outliers, calibration.world.c_str(), calibration.seconds);
  return text + line;
}

}  // namespace tega::calibrate
