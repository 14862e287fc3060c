#include "report.h"

#include <algorithm>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "tega/core/image.h"
#include "tega/core/mesh.h"
#include "tega/core/take_images.h"
#include "tega/core/thread_pool.h"

namespace tega::tracking {
namespace fs = std::filesystem;

namespace {

struct Series {
  std::string label;
  cv::Scalar colour;
  std::vector<double> values;  // per record; < 0 where absent
};

// One panel: frames along x, the series' values along y from 0 to their maximum.
void draw_panel(cv::Mat& canvas, cv::Rect area, const std::string& title, const std::vector<Series>& series,
                const std::vector<FrameRecord>& records) {
  cv::rectangle(canvas, area, cv::Scalar(0, 0, 0), 1);
  double top = 0;
  for (const auto& s : series)
    for (double v : s.values) top = std::max(top, v);
  top = top > 0 ? top * 1.1 : 1;
  const int n = int(records.size());
  const auto x_of = [&](int i) { return area.x + (n > 1 ? i * (area.width - 1) / (n - 1) : area.width / 2); };
  const auto y_of = [&](double v) { return area.y + area.height - 1 - int(v / top * (area.height - 1)); };
  for (int i = 0; i < n; ++i)
    if (records[size_t(i)].status != "tracked")  // failed and skipped frames in grey
      cv::line(canvas, {x_of(i), area.y}, {x_of(i), area.y + area.height - 1}, cv::Scalar(200, 200, 200), 3);
  int legend_y = area.y + 18;
  for (const auto& s : series) {
    for (int i = 1; i < n; ++i) {
      const double a = s.values[size_t(i - 1)], b = s.values[size_t(i)];
      if (a >= 0 && b >= 0) cv::line(canvas, {x_of(i - 1), y_of(a)}, {x_of(i), y_of(b)}, s.colour, 2, cv::LINE_AA);
    }
    for (int i = 0; i < n; ++i)
      if (s.values[size_t(i)] >= 0) cv::circle(canvas, {x_of(i), y_of(s.values[size_t(i)])}, 2, s.colour, -1);
    cv::putText(canvas, s.label, {area.x + area.width - 230, legend_y}, cv::FONT_HERSHEY_SIMPLEX, 0.45, s.colour, 1,
                cv::LINE_AA);
    legend_y += 18;
  }
  char scale[64];
  std::snprintf(scale, sizeof scale, "%s (0 to %.3g)", title.c_str(), top);
  cv::putText(canvas, scale, {area.x + 6, area.y + 18}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1,
              cv::LINE_AA);
  char frames[64];
  std::snprintf(frames, sizeof frames, "frames %d to %d", n ? records.front().frame : 0, n ? records.back().frame : 0);
  cv::putText(canvas, frames, {area.x, area.y + area.height + 16}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1,
              cv::LINE_AA);
}

void write_png(const cv::Mat& bgr, const fs::path& file) {
  Image8 image(bgr.cols, bgr.rows, 3);
  cv::Mat rgb(bgr.rows, bgr.cols, CV_8UC3, image.pixels.data());
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  write_image(image, file);
}

void write_residual_plot(const std::vector<FrameRecord>& records, const fs::path& file) {
  const auto series = [&](const char* label, cv::Scalar colour, auto value) {
    Series s{label, colour, {}};
    for (const auto& r : records) s.values.push_back(r.status == "skipped" ? -1.0 : value(r.residuals));
    return s;
  };
  cv::Mat canvas(620, 960, CV_8UC3, cv::Scalar(255, 255, 255));
  draw_panel(canvas, {50, 20, 880, 250}, "scan distance, mm",
             {series("median", cv::Scalar(200, 80, 0), [](const FrameResiduals& r) { return 1000 * r.surface_median_m; }),
              series("90th percentile", cv::Scalar(0, 120, 220), [](const FrameResiduals& r) { return 1000 * r.surface_p90_m; }),
              series("share of face on scan", cv::Scalar(0, 150, 0), [](const FrameResiduals& r) { return r.inlier_fraction; })},
             records);
  draw_panel(canvas, {50, 330, 880, 250}, "image terms, px rms",
             {series("flow", cv::Scalar(160, 0, 160), [](const FrameResiduals& r) { return r.flow_rms_px; }),
              series("landmarks", cv::Scalar(0, 0, 200), [](const FrameResiduals& r) { return r.landmark_rms_px; })},
             records);
  write_png(canvas, file);
}

// The camera whose view of the head at `pose` is most frontal.
size_t frontal_camera(const std::vector<Camera>& cameras, const RigidTransform& head_to_world) {
  const Eigen::Vector3d forward = head_to_world.R.col(2);
  size_t best = 0;
  double best_cosine = -2;
  for (size_t c = 0; c < cameras.size(); ++c) {
    const double cosine = (cameras[c].center() - head_to_world.t).normalized().dot(forward);
    if (cosine > best_cosine) best_cosine = cosine, best = c;
  }
  return best;
}

// The skin's triangles that face the camera, as lines over the photo.
void draw_overlay(const TakeInfo& take, const Camera& camera, size_t camera_index, const FrameRecord& record,
                  const HeadModel& model, const fs::path& take_dir, const fs::path& file) {
  if (!take.has_image(take.cameras[camera_index], record.frame)) return;
  Image8 photo = read_recorded_rgb(take, take.cameras[camera_index], record.frame);
  char name[32];
  std::snprintf(name, sizeof name, "%06d.bin", record.frame);
  const Vertices world = read_vertices_bin(take_dir / name, model.num_vertices());
  std::vector<char> skin(size_t(model.num_vertices()), 0);
  for (int v : model.skin_vertices) skin[size_t(v)] = 1;
  cv::Mat rgb(photo.height, photo.width, CV_8UC3, photo.pixels.data());
  cv::Mat lines = rgb.clone();
  const Triangles& faces = model.shapes.neutral.faces;
  const Eigen::Vector3d eye = camera.center();
  for (int f = 0; f < faces.rows(); ++f) {
    if (!skin[size_t(faces(f, 0))] || !skin[size_t(faces(f, 1))] || !skin[size_t(faces(f, 2))]) continue;
    Eigen::Vector3d p[3];
    for (int k = 0; k < 3; ++k) p[k] = world.row(faces(f, k)).cast<double>().transpose();
    if ((p[1] - p[0]).cross(p[2] - p[0]).dot(eye - p[0]) <= 0) continue;
    cv::Point q[3];
    bool in_front = true;
    for (int k = 0; k < 3; ++k) {
      const auto pixel = camera.project(p[k]);
      if (!pixel) in_front = false;
      else q[k] = cv::Point(int(std::lround(pixel->x())), int(std::lround(pixel->y())));
    }
    if (!in_front) continue;
    for (int k = 0; k < 3; ++k) cv::line(lines, q[k], q[(k + 1) % 3], cv::Scalar(40, 255, 40), 1, cv::LINE_AA);
  }
  cv::addWeighted(lines, 0.55, rgb, 0.45, 0, rgb);
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  write_png(bgr, file);
}

}  // namespace

void write_take_report(const fs::path& report_dir, const std::vector<FrameRecord>& records, const TakeInfo& take,
                       const std::vector<Camera>& cameras, const HeadModel& model, int overlays, ThreadPool& pool) {
  fs::create_directories(report_dir);
  write_residual_plot(records, report_dir / "residuals.png");
  std::vector<const FrameRecord*> tracked;
  for (const auto& r : records)
    if (r.status == "tracked") tracked.push_back(&r);
  if (tracked.empty() || overlays <= 0) return;
  std::vector<const FrameRecord*> chosen;
  const int count = std::min<int>(overlays, int(tracked.size()));
  for (int i = 0; i < count; ++i)
    chosen.push_back(tracked[size_t(count > 1 ? i * (int(tracked.size()) - 1) / (count - 1) : 0)]);
  pool.parallel_for(0, int64_t(chosen.size()), [&](int64_t i) {
    const FrameRecord& r = *chosen[size_t(i)];
    const size_t c = frontal_camera(cameras, r.state.head_to_world);
    char name[64];
    std::snprintf(name, sizeof name, "overlay_%06d_%s.png", r.frame, take.cameras[c].c_str());
    draw_overlay(take, cameras[c], c, r, model, report_dir.parent_path(), report_dir / name);
  });
}

}  // namespace tega::tracking
