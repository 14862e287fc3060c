#include <algorithm>
#include <cmath>

#include "tega/core/error.h"
#include "tega/synth/rasterizer.h"

namespace tega::synth {
namespace {

constexpr int kTile = 16;             // output pixels per tile side
constexpr double kNearDepth = 0.01;   // metres; triangles reaching closer are dropped

struct ScreenTriangle {
  int surface, triangle;
  double x[3], y[3], inv_z[3];
  double area;  // signed, pixel units (twice the area)
  // Screen barycentrics of vertices 1 and 2 as affine functions of the pixel: l = a x + b y + c.
  double a1, b1, c1, a2, b2, c2;
  int x0, y0, x1, y1;  // pixel bounding box, inclusive, clipped to the image
};

struct Sample {
  float inv_z = 0;  // 0: empty
  int screen_triangle = -1;
  float l1 = 0, l2 = 0;  // screen-space barycentrics of vertices 1 and 2
};

}  // namespace

ImageF rasterize(const Camera& camera, const std::vector<Surface>& surfaces, int supersampling) {
  if (supersampling < 1) throw Error("supersampling must be at least 1");
  const int W = camera.width, H = camera.height, S = supersampling;

  // Project every vertex once and set up the visible front-facing triangles.
  std::vector<ScreenTriangle> tris;
  for (int s = 0; s < static_cast<int>(surfaces.size()); ++s) {
    const Surface& surf = surfaces[s];
    const Vertices& P = *surf.positions;
    std::vector<Eigen::Vector3d> screen(P.rows());  // x, y, 1/z (0 when unusable)
    for (int v = 0; v < P.rows(); ++v) {
      const Eigen::Vector3d world = P.row(v).cast<double>().transpose();
      const double z = camera.world_to_camera.apply(world).z();
      const auto pixel = z > kNearDepth ? camera.project(world) : std::nullopt;
      screen[v] = pixel ? Eigen::Vector3d(pixel->x(), pixel->y(), 1.0 / z) : Eigen::Vector3d::Zero();
    }
    const Triangles& F = *surf.faces;
    for (int f = 0; f < F.rows(); ++f) {
      ScreenTriangle t{};
      t.surface = s;
      t.triangle = f;
      bool usable = true;
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d& p = screen[F(f, k)];
        usable &= p.z() > 0;
        t.x[k] = p.x(), t.y[k] = p.y(), t.inv_z[k] = p.z();
      }
      if (!usable) continue;
      t.area = (t.x[1] - t.x[0]) * (t.y[2] - t.y[0]) - (t.x[2] - t.x[0]) * (t.y[1] - t.y[0]);
      // Pixel y points down, so a triangle the camera sees counter-clockwise has negative area.
      if (!(t.area < 0)) continue;
      t.a1 = (t.y[2] - t.y[0]) / t.area;
      t.b1 = -(t.x[2] - t.x[0]) / t.area;
      t.c1 = -(t.x[0] * t.a1 + t.y[0] * t.b1);
      t.a2 = -(t.y[1] - t.y[0]) / t.area;
      t.b2 = (t.x[1] - t.x[0]) / t.area;
      t.c2 = -(t.x[0] * t.a2 + t.y[0] * t.b2);
      t.x0 = std::max(0, static_cast<int>(std::floor(std::min({t.x[0], t.x[1], t.x[2]}) + 0.5)));
      t.y0 = std::max(0, static_cast<int>(std::floor(std::min({t.y[0], t.y[1], t.y[2]}) + 0.5)));
      t.x1 = std::min(W - 1, static_cast<int>(std::ceil(std::max({t.x[0], t.x[1], t.x[2]}) - 0.5)));
      t.y1 = std::min(H - 1, static_cast<int>(std::ceil(std::max({t.y[0], t.y[1], t.y[2]}) - 0.5)));
      if (t.x0 > t.x1 || t.y0 > t.y1) continue;
      tris.push_back(t);
    }
  }

  // Bin triangles to tiles (counting sort keeps the original order, which
  // makes depth ties resolve the same way every time).
  const int tiles_x = (W + kTile - 1) / kTile, tiles_y = (H + kTile - 1) / kTile;
  std::vector<int> tile_start(tiles_x * tiles_y + 1, 0);
  for (const auto& t : tris)
    for (int ty = t.y0 / kTile; ty <= t.y1 / kTile; ++ty)
      for (int tx = t.x0 / kTile; tx <= t.x1 / kTile; ++tx) ++tile_start[ty * tiles_x + tx + 1];
  for (size_t i = 1; i < tile_start.size(); ++i) tile_start[i] += tile_start[i - 1];
  std::vector<int> binned(tile_start.back());
  {
    std::vector<int> fill(tile_start.begin(), tile_start.end() - 1);
    for (int i = 0; i < static_cast<int>(tris.size()); ++i)
      for (int ty = tris[i].y0 / kTile; ty <= tris[i].y1 / kTile; ++ty)
        for (int tx = tris[i].x0 / kTile; tx <= tris[i].x1 / kTile; ++tx) binned[fill[ty * tiles_x + tx]++] = i;
  }

