#include "cpu_rasterizer.h"

#include <ATen/Parallel.h>

#include <algorithm>
#include <numeric>
#include <utility>

namespace tega::splat::cpu {
namespace {

// Pixels per parallel_for chunk are whole tiles; a few per task.
constexpr int64_t kTilesPerTask = 4;

struct TileOrigin {
  int32_t camera, x, y;  // first pixel of the tile
};

TileOrigin tile_origin(const ImageGeometry& g, int64_t tile) {
  const int64_t per_camera = int64_t(g.tiles_x) * g.tiles_y;
  const int64_t local = tile % per_camera;
  return {int32_t(tile / per_camera), int32_t(local % g.tiles_x) * kTileSize,
          int32_t(local / g.tiles_x) * kTileSize};
}

}  // namespace

template <typename T>
void project(const RasterInputs<T>& in, const ProjectedBuffers<T>& out) {
  const int64_t n = in.num_gaussians, row = int64_t(3) * in.sh_coefficients;
  at::parallel_for(0, in.num_projected(), 1024, [&](int64_t begin, int64_t end) {
    for (int64_t i = begin; i < end; ++i)
      out.radii[i] = project_one(in, int32_t(i / n), i % n, in.colors + row * (i % n), out.splats[i], out.rects[i],
                                 out.color_jacobians ? out.color_jacobians + i : nullptr);
  });
}

template <typename T>
std::vector<int32_t> bin(const RasterInputs<T>& in, const ProjectedBuffers<T>& projected, int32_t* ranges) {
  const int64_t total = in.num_projected();
  const int64_t n = in.num_gaussians;
  // Front to back within each camera; ties keep index order (as the CUDA
  // path's stable radix sort does).
  std::vector<int32_t> order;
  for (int64_t i = 0; i < total; ++i)
    if (projected.radii[i] > 0) order.push_back(int32_t(i));
  std::stable_sort(order.begin(), order.end(), [&](int32_t a, int32_t b) {
    const int64_t ca = a / n, cb = b / n;
    if (ca != cb) return ca < cb;
    return projected.splats[a].depth < projected.splats[b].depth;
  });
  // Each Gaussian's tiles: those of its rectangle that its ellipse may
  // touch (the same test as the CUDA path). A counting sort by tile keeps the
  // depth order inside each tile.
  const ImageGeometry& g = in.geometry;
  const int64_t tiles_per_camera = int64_t(g.tiles_x) * g.tiles_y;
  std::vector<std::pair<int64_t, int32_t>> entries;  // (tile, id), in depth order
  for (int32_t id : order) {
    const TileRect& r = projected.rects[id];
    const Splat2D<T>& sp = projected.splats[id];
    const T level = splat_level(sp);
    const int64_t base = (id / n) * tiles_per_camera;
    for (int32_t ty = r.y0; ty < r.y1; ++ty)
      for (int32_t tx = r.x0; tx < r.x1; ++tx)
        if (splat_may_touch_tile(sp, level, g, tx, ty)) entries.emplace_back(base + int64_t(ty) * g.tiles_x + tx, id);
  }
  std::vector<int64_t> counts(in.num_tiles() + 1, 0);
  for (const auto& [tile, id] : entries) ++counts[tile + 1];
  std::partial_sum(counts.begin(), counts.end(), counts.begin());
  std::vector<int32_t> ids(counts.back());
  std::vector<int64_t> cursor(counts.begin(), counts.end() - 1);
  for (const auto& [tile, id] : entries) ids[cursor[tile]++] = id;
  for (int64_t t = 0; t < in.num_tiles(); ++t) {
    ranges[2 * t] = int32_t(counts[t]);
    ranges[2 * t + 1] = int32_t(counts[t + 1]);
  }
  return ids;
}

template <typename T>
void render_forward(const RasterInputs<T>& in, const Splat2D<T>* splats, const TileBins& bins,
                    const ImageBuffers<T>& image) {
  const ImageGeometry& g = in.geometry;
  const T bg[3] = {in.background[0], in.background[1], in.background[2]};
  at::parallel_for(0, in.num_tiles(), kTilesPerTask, [&](int64_t begin, int64_t end) {
    for (int64_t tile = begin; tile < end; ++tile) {
      const TileOrigin o = tile_origin(g, tile);
      const int32_t first = bins.ranges[2 * tile], stop = bins.ranges[2 * tile + 1];
      for (int32_t py = o.y; py < std::min(o.y + kTileSize, g.height); ++py)
        for (int32_t px = o.x; px < std::min(o.x + kTileSize, g.width); ++px) {
          PixelAccumulator<T> acc;
          for (int32_t k = first; k < stop && !acc.done; ++k)
            blend_forward(acc, splats[bins.gaussian_ids[k]], T(px), T(py), k - first);
          const int64_t pixel = (int64_t(o.camera) * g.height + py) * g.width + px;
          for (int ch = 0; ch < 3; ++ch) image.rgb[3 * pixel + ch] = acc.rgb[ch] + acc.transmittance * bg[ch];
          image.alpha[pixel] = T(1) - acc.transmittance;
          image.depth[pixel] = expected_depth(acc.depth, T(1) - acc.transmittance);
          image.final_transmittance[pixel] = acc.transmittance;
          image.last[pixel] = acc.last;
        }
    }
  });
}

template <typename T>
void render_backward(const RasterInputs<T>& in, const Splat2D<T>* splats, const TileBins& bins,
                     const ImageBuffers<T>& image, const ImageGradients<T>& grads, Splat2D<T>* splat_grads) {
  const ImageGeometry& g = in.geometry;
  const T bg[3] = {in.background[0], in.background[1], in.background[2]};
  const int64_t num_tiles = in.num_tiles();
  const int64_t num_intersections = bins.count;
  // One gradient slot per (tile, splat) entry: each tile writes only its own
  // run, so tiles run in parallel and the sum below is deterministic.
  std::vector<Splat2D<T>> per_entry(num_intersections, Splat2D<T>{});
  at::parallel_for(0, num_tiles, kTilesPerTask, [&](int64_t begin, int64_t end) {
    for (int64_t tile = begin; tile < end; ++tile) {
      const TileOrigin o = tile_origin(g, tile);
      const int32_t first = bins.ranges[2 * tile];
      for (int32_t py = o.y; py < std::min(o.y + kTileSize, g.height); ++py)
        for (int32_t px = o.x; px < std::min(o.x + kTileSize, g.width); ++px) {
          const int64_t pixel = (int64_t(o.camera) * g.height + py) * g.width + px;
          PixelBackward<T> st;
          for (int ch = 0; ch < 3; ++ch) st.grad_rgb[ch] = grads.rgb[3 * pixel + ch];
          st.grad_alpha_out = grads.alpha[pixel];
          st.final_transmittance = image.final_transmittance[pixel];
          st.grad_depth = grads.depth ? expected_depth_backward(grads.depth[pixel], image.depth[pixel],
                                                                T(1) - st.final_transmittance, st.grad_alpha_out)
                                      : T(0);
          st.transmittance = st.final_transmittance;
          st.background_dot = bg[0] * st.grad_rgb[0] + bg[1] * st.grad_rgb[1] + bg[2] * st.grad_rgb[2];
          for (int32_t k = first + image.last[pixel] - 1; k >= first; --k)
            blend_backward(st, splats[bins.gaussian_ids[k]], T(px), T(py), per_entry[k]);
        }
    }
  });
  std::fill(splat_grads, splat_grads + in.num_projected(), Splat2D<T>{});
  for (int64_t k = 0; k < num_intersections; ++k) {
    Splat2D<T>& dst = splat_grads[bins.gaussian_ids[k]];
    const Splat2D<T>& src = per_entry[k];
    dst.u += src.u; dst.v += src.v; dst.opacity += src.opacity; dst.depth += src.depth;
    dst.conic_a += src.conic_a; dst.conic_b += src.conic_b; dst.conic_c += src.conic_c;
    dst.red += src.red; dst.green += src.green; dst.blue += src.blue;
  }
}

template <typename T>
void project_backward(const RasterInputs<T>& in, const int32_t* radii, const Splat2D<T>* splat_grads,
                      const ColorJacobian<T>* color_jacobians, const InputGradients<T>& out) {
  at::parallel_for(0, in.num_gaussians, 256, [&](int64_t begin, int64_t end) {
    const int64_t row = int64_t(3) * in.sh_coefficients;
    for (int64_t g = begin; g < end; ++g)
      project_backward_one(in, radii, splat_grads, color_jacobians, g, out.colors + row * g, out);
  });
}

#define TEGA_SPLAT_INSTANTIATE(T)                                                                       \
  template void project<T>(const RasterInputs<T>&, const ProjectedBuffers<T>&);                        \
  template std::vector<int32_t> bin<T>(const RasterInputs<T>&, const ProjectedBuffers<T>&, int32_t*);  \
  template void render_forward<T>(const RasterInputs<T>&, const Splat2D<T>*, const TileBins&,          \
                                  const ImageBuffers<T>&);                                              \
  template void render_backward<T>(const RasterInputs<T>&, const Splat2D<T>*, const TileBins&,         \
                                   const ImageBuffers<T>&, const ImageGradients<T>&, Splat2D<T>*);     \
  template void project_backward<T>(const RasterInputs<T>&, const int32_t*, const Splat2D<T>*,         \
                                    const ColorJacobian<T>*, const InputGradients<T>&);
TEGA_SPLAT_INSTANTIATE(float)
TEGA_SPLAT_INSTANTIATE(double)
#undef TEGA_SPLAT_INSTANTIATE

}  // namespace tega::splat::cpu
