#include "eyelids.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

#include "rigid_alignment.h"
#include "surface_query.h"
#include "tega/core/error.h"

namespace tega::tracking {
namespace {

// Blink values at which the model's lid is tested.
constexpr int kBlinkSteps = 10;
// Skin within this many eyeball radii of an eye's centre can hide it ...
constexpr double kLidReach = 1.6;
// ... and skin between these radii that the blink leaves still gives its colour.
constexpr double kRingInner = 1.2, kRingOuter = 2.2;
constexpr float kRingMaxBlinkMotionM = 0.0005;
// An eyeball point faces a camera when its outward normal is within 60 degrees of it.
constexpr double kMinFacingCosine = 0.5;
// A lid counts as hiding a point when it crosses the line of sight this far before it.
constexpr double kOcclusionMarginM = 0.0002;
// Colour features: chromaticity in 8-bit levels, brightness as 40 levels per
// e-fold (a shadow that halves the light moves it 28 levels).
constexpr double kBrightnessWeight = 40;

Eigen::Vector3d row3(const Vertices& v, int i) { return v.row(i).cast<double>().transpose(); }

struct EyeGeometry {
  Eigen::Vector3d centre;
  double radius = 0;
  std::vector<int> vertices;
};

// The eyeball vertices split at their mean x: the model's two eyes.
std::vector<EyeGeometry> split_eyeballs(const HeadModel& model) {
  const Vertices& neutral = model.shapes.neutral.positions;
  double mean_x = 0;
  for (int v : model.eyeball_vertices) mean_x += neutral(v, 0);
  mean_x /= double(model.eyeball_vertices.size());
  std::vector<EyeGeometry> eyes(2);
  for (int v : model.eyeball_vertices) eyes[neutral(v, 0) < mean_x ? 0 : 1].vertices.push_back(v);
  for (auto& eye : eyes) {
    eye.centre.setZero();
    for (int v : eye.vertices) eye.centre += row3(neutral, v);
    eye.centre /= double(eye.vertices.size());
    for (int v : eye.vertices) eye.radius += (row3(neutral, v) - eye.centre).norm();
    eye.radius /= double(eye.vertices.size());
  }
  return eyes;
}

double median_of(std::vector<double> values) {
  if (values.empty()) return 0;
  std::nth_element(values.begin(), values.begin() + long(values.size() / 2), values.end());
  return values[values.size() / 2];
}

// A photo's colour at a pixel (integers at pixel centres), bilinear; none off the image.
std::optional<Eigen::Vector3d> colour_at(const Image8& image, const Eigen::Vector2d& pixel) {
  const double x = pixel.x(), y = pixel.y();
  const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= image.width || y0 + 1 >= image.height || image.channels < 3) return std::nullopt;
  const double fx = x - x0, fy = y - y0;
  Eigen::Vector3d c;
  for (int k = 0; k < 3; ++k)
    c[k] = (1 - fy) * ((1 - fx) * image.at(x0, y0, k) + fx * image.at(x0 + 1, y0, k)) +
           fy * ((1 - fx) * image.at(x0, y0 + 1, k) + fx * image.at(x0 + 1, y0 + 1, k));
  return c;
}

// Colour as chromaticity and log brightness: a lid's shadow darkens the skin
// but keeps its hue; sclera and iris differ from skin in both.
Eigen::Vector3d colour_feature(const Eigen::Vector3d& rgb) {
  const double sum = rgb.sum() + 3;
  return {255 * (rgb[0] + 1) / sum, 255 * (rgb[2] + 1) / sum, kBrightnessWeight * std::log(sum / 3)};
}

// The lids with every eye's blink at `blink`, the rest of the state as is.
Mesh lids_at(const ModelEyes& eyes, const HeadModel& model, const Vertices& head, const HeadState& state,
             double blink) {
  Vertices shaped = head;
  for (const auto& eye : eyes.eyes)
    shaped += float(blink - state.expression[size_t(eye.blink)]) * model.shapes.expression_deltas[size_t(eye.blink)];
  Mesh lids;
  lids.positions = posed(shaped, state.head_to_world);
  lids.faces = eyes.lids;
  return lids;
}

}  // namespace

