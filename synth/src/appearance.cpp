#include <algorithm>
#include <cmath>

#include "tega/synth/appearance.h"
#include "tega/synth/random.h"

namespace tega::synth {
namespace {

// Layers of procedural detail, each with its own hash stream.
enum Layer : int { kTone, kBlotch, kRedness, kPores, kFreckles, kFreckleMask, kStubble, kBrows, kHair, kIris };

float gauss(float x, float y) { return std::exp(-0.5f * (x * x + y * y)); }

// Darkening of a jittered dot per lattice cell (`cells` per UV unit).
// Independent uniforms of one lattice cell: one hash of the cell, then a cheap mix per draw.
struct CellRandom {
  uint64_t h;
  CellRandom(uint64_t seed, int layer, int64_t i, int64_t j) : h(hash_of(seed, layer, i, j)) {}
  double operator()(int draw) const { return unit_from_hash(mix64(h + uint64_t(draw) * 0x9e3779b97f4a7c15ull)); }
};

float dots(uint64_t seed, int layer, const Eigen::Vector2f& uv, double cells, double radius, double presence) {
  const double x = uv.x() * cells, y = uv.y() * cells;
  const auto cx = static_cast<int64_t>(std::floor(x)), cy = static_cast<int64_t>(std::floor(y));
  const CellRandom random(seed, layer, cx, cy);
  if (random(0) >= presence) return 0;
  const double px = cx + 0.25 + 0.5 * random(1);
  const double py = cy + 0.25 + 0.5 * random(2);
  const double r = radius * (0.6 + 0.8 * random(3));
  const double d2 = ((x - px) * (x - px) + (y - py) * (y - py)) / (r * r);
  return static_cast<float>(std::exp(-d2));
}

// Coverage by short hair-like strokes, one per lattice cell at most, pointing
// along `angle` +- `spread`. Strokes reach into neighbouring cells, so the
// 3 x 3 neighbourhood is searched.
float strokes(uint64_t seed, int layer, const Eigen::Vector2f& uv, double cells, double presence, double length,
              double width, double angle, double spread) {
  const double x = uv.x() * cells, y = uv.y() * cells;
  const auto cx = static_cast<int64_t>(std::floor(x)), cy = static_cast<int64_t>(std::floor(y));
  double coverage = 0;
  for (int64_t j = cy - 1; j <= cy + 1; ++j) {
    for (int64_t i = cx - 1; i <= cx + 1; ++i) {
      const CellRandom random(seed, layer, i, j);
      if (random(0) >= presence) continue;
      const double ox = i + random(1), oy = j + random(2);
      if ((x - ox) * (x - ox) + (y - oy) * (y - oy) > (length + 3 * width) * (length + 3 * width)) continue;
      const double a = angle + spread * (2 * random(3) - 1);
      const double dx = std::cos(a), dy = std::sin(a);
      const double along = std::clamp((x - ox) * dx + (y - oy) * dy, 0.0, length);
      const double ex = x - (ox + along * dx), ey = y - (oy + along * dy);
      coverage = std::max(coverage, std::exp(-(ex * ex + ey * ey) / (width * width)));
    }
  }
  return static_cast<float>(coverage);
}

Eigen::Vector3f mix(const Eigen::Vector3f& a, const Eigen::Vector3f& b, float t) { return a + t * (b - a); }

}  // namespace

float lip_weight(const Eigen::Vector3f& fp) { return gauss(fp.x() / 0.38f, (fp.y() + 1.06f) / 0.12f); }

Appearance::Appearance(uint64_t seed) : seed_(seed) {
  const float tone = static_cast<float>(uniform(seed, kTone, 0));
  skin_tone_ = mix(Eigen::Vector3f(0.80f, 0.60f, 0.50f), Eigen::Vector3f(0.50f, 0.34f, 0.25f), tone);
  const float iris = static_cast<float>(uniform(seed, kIris, 0));
  iris_ = mix(Eigen::Vector3f(0.25f, 0.40f, 0.55f), Eigen::Vector3f(0.35f, 0.20f, 0.10f), iris);
}

Eigen::Vector3f Appearance::skin(const Eigen::Vector2f& uv, const Eigen::Vector3f& fp) const {
  Eigen::Vector3f c = skin_tone_ * float(0.9 + 0.2 * value_noise(hash_of(seed_, kBlotch), uv.x() * 7, uv.y() * 7));
  c.x() += float(0.06 * (value_noise(hash_of(seed_, kRedness), uv.x() * 12, uv.y() * 12) - 0.5));

  const float lips = lip_weight(fp);
  c = mix(c, Eigen::Vector3f(0.62f, 0.30f, 0.30f), 0.7f * lips);

  c *= 1.0f - 0.3f * dots(seed_, kPores, uv, 420, 0.18, 0.8);
  const float freckle_density =
      float(0.5 * smoothstep(0.45, 0.75, value_noise(hash_of(seed_, kFreckleMask), uv.x() * 5, uv.y() * 5)));
  const float freckle = dots(seed_, kFreckles, uv, 70, 0.22, freckle_density);
  c = c.cwiseProduct(Eigen::Vector3f(1 - 0.3f * freckle, 1 - 0.38f * freckle, 1 - 0.45f * freckle));

  const Eigen::Vector3f hair_colour(0.13f, 0.09f, 0.07f);
  // Beard: below the cheeks, down to under the chin, on the front of the face.
  const float beard = float(smoothstep(-0.7, -0.95, fp.y()) * smoothstep(-2.3, -1.9, fp.y()) *
                            smoothstep(1.3, 0.9, std::abs(fp.x())) * smoothstep(-1.0, -0.6, fp.z())) *
                      (1 - lips);
  if (beard > 0.01f)
    c = mix(c, hair_colour, 0.65f * beard * strokes(seed_, kStubble, uv, 300, 0.6, 0.8, 0.08, -1.57, 0.6));
  const float brow = gauss((std::abs(fp.x()) - 0.55f) / 0.3f, (fp.y() - 0.42f) / 0.09f);
  if (brow > 0.01f)
    c = mix(c, hair_colour, 0.9f * brow * strokes(seed_, kBrows, uv, 350, 0.9, 1.6, 0.1, 0.2, 0.35));
  const float scalp = float(std::max(smoothstep(1.25, 1.6, fp.y()),
                                     smoothstep(-0.9, -1.5, fp.z()) * smoothstep(-0.4, 0.1, fp.y())));
  if (scalp > 0.01f) {
    const float strand = float(value_noise(hash_of(seed_, kHair), uv.x() * 900, uv.y() * 60));
    c = mix(c, hair_colour * (0.7f + 0.6f * strand), scalp);
  }
  return c.cwiseMax(0.0f).cwiseMin(1.0f);
}

Eigen::Vector3f Appearance::eye(const Eigen::Vector3f& d) const {
  constexpr float kPupilCos = 0.982f, kIrisCos = 0.866f;
  const float c = d.z();
  if (c > kPupilCos) return Eigen::Vector3f(0.02f, 0.02f, 0.02f);
  if (c > kIrisCos) {
    const double around = std::atan2(d.y(), d.x());
    const float streak = float(value_noise(hash_of(seed_, kIris, 1), around * 12, c * 40));
    const float limbus = float(smoothstep(kIrisCos + 0.03, kIrisCos, c));
    return iris_ * (0.7f + 0.6f * streak) * (1 - 0.6f * limbus);
  }
  return Eigen::Vector3f(0.86f, 0.84f, 0.80f);
}

}  // namespace tega::synth
