#include "tega/ingest/matte.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "tega/core/error.h"

namespace tega::ingest {
namespace {

// Exact squared Euclidean distance transform along one line (Felzenszwalb and
// Huttenlocher's lower envelope of parabolas): out[q] = min_p (q - p)^2 + f[p].
void distance_transform_1d(const std::vector<double>& f, std::vector<double>& out) {
  const int n = static_cast<int>(f.size());
  std::vector<int> v(n);          // parabolas of the lower envelope
  std::vector<double> z(n + 1);   // where each starts to be the lowest
  const auto intersection = [&](int q, int p) {
    return ((f[q] + double(q) * q) - (f[p] + double(p) * p)) / (2.0 * (q - p));
  };
  int k = 0;
  v[0] = 0;
  z[0] = -std::numeric_limits<double>::infinity();
  z[1] = std::numeric_limits<double>::infinity();
  for (int q = 1; q < n; ++q) {
    double s = intersection(q, v[k]);
    while (s <= z[k]) s = intersection(q, v[--k]);
    v[++k] = q;
    z[k] = s;
    z[k + 1] = std::numeric_limits<double>::infinity();
  }
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (z[k + 1] < q) ++k;
    const double d = q - v[k];
    out[q] = d * d + f[v[k]];
  }
}

}  // namespace

Image8 soft_dilate(const Image8& silhouette, double dilation_px, double feather_px) {
  const int w = silhouette.width, h = silhouette.height;
  // Squared distance to the nearest silhouette pixel: columns, then rows.
  constexpr double kFar = 1e20;
  std::vector<double> squared(static_cast<size_t>(w) * h);
  std::vector<double> line, out;
  line.resize(h);
  out.resize(h);
  for (int x = 0; x < w; ++x) {
    for (int y = 0; y < h; ++y) line[y] = silhouette.at(x, y, 0) ? 0.0 : kFar;
    distance_transform_1d(line, out);
    for (int y = 0; y < h; ++y) squared[static_cast<size_t>(y) * w + x] = out[y];
  }
  line.resize(w);
  out.resize(w);
  Image8 alpha(w, h, 1, 0);
  for (int y = 0; y < h; ++y) {
    std::copy_n(squared.begin() + static_cast<size_t>(y) * w, w, line.begin());
    distance_transform_1d(line, out);
    for (int x = 0; x < w; ++x) {
      const double beyond = std::sqrt(out[x]) - dilation_px;
      const double a = beyond <= 0 ? 1.0 : feather_px > 0 ? std::max(0.0, 1.0 - beyond / feather_px) : 0.0;
      alpha.at(x, y, 0) = static_cast<uint8_t>(std::lround(255 * a));
    }
  }
  return alpha;
}

}  // namespace tega::ingest