ModelEyes find_model_eyes(const HeadModel& model, const EyelidOptions& options) {
  const auto& dir = model.directory;
  if (options.shapes.size() != 2)
    throw Error("tracking option eyelids.shapes must name two shapes, one per eye (it names " +
                std::to_string(options.shapes.size()) + ")");
  if (model.eyeball_vertices.empty()) throw Error(dir, "has no eyeball vertices: the eyelid term needs them");
  std::vector<int> shapes;
  for (const auto& name : options.shapes) {
    const int k = model.shapes.expression_index(name);
    if (k < 0) throw Error(dir, "has no expression shape " + name + " (tracking option eyelids.shapes)");
    shapes.push_back(k);
  }
  const Vertices& neutral = model.shapes.neutral.positions;
  const std::vector<EyeGeometry> geometry = split_eyeballs(model);

  ModelEyes found;
  std::vector<char> near_eye(size_t(model.num_vertices()), 0);
  for (const auto& eye : geometry) {
    // The shape that moves the skin around this eye most closes it.
    ModelEye m;
    double most = -1;
    for (int k : shapes) {
      double motion = 0;
      for (int v : model.skin_vertices)
        if ((row3(neutral, v) - eye.centre).norm() < kRingOuter * eye.radius)
          motion += model.shapes.expression_deltas[size_t(k)].row(v).norm();
      if (motion > most) most = motion, m.blink = k;
    }
    for (size_t i = 0; i < eye.vertices.size(); i += size_t(std::max(1, options.sample_step)))
      m.eyeball_samples.push_back(eye.vertices[i]);
    for (int v : model.skin_vertices) {
      const double d = (row3(neutral, v) - eye.centre).norm();
      if (d < kLidReach * eye.radius) near_eye[size_t(v)] = 1;
      if (d > kRingInner * eye.radius && d < kRingOuter * eye.radius &&
          model.shapes.expression_deltas[size_t(m.blink)].row(v).norm() < kRingMaxBlinkMotionM)
        m.skin_ring.push_back(v);
    }
    found.eyes.push_back(std::move(m));
  }
  if (found.eyes[0].blink == found.eyes[1].blink)
    throw Error(dir, "both eyes pair with the shape " + model.shapes.expression_names[size_t(found.eyes[0].blink)] +
                         ": tracking option eyelids.shapes must name one shape per eye");

  std::vector<char> skin(size_t(model.num_vertices()), 0);
  for (int v : model.skin_vertices) skin[size_t(v)] = 1;
  const Triangles& faces = model.shapes.neutral.faces;
  std::vector<int> kept;
  for (int f = 0; f < faces.rows(); ++f) {
    bool all_skin = true, any_near = false;
    for (int c = 0; c < 3; ++c) {
      all_skin = all_skin && skin[size_t(faces(f, c))];
      any_near = any_near || near_eye[size_t(faces(f, c))];
    }
    if (all_skin && any_near) kept.push_back(f);
  }
  found.lids.resize(Eigen::Index(kept.size()), 3);
  for (size_t i = 0; i < kept.size(); ++i) found.lids.row(Eigen::Index(i)) = faces.row(kept[i]);
  return found;
}

