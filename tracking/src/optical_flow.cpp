#include "optical_flow.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "tega/core/error.h"

namespace tega::tracking {

struct FlowField::Fields {
  cv::Mat forward, backward;  // CV_32FC2, at the reduced size
  double scale = 1;           // reduced / full
  int width = 0, height = 0;  // full size
};

namespace {

cv::Mat grey_at_scale(const Image8& image, double scale) {
  const cv::Mat view(image.height, image.width, CV_8UC(image.channels), const_cast<uint8_t*>(image.pixels.data()));
  cv::Mat grey;
  if (image.channels == 3)
    cv::cvtColor(view, grey, cv::COLOR_RGB2GRAY);
  else if (image.channels == 1)
    grey = view;
  else
    throw Error("optical flow: expected an RGB or grey photo, got " + std::to_string(image.channels) + " channels");
  if (scale >= 1) return grey.clone();
  cv::Mat reduced;
  cv::resize(grey, reduced, cv::Size(), scale, scale, cv::INTER_AREA);
  return reduced;
}

Eigen::Vector2d sample(const cv::Mat& flow, double x, double y) {
  const int x0 = std::clamp(int(std::floor(x)), 0, flow.cols - 2), y0 = std::clamp(int(std::floor(y)), 0, flow.rows - 2);
  const double fx = std::clamp(x - x0, 0.0, 1.0), fy = std::clamp(y - y0, 0.0, 1.0);
  const auto at = [&](int yy, int xx) {
    const cv::Vec2f v = flow.at<cv::Vec2f>(yy, xx);
    return Eigen::Vector2d(v[0], v[1]);
  };
  return (1 - fy) * ((1 - fx) * at(y0, x0) + fx * at(y0, x0 + 1)) + fy * ((1 - fx) * at(y0 + 1, x0) + fx * at(y0 + 1, x0 + 1));
}

}  // namespace

FlowField::FlowField(const Image8& from, const Image8& to, double max_side) : fields_(std::make_unique<Fields>()) {
  if (from.width != to.width || from.height != to.height)
    throw Error("optical flow: consecutive photos of a camera differ in size (" + std::to_string(from.width) + "x" +
                std::to_string(from.height) + " and " + std::to_string(to.width) + "x" + std::to_string(to.height) + ")");
  fields_->width = from.width;
  fields_->height = from.height;
  fields_->scale = std::min(1.0, max_side / std::max(from.width, from.height));
  const cv::Mat a = grey_at_scale(from, fields_->scale), b = grey_at_scale(to, fields_->scale);
  auto dis = cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_MEDIUM);
  dis->calc(a, b, fields_->forward);
  dis->calc(b, a, fields_->backward);
}

FlowField::~FlowField() = default;
FlowField::FlowField(FlowField&&) noexcept = default;

std::optional<Eigen::Vector2d> FlowField::follow(const Eigen::Vector2d& pixel, double max_round_trip_px) const {
  const Fields& f = *fields_;
  if (pixel.x() < 0 || pixel.y() < 0 || pixel.x() > f.width - 1 || pixel.y() > f.height - 1) return std::nullopt;
  // Pixel centres: full-size x maps to scale (x + 0.5) - 0.5.
  const Eigen::Vector2d reduced = f.scale * (pixel.array() + 0.5).matrix() - Eigen::Vector2d::Constant(0.5);
  const Eigen::Vector2d moved = reduced + sample(f.forward, reduced.x(), reduced.y());
  if (moved.x() < 0 || moved.y() < 0 || moved.x() > f.forward.cols - 1 || moved.y() > f.forward.rows - 1)
    return std::nullopt;
  const Eigen::Vector2d back = moved + sample(f.backward, moved.x(), moved.y());
  if ((back - reduced).norm() / f.scale > max_round_trip_px) return std::nullopt;
  return ((moved.array() + 0.5) / f.scale - 0.5).matrix();
}

}  // namespace tega::tracking