  ImageF out(W, H, 4, 0.0f);
  const Eigen::Vector3d camera_centre = camera.center();
  std::vector<Sample> samples(kTile * kTile * S * S);
  const double inv_samples = 1.0 / (S * S);
  for (int ty = 0; ty < tiles_y; ++ty) {
    for (int tx = 0; tx < tiles_x; ++tx) {
      const int tile = ty * tiles_x + tx;
      if (tile_start[tile] == tile_start[tile + 1]) continue;
      std::fill(samples.begin(), samples.end(), Sample{});
      const int px0 = tx * kTile, py0 = ty * kTile;
      const int px1 = std::min(W, px0 + kTile) - 1, py1 = std::min(H, py0 + kTile) - 1;
      const int row_samples = kTile * S;

      for (int b = tile_start[tile]; b < tile_start[tile + 1]; ++b) {
        const ScreenTriangle& t = tris[binned[b]];
        const int sx0 = (std::max(t.x0, px0) - px0) * S, sx1 = (std::min(t.x1, px1) - px0 + 1) * S;
        const int sy0 = (std::max(t.y0, py0) - py0) * S, sy1 = (std::min(t.y1, py1) - py0 + 1) * S;
        for (int sy = sy0; sy < sy1; ++sy) {
          const double y = py0 + (sy + 0.5) / S - 0.5;
          for (int sx = sx0; sx < sx1; ++sx) {
            const double x = px0 + (sx + 0.5) / S - 0.5;
            // Barycentrics from edge functions; inclusive edges so that
            // neighbouring triangles leave no cracks.
            const double l1 = t.a1 * x + t.b1 * y + t.c1;
            const double l2 = t.a2 * x + t.b2 * y + t.c2;
            const double l0 = 1.0 - l1 - l2;
            if (l0 < 0 || l1 < 0 || l2 < 0) continue;
            const double inv_z = l0 * t.inv_z[0] + l1 * t.inv_z[1] + l2 * t.inv_z[2];
            Sample& smp = samples[sy * row_samples + sx];
            if (inv_z > smp.inv_z) smp = {float(inv_z), binned[b], float(l1), float(l2)};
          }
        }
      }

      // Multisampling: coverage counts every sample, but each triangle in a
      // pixel is shaded once, at the mean of its samples.
      struct Group {
        int screen_triangle, count;
        double l1, l2;
      };
      std::vector<Group> groups;
      for (int py = py0; py <= py1; ++py) {
        for (int px = px0; px <= px1; ++px) {
          groups.clear();
          for (int j = 0; j < S; ++j) {
            for (int i = 0; i < S; ++i) {
              const Sample& smp = samples[((py - py0) * S + j) * row_samples + (px - px0) * S + i];
              if (smp.screen_triangle < 0) continue;
              auto g = std::find_if(groups.begin(), groups.end(),
                                    [&](const Group& x) { return x.screen_triangle == smp.screen_triangle; });
              if (g == groups.end()) groups.push_back({smp.screen_triangle, 1, smp.l1, smp.l2});
              else ++g->count, g->l1 += smp.l1, g->l2 += smp.l2;
            }
          }
          if (groups.empty()) continue;
          Eigen::Vector3d colour = Eigen::Vector3d::Zero();
          int covered = 0;
          for (const Group& g : groups) {
            const ScreenTriangle& t = tris[g.screen_triangle];
            const Surface& surf = surfaces[t.surface];
            const double l[3] = {1.0 - (g.l1 + g.l2) / g.count, g.l1 / g.count, g.l2 / g.count};
            const double inv_z = l[0] * t.inv_z[0] + l[1] * t.inv_z[1] + l[2] * t.inv_z[2];
            SurfaceSample ss;
            ss.triangle = t.triangle;
            for (int k = 0; k < 3; ++k) ss.barycentric[k] = float(l[k] * t.inv_z[k] / inv_z);
            ss.position.setZero();
            ss.normal.setZero();
            ss.uv.setZero();
            for (int k = 0; k < 3; ++k) {
              const int v = (*surf.faces)(t.triangle, k);
              ss.position += ss.barycentric[k] * surf.positions->row(v).transpose();
              ss.normal += ss.barycentric[k] * surf.normals->row(v).transpose();
              if (surf.uvs) ss.uv += ss.barycentric[k] * surf.uvs->row((*surf.uv_faces)(t.triangle, k)).transpose();
            }
            if (ss.normal.squaredNorm() > 0) ss.normal.normalize();
            ss.to_camera = (camera_centre.cast<float>() - ss.position).normalized();
            colour += g.count * surf.shade(ss).cast<double>();
            covered += g.count;
          }
          for (int c = 0; c < 3; ++c) out.at(px, py, c) = float(colour[c] * inv_samples);
          out.at(px, py, 3) = float(covered * inv_samples);
        }
      }
    }
  }
  return out;
}

}  // namespace tega::synth