std::vector<EyelidObservation> observe_eyelids(const ModelEyes& eyes, const HeadModel& model, const Vertices& head,
                                               const HeadState& state, const std::vector<Image8>& images,
                                               const std::vector<Camera>& cameras,
                                               const std::map<std::string, double>& open_eyes_covered,
                                               const EyelidOptions& options) {
  const Vertices world = posed(head, state.head_to_world);
  Mesh posed_mesh;
  posed_mesh.positions = world;
  posed_mesh.faces = model.shapes.neutral.faces;
  const Vertices normals = posed_mesh.vertex_normals();
  std::vector<std::unique_ptr<SurfaceQuery>> lids;  // per tested blink value
  for (int step = 0; step <= kBlinkSteps; ++step)
    lids.push_back(std::make_unique<SurfaceQuery>(lids_at(eyes, model, head, state, double(step) / kBlinkSteps)));
  const double max_view_cosine = std::cos(options.max_view_angle_deg * M_PI / 180);

  std::vector<EyelidObservation> observed;
  for (const auto& eye : eyes.eyes) {
    if (eye.skin_ring.empty()) continue;  // no skin to tell the eye's front and the skin's colour
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (int v : eye.eyeball_samples) centre += row3(world, v);
    centre /= double(eye.eyeball_samples.size());
    // The eye looks out through the skin around it.
    Eigen::Vector3d ring_centre = Eigen::Vector3d::Zero();
    for (int v : eye.skin_ring) ring_centre += row3(world, v);
    const Eigen::Vector3d front = (ring_centre / double(eye.skin_ring.size()) - centre).normalized();

    EyelidObservation o;
    o.blink = eye.blink;
    int skin_seen = 0;
    std::vector<int> covered_at(kBlinkSteps + 1, 0);
    for (size_t c = 0; c < cameras.size(); ++c) {
      if (c >= images.size() || images[c].empty()) continue;
      const Eigen::Vector3d eye_point = cameras[c].center();
      if (front.dot((eye_point - centre).normalized()) < max_view_cosine) continue;

      // The skin's colour here, and how much it varies.
      std::vector<Eigen::Vector3d> ring_colours;
      for (int v : eye.skin_ring) {
        const Eigen::Vector3d p = row3(world, v);
        if (row3(normals, v).dot((eye_point - p).normalized()) < kMinFacingCosine) continue;
        const auto pixel = cameras[c].project(p);
        if (!pixel) continue;
        if (const auto colour = colour_at(images[c], *pixel)) ring_colours.push_back(colour_feature(*colour));
      }
      if (ring_colours.size() < 10) continue;
      Eigen::Vector3d skin_colour;
      for (int k = 0; k < 3; ++k) {
        std::vector<double> channel;
        for (const auto& colour : ring_colours) channel.push_back(colour[k]);
        skin_colour[k] = median_of(channel);
      }
      std::vector<double> spread;
      for (const auto& colour : ring_colours) spread.push_back((colour - skin_colour).norm());
      const double skin_distance =
          std::max(options.min_skin_distance, options.skin_distance_factor * median_of(spread));

      // The eyeball points that face this camera ...
      std::vector<Eigen::Vector3d> points, colours;
      for (int v : eye.eyeball_samples) {
        const Eigen::Vector3d p = row3(world, v);
        if ((p - centre).normalized().dot((eye_point - p).normalized()) < kMinFacingCosine) continue;
        const auto pixel = cameras[c].project(p);
        const auto colour = pixel ? colour_at(images[c], *pixel) : std::nullopt;
        if (!colour) continue;
        points.push_back(p);
        colours.push_back(colour_feature(*colour));
      }
      // ... and of them those the open lid leaves in sight.
      const std::vector<bool> hidden_open = lids[0]->occluded(eye_point, points, kOcclusionMarginM);
      std::vector<Eigen::Vector3d> open_points;
      for (size_t i = 0; i < points.size(); ++i) {
        if (hidden_open[i]) continue;
        open_points.push_back(points[i]);
        skin_seen += (colours[i] - skin_colour).norm() <= skin_distance;
      }
      o.samples += int(open_points.size());
      for (int step = 1; step <= kBlinkSteps; ++step) {
        const std::vector<bool> hidden = lids[size_t(step)]->occluded(eye_point, open_points, kOcclusionMarginM);
        covered_at[size_t(step)] += int(std::count(hidden.begin(), hidden.end(), true));
      }
    }
    if (o.samples < options.min_samples) continue;
    o.seen_covered = double(skin_seen) / o.samples;
    const auto open = open_eyes_covered.find(model.shapes.expression_names[size_t(eye.blink)]);
    const double baseline = open == open_eyes_covered.end() ? 0.0 : std::min(open->second, 0.9);
    o.covered = std::max(0.0, (o.seen_covered - baseline) / (1 - baseline));
    // The blink values whose lid covers what the photos show covered.
    double best_gap = 2, best = 0;
    o.low = 2, o.high = -1;
    for (int step = 0; step <= kBlinkSteps; ++step) {
      const double blink = double(step) / kBlinkSteps;
      const double gap = std::abs(double(covered_at[size_t(step)]) / o.samples - o.covered);
      if (gap < best_gap) best_gap = gap, best = blink;
      if (gap <= options.tolerance) o.low = std::min(o.low, blink), o.high = std::max(o.high, blink);
    }
    if (o.high < o.low) o.low = o.high = best;
    observed.push_back(o);
  }
  return observed;
}

}  // namespace tega::tracking
