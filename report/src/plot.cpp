#include "plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "image_conversion.h"

namespace tega::report {
namespace {

const cv::Scalar kBlack(0, 0, 0), kGrid(225, 225, 225);

cv::Scalar colour(size_t i) {
  static const cv::Scalar palette[] = {{200, 80, 0}, {0, 120, 220}, {0, 150, 0}, {160, 0, 160}, {0, 0, 200}};
  return palette[i % std::size(palette)];
}

void label(cv::Mat& canvas, const std::string& text, cv::Point at, double scale = 0.45, const cv::Scalar& c = kBlack) {
  cv::putText(canvas, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, c, 1, cv::LINE_AA);
}

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", v);
  return text;
}

// The value range of a panel, padded so that lines do not run along the frame.
std::pair<double, double> padded_range(double low, double high) {
  if (!std::isfinite(low) || !std::isfinite(high)) return {0, 1};
  if (high - low < 1e-12)
    return {low - 0.5 * std::max(1.0, std::abs(low)) * 0.1, high + 0.5 * std::max(1.0, std::abs(high)) * 0.1};
  const double pad = 0.05 * (high - low);
  return {low - pad, high + pad};
}

void draw_line_panel(cv::Mat& canvas, cv::Rect area, const LinePanel& panel, double x_low, double x_high) {
  double low = INFINITY, high = -INFINITY;
  for (const auto& s : panel.series)
    for (double v : s.y)
      if (std::isfinite(v)) low = std::min(low, v), high = std::max(high, v);
  const auto [y_low, y_high] = padded_range(low, high);
  const double x_span = x_high > x_low ? x_high - x_low : 1;
  const auto px = [&](double x) { return area.x + int(std::lround((x - x_low) / x_span * (area.width - 1))); };
  const auto py = [&](double y) {
    return area.y + area.height - 1 - int(std::lround((y - y_low) / (y_high - y_low) * (area.height - 1)));
  };
  for (int k = 1; k < 4; ++k) {
    const int y = area.y + k * area.height / 4;
    cv::line(canvas, {area.x, y}, {area.x + area.width - 1, y}, kGrid, 1);
  }
  cv::rectangle(canvas, area, kBlack, 1);
  int legend_y = area.y + 18;
  for (size_t i = 0; i < panel.series.size(); ++i) {
    const auto& s = panel.series[i];
    const size_t n = std::min(s.x.size(), s.y.size());
    for (size_t k = 0; k < n; ++k) {
      if (!std::isfinite(s.y[k])) continue;
      if (k > 0 && std::isfinite(s.y[k - 1]))
        cv::line(canvas, {px(s.x[k - 1]), py(s.y[k - 1])}, {px(s.x[k]), py(s.y[k])}, colour(i), 2, cv::LINE_AA);
      if (n <= 60) cv::circle(canvas, {px(s.x[k]), py(s.y[k])}, 2, colour(i), -1);
    }
    label(canvas, s.label, {area.x + area.width - 230, legend_y}, 0.45, colour(i));
    legend_y += 18;
  }
  label(canvas, panel.title + " (" + number(y_low) + " to " + number(y_high) + ")", {area.x, area.y - 6}, 0.5);
}

}  // namespace

Image8 draw_line_panels(const std::vector<LinePanel>& panels, const std::string& x_label, int width, int panel_height) {
  double x_low = INFINITY, x_high = -INFINITY;
  for (const auto& p : panels)
    for (const auto& s : p.series)
      for (double x : s.x) x_low = std::min(x_low, x), x_high = std::max(x_high, x);
  if (!std::isfinite(x_low)) x_low = 0, x_high = 1;
  const int gap = 40;
  cv::Mat canvas(int(panels.size()) * (panel_height + gap) + 30, width, CV_8UC3, cv::Scalar(255, 255, 255));
  for (size_t i = 0; i < panels.size(); ++i)
    draw_line_panel(canvas, {50, 20 + int(i) * (panel_height + gap), width - 80, panel_height}, panels[i], x_low,
                    x_high);
  label(canvas, x_label + " " + number(x_low) + " to " + number(x_high), {50, canvas.rows - 12});
  return image_of(canvas);
}

Image8 draw_bar_chart(const BarChart& chart, int width, int height) {
  cv::Mat canvas(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const cv::Rect area(50, 30, width - 80, height - 80);
  double high = 0;
  for (double v : chart.values)
    if (std::isfinite(v)) high = std::max(high, v);
  if (std::isfinite(chart.target)) high = std::max(high, chart.target);
  high = high > 0 ? high * 1.15 : 1;
  const auto py = [&](double v) { return area.y + area.height - 1 - int(std::lround(v / high * (area.height - 1))); };
  cv::rectangle(canvas, area, kBlack, 1);
  const int n = int(chart.values.size());
  const int slot = n ? area.width / n : area.width;
  for (int i = 0; i < n; ++i) {
    const double v = chart.values[size_t(i)];
    const int x0 = area.x + i * slot + slot / 6, x1 = area.x + (i + 1) * slot - slot / 6;
    if (std::isfinite(v) && v > 0) cv::rectangle(canvas, {x0, py(v)}, {x1, area.y + area.height - 1}, colour(0), -1);
    if (std::isfinite(v)) label(canvas, number(v), {x0, py(std::max(v, 0.0)) - 4}, 0.4);
    const std::string& name = i < int(chart.labels.size()) ? chart.labels[size_t(i)] : std::string();
    label(canvas, name, {x0, area.y + area.height + 18}, 0.4);
  }
  if (std::isfinite(chart.target)) {
    const int y = py(chart.target);
    for (int x = area.x; x < area.x + area.width; x += 12)
      cv::line(canvas, {x, y}, {std::min(x + 6, area.x + area.width - 1), y}, {0, 0, 200}, 1);
    label(canvas, "target " + number(chart.target), {area.x + area.width - 120, y - 4}, 0.4, {0, 0, 200});
  }
  label(canvas, chart.title + " (0 to " + number(high) + ")", {area.x + 6, area.y - 10}, 0.5);
  return image_of(canvas);
}

}  // namespace tega::report
