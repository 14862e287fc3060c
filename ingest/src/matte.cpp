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

Image8 mesh_silhouette(const Camera& camera, const Vertices& world, const Triangles& faces) {
  Image8 mask(camera.width, camera.height, 1, 0);
  std::vector<Eigen::Vector2d> pixel(world.rows());
  std::vector<bool> in_front(world.rows());
  for (Eigen::Index i = 0; i < world.rows(); ++i) {
    const Eigen::Vector3d c = camera.world_to_camera.apply(world.row(i).transpose().cast<double>());
    in_front[i] = c.z() > 0;
    if (in_front[i]) pixel[i] = (camera.K * (c / c.z())).head<2>();
  }
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    const int a = faces(f, 0), b = faces(f, 1), c = faces(f, 2);
    if (!in_front[a] || !in_front[b] || !in_front[c]) continue;
    const Eigen::Vector2d &pa = pixel[a], &pb = pixel[b], &pc = pixel[c];
    const double area = (pb - pa).x() * (pc - pa).y() - (pb - pa).y() * (pc - pa).x();
    if (area == 0) continue;
    const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({pa.x(), pb.x(), pc.x()}))));
    const int x1 = std::min(camera.width - 1, static_cast<int>(std::floor(std::max({pa.x(), pb.x(), pc.x()}))));
    const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({pa.y(), pb.y(), pc.y()}))));
    const int y1 = std::min(camera.height - 1, static_cast<int>(std::floor(std::max({pa.y(), pb.y(), pc.y()}))));
    // Either winding: a pixel centre is inside when all three edge functions
    // have the sign of the area.
    const auto edge = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q, double x, double y) {
      return (q.x() - p.x()) * (y - p.y()) - (q.y() - p.y()) * (x - p.x());
    };
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const double e0 = edge(pa, pb, x, y) * area, e1 = edge(pb, pc, x, y) * area, e2 = edge(pc, pa, x, y) * area;
        if (e0 >= 0 && e1 >= 0 && e2 >= 0) mask.at(x, y, 0) = 255;
      }
    }
  }
  return mask;
}

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

Image8 box_downsample(const Image8& image, int factor) {
  if (factor < 1 || image.width % factor != 0 || image.height % factor != 0) {
    throw Error("downsample " + std::to_string(factor) + " does not divide the image size " +
                std::to_string(image.width) + "x" + std::to_string(image.height));
  }
  if (factor == 1) return image;
  Image8 out(image.width / factor, image.height / factor, image.channels);
  const int area = factor * factor;
  for (int y = 0; y < out.height; ++y) {
    for (int x = 0; x < out.width; ++x) {
      for (int c = 0; c < image.channels; ++c) {
        int sum = 0;
        for (int dy = 0; dy < factor; ++dy)
          for (int dx = 0; dx < factor; ++dx) sum += image.at(x * factor + dx, y * factor + dy, c);
        out.at(x, y, c) = static_cast<uint8_t>((sum + area / 2) / area);
      }
    }
  }
  return out;
}

}  // namespace tega::ingest
