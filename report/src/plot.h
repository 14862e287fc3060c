#pragma once
// Simple plots for the report, drawn with OpenCV in the style of tracking's
// residual plot (tracking/src/report.cpp): panels of lines over a shared x,
// and bars with an optional target line.

#include <limits>
#include <string>
#include <vector>

#include "tega/core/image.h"

namespace tega::report {

struct LineSeries {
  std::string label;
  std::vector<double> x, y;  // non-finite y values leave a gap
};

struct LinePanel {
  std::string title;  // with the unit: "loss", "PSNR, dB"
  std::vector<LineSeries> series;
};

// Panels stacked top to bottom, each `panel_height` pixels, all over `x_label`.
Image8 draw_line_panels(const std::vector<LinePanel>& panels, const std::string& x_label, int width = 960,
                        int panel_height = 220);

struct BarChart {
  std::string title;  // with the unit
  std::vector<std::string> labels;
  std::vector<double> values;
  double target = std::numeric_limits<double>::quiet_NaN();  // drawn as a dashed line when finite
};

Image8 draw_bar_chart(const BarChart& chart, int width = 960, int height = 300);

}  // namespace tega::report
