// One image's matte (docs/matting.md#the-method).
#include <algorithm>
#include <cmath>
#include <optional>
#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc/edge_filter.hpp>
#include <tuple>
#include <vector>

#include "tega/core/error.h"
#include "tega/core/silhouette.h"
#include "tega/matting/matte.h"

namespace tega::matting {
namespace {

cv::Mat view_of(const Image8& image) {
  return cv::Mat(image.height, image.width, CV_8UC(image.channels), const_cast<uint8_t*>(image.pixels.data()));
}

// Distance of every pixel to the nearest pixel outside `mask` (0 outside it).
cv::Mat distance_inside(const cv::Mat& mask) {
  cv::Mat distance;
  cv::distanceTransform(mask, distance, cv::DIST_L2, cv::DIST_MASK_5);
  return distance;
}
cv::Mat distance_outside(const cv::Mat& mask) { return distance_inside(mask == 0); }

double median_of(std::vector<float>& values) {
  if (values.empty()) return 0;
  auto mid = values.begin() + long(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

// Every few pixels where `where` holds: enough for robust statistics.
std::vector<cv::Point> sample_points(const cv::Mat& where, int target = 200000) {
  const int step = std::max(1, int(std::sqrt(double(where.total()) / target)));
  std::vector<cv::Point> points;
  for (int y = 0; y < where.rows; y += step)
    for (int x = 0; x < where.cols; x += step)
      if (where.at<uint8_t>(y, x)) points.emplace_back(x, y);
  return points;
}

// Sums over 3 x 3 pixels (exact, in 16 bits) of an RGB image: the 3 x 3
// means the difference is taken between, at a fraction of a float blur's cost.
cv::Mat sums_3x3(const cv::Mat& colour) {
  cv::Mat sums;
  cv::boxFilter(colour, sums, CV_16U, cv::Size(3, 3), cv::Point(-1, -1), false);
  return sums;
}

// The frame's exposure against the clean plate: a per-channel gain measured
// on the far background, where the plate and the frame show the same thing.
cv::Vec3f exposure_gain(const cv::Mat& photo, const cv::Mat& plate, const std::vector<cv::Point>& background,
                        double max_change) {
  cv::Vec3f gain(1, 1, 1);
  for (int c = 0; c < 3; ++c) {
    std::vector<float> ratios;
    for (const auto& p : background) {
      const float b = plate.at<cv::Vec3b>(p)[c];
      if (b > 0.04f * 255) ratios.push_back(photo.at<cv::Vec3b>(p)[c] / b);
    }
    if (ratios.size() > 100) gain[c] = float(std::clamp(median_of(ratios), 1 - max_change, 1 + max_change));
  }
  return gain;
}

// The part of the 3 x 3 mean photo - plate that a change of shading within
// 1 +- `shading` does not explain (a shadow on the backdrop, a passing cloud):
// the plate scaled by the factor that best matches the photo, clamped to that
// range, is subtracted (brightness and colour distortion, Horprasert et al.).
// The plate is first brought to the frame's exposure by `gain`. From the
// exact 3 x 3 sums; [0, 1] units.
class MeanDifference {
 public:
  MeanDifference(const cv::Vec3f& gain, double shading)
      : gain_(gain / (9.0f * 255)), low_(float(1 - shading)), high_(float(1 + shading)), shading_(shading > 0) {}
  cv::Vec3f operator()(const cv::Vec3w& photo_sums, const cv::Vec3w& plate_sums) const {
    const cv::Vec3f I(photo_sums[0] * kUnit, photo_sums[1] * kUnit, photo_sums[2] * kUnit);
    const cv::Vec3f B(plate_sums[0] * gain_[0], plate_sums[1] * gain_[1], plate_sums[2] * gain_[2]);
    if (!shading_) return I - B;
    const float b2 = B.dot(B);
    const float k = b2 > 1e-6f ? std::clamp(I.dot(B) / b2, low_, high_) : 1.0f;
    return I - k * B;
  }

 private:
  static constexpr float kUnit = 1.0f / (9 * 255);
  cv::Vec3f gain_;
  float low_, high_;
  bool shading_;
};

// The noise of the mean difference, from its median absolute deviation on the
// far background.
double difference_noise(const cv::Mat& photo_sums, const cv::Mat& plate_sums, const MeanDifference& difference,
                        const std::vector<cv::Point>& background) {
  std::vector<float> values;
  values.reserve(background.size() * 3);
  for (const auto& p : background) {
    const cv::Vec3f d = difference(photo_sums.at<cv::Vec3w>(p), plate_sums.at<cv::Vec3w>(p));
    for (int c = 0; c < 3; ++c) values.push_back(d[c]);
  }
  const float centre = float(median_of(values));
  for (float& v : values) v = std::abs(v - centre);
  return 1.4826 * median_of(values);
}

// 255 where the mean difference is longer than `threshold`.
cv::Mat differs(const cv::Mat& photo_sums, const cv::Mat& plate_sums, const MeanDifference& difference,
                double threshold) {
  cv::Mat out(photo_sums.size(), CV_8U);
  const float limit2 = float(threshold * threshold);
  for (int y = 0; y < out.rows; ++y) {
    const cv::Vec3w* photo = photo_sums.ptr<cv::Vec3w>(y);
    const cv::Vec3w* plate = plate_sums.ptr<cv::Vec3w>(y);
    uint8_t* row = out.ptr<uint8_t>(y);
    for (int x = 0; x < out.cols; ++x) {
      const cv::Vec3f d = difference(photo[x], plate[x]);
      row[x] = d.dot(d) > limit2 ? 255 : 0;
    }
  }
  return out;
}

// Alpha of colour I between the subject's colour F and the known background B
// (I = a F + (1 - a) B, least squares), leaning on `prior` as far as F and B
// are alike: the unmixing is noise there.
float unmix(const cv::Vec3f& I, const cv::Vec3f& F, const cv::Vec3f& B, float prior, float contrast2) {
  const cv::Vec3f d = F - B;
  const float d2 = d.dot(d);
  if (d2 <= 0) return prior;
  const float a = std::clamp((I - B).dot(d) / d2, 0.0f, 1.0f);
  const float trust = d2 / (d2 + contrast2);
  return trust * a + (1 - trust) * prior;
}

cv::Mat disk(int radius) {
  return cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1));
}

// Subject regions that touch `anchor`, with the holes that lie within
// `possible` filled (a pupil as dark as the backdrop is still the head).
cv::Mat connected_subject(const cv::Mat& subject, const cv::Mat& anchor, const cv::Mat& possible, bool connected_only) {
  cv::Mat labels;
  const int count = cv::connectedComponents(subject, labels, 8, CV_32S);
  std::vector<uint8_t> keep(size_t(count), connected_only ? 0 : 1);
  keep[0] = 0;
  if (connected_only)
    for (int y = 0; y < subject.rows; ++y)
      for (int x = 0; x < subject.cols; ++x)
        if (anchor.at<uint8_t>(y, x)) keep[size_t(labels.at<int>(y, x))] = 1;
  cv::Mat kept(subject.size(), CV_8U);
  for (int y = 0; y < subject.rows; ++y)
    for (int x = 0; x < subject.cols; ++x) kept.at<uint8_t>(y, x) = keep[size_t(labels.at<int>(y, x))] ? 255 : 0;

  const int holes = cv::connectedComponents(kept == 0, labels, 4, CV_32S);
  std::vector<uint8_t> fill(size_t(holes), 1);
  fill[0] = 0;
  for (int y = 0; y < subject.rows; ++y) {
    for (int x = 0; x < subject.cols; ++x) {
      const int l = labels.at<int>(y, x);
      const bool border = x == 0 || y == 0 || x == subject.cols - 1 || y == subject.rows - 1;
      if (border || !possible.at<uint8_t>(y, x)) fill[size_t(l)] = 0;
    }
  }
  for (int y = 0; y < subject.rows; ++y)
    for (int x = 0; x < subject.cols; ++x)
      if (fill[size_t(labels.at<int>(y, x))]) kept.at<uint8_t>(y, x) = 255;
  return kept;
}

// Mean colour of the `known` pixels around each pixel, over ever larger
// windows until some are found for every `needed` pixel: the subject's colour
// just inside its edge. -1 where none was found.
cv::Mat nearby_colour(const cv::Mat& colour, const cv::Mat& known, const cv::Mat& needed, int radius) {
  cv::Mat weight;
  known.convertTo(weight, CV_32F, 1.0 / 255);
  cv::Mat weighted;
  cv::Mat weight3;
  cv::merge(std::vector<cv::Mat>{weight, weight, weight}, weight3);
  cv::multiply(colour, weight3, weighted);
  cv::Mat result(colour.size(), CV_32FC3, cv::Scalar::all(-1));
  for (int r = radius; r <= 8 * radius; r *= 2) {
    cv::Mat sum, total;
    cv::boxFilter(weighted, sum, -1, cv::Size(2 * r + 1, 2 * r + 1), cv::Point(-1, -1), false);
    cv::boxFilter(weight, total, -1, cv::Size(2 * r + 1, 2 * r + 1), cv::Point(-1, -1), false);
    bool missing = false;
    for (int y = 0; y < colour.rows; ++y) {
      cv::Vec3f* out = result.ptr<cv::Vec3f>(y);
      const cv::Vec3f* sums = sum.ptr<cv::Vec3f>(y);
      const float* totals = total.ptr<float>(y);
      const uint8_t* need = needed.ptr<uint8_t>(y);
      for (int x = 0; x < colour.cols; ++x) {
        if (out[x][0] >= 0) continue;
        if (totals[x] > 0.5f) out[x] = sums[x] / totals[x];
        else if (need[x]) missing = true;
      }
    }
    if (!missing) break;
  }
  return result;
}

cv::Rect grown(const cv::Rect& r, int by, const cv::Size& size) {
  return cv::Rect(r.x - by, r.y - by, r.width + 2 * by, r.height + 2 * by) & cv::Rect(cv::Point(0, 0), size);
}

Image8 image_of(const cv::Mat& alpha) {
  Image8 out(alpha.cols, alpha.rows, 1);
  cv::Mat view = view_of(out);
  alpha.convertTo(view, CV_8U, 255.0);
  return out;
}

// Without a clean plate: the silhouette, its uncertain margin decided by a
// guided filter along the photo's edges.
Image8 mesh_only_matte(const cv::Mat& photo8, const cv::Mat& silhouette, int margin, const MatteOptions& options) {
  const cv::Mat inside = distance_inside(silhouette), outside = distance_outside(silhouette);
  cv::Mat alpha;
  silhouette.convertTo(alpha, CV_32F, 1.0 / 255);
  cv::Mat filtered;
  cv::ximgproc::guidedFilter(photo8, alpha, filtered, margin, options.edge.guided_filter_eps);
  for (int y = 0; y < alpha.rows; ++y) {
    for (int x = 0; x < alpha.cols; ++x) {
      float& a = alpha.at<float>(y, x);
      if (inside.at<float>(y, x) > margin) a = 1;
      else if (outside.at<float>(y, x) > margin) a = 0;
      else a = std::clamp(filtered.at<float>(y, x), 0.0f, 1.0f);
    }
  }
  return image_of(alpha);
}

Image8 resized(const Image8& image, int width, int height, int interpolation) {
  Image8 out(width, height, image.channels);
  cv::Mat target = view_of(out);
  cv::resize(view_of(image), target, cv::Size(width, height), 0, 0, interpolation);
  return out;
}

// A clean plate at the size photos are matted at, with its 3 x 3 sums.
struct Plate {
  cv::Mat colour;  // CV_8UC3
  cv::Mat sums;    // CV_16UC3
};

Plate plate_of(const Image8& image) { return {view_of(image), sums_3x3(view_of(image))}; }

// What unmixing needs, kept from a matte made at a smaller size to unmix the
// full-size photo's edge.
struct EdgeModel {
  cv::Vec3f gain{1, 1, 1};  // exposure of the frame against the clean plate
  cv::Rect roi;             // where the edge lies, in the small image
  cv::Mat subject_colour;   // CV_32FC3 over roi, the subject's colour near its edge; -1 where unknown
};

Image8 matte_at_this_size(const Image8& photo, const Plate* plate, const Image8& silhouette, double margin_px,
                          const MatteOptions& options, EdgeModel* edge_model = nullptr) {
  const cv::Mat photo8 = view_of(photo), mesh = view_of(silhouette);
  const int margin = std::max(1, int(std::lround(margin_px)));
  if (!plate) return mesh_only_matte(photo8, mesh, margin, options);

  const int band = std::max(1, options.edge.band_px);
  // Distances to the mesh's outline matter within `reach` of it; the rest of
  // the photo is far background.
  cv::Mat certain(photo8.size(), CV_8U, cv::Scalar(0));  // subject whatever the plate says
  cv::Mat possible(photo8.size(), CV_8U, cv::Scalar(0));
  cv::Mat far_mask(photo8.size(), CV_8U, cv::Scalar(255));
  const int reach = margin + 4 * band + 2;
  const cv::Rect near_mesh = grown(cv::boundingRect(mesh), reach, photo8.size());
  if (near_mesh.area() > 0) {
    const cv::Mat inside = distance_inside(mesh(near_mesh)), outside = distance_outside(mesh(near_mesh));
    cv::Mat(inside > margin).copyTo(certain(near_mesh));
    cv::Mat(outside <= margin).copyTo(possible(near_mesh));
    cv::Mat(outside > margin + 4 * band).copyTo(far_mask(near_mesh));
  }
  const std::vector<cv::Point> far = sample_points(far_mask);

  const cv::Vec3f gain = exposure_gain(photo8, plate->colour, far, options.difference.max_exposure_change);
  // Subject: where the 3x3 mean difference stands out of that mean's noise,
  // measured on the far background (real noise is correlated: a third of one
  // pixel's would be too optimistic), cleaned, joined with the certain head,
  // its holes filled.
  const cv::Mat photo_sums = sums_3x3(photo8);
  const MeanDifference difference(gain, options.difference.shading_tolerance);
  const double noise = options.difference.noise_sigma > 0
                           ? options.difference.noise_sigma / 3
                           : std::max(3e-4, difference_noise(photo_sums, plate->sums, difference, far));
  cv::Mat subject = differs(photo_sums, plate->sums, difference, options.difference.subject_sigmas * noise);
  if (options.difference.open_px > 0) cv::morphologyEx(subject, subject, cv::MORPH_OPEN, disk(options.difference.open_px));
  if (options.difference.close_px > 0) cv::morphologyEx(subject, subject, cv::MORPH_CLOSE, disk(options.difference.close_px));
  subject |= certain;
  subject = connected_subject(subject, certain, possible, options.mesh.keep_connected_only && cv::countNonZero(certain) > 0);

  // The band around the edge, where alpha is fractional; the work stays in
  // its bounding box. Subject within `band` of the photo's border is in it
  // too: the 3 x 3 difference and the closing carry the subject onto the
  // last pixels whatever they show, so an edge lying there (a bust cut just
  // above the frame's bottom) is decided by unmixing like any other.
  cv::Mat band_mask =
      ((distance_inside(subject) <= band) & subject) | ((distance_outside(subject) <= band) & (subject == 0));
  cv::Mat near_border(subject.size(), CV_8U, cv::Scalar(255));
  if (subject.cols > 2 * band && subject.rows > 2 * band)
    near_border(cv::Rect(band, band, subject.cols - 2 * band, subject.rows - 2 * band)).setTo(0);
  band_mask |= near_border & subject;
  cv::Mat alpha;
  subject.convertTo(alpha, CV_32F, 1.0 / 255);
  const cv::Rect box = cv::boundingRect(band_mask);
  if (box.area() == 0) return image_of(alpha);
  const cv::Rect roi = grown(box, 8 * (2 * band + 1), photo8.size());
  const cv::Mat in_band = band_mask(roi), known_subject = subject(roi) & (in_band == 0);
  cv::Mat colour, background;
  photo8(roi).convertTo(colour, CV_32FC3, 1.0 / 255);
  plate->colour(roi).convertTo(background, CV_32FC3, 1.0 / 255);
  cv::multiply(background, cv::Scalar(gain[0], gain[1], gain[2]), background);
  const cv::Mat subject_colour = nearby_colour(colour, known_subject, in_band, 2 * band + 1);
  if (edge_model) *edge_model = {gain, roi, subject_colour};
  cv::Mat smooth_mask;
  cv::blur(alpha(roi), smooth_mask, cv::Size(3, 3));

  // Unmixing against the known background.
  cv::Mat unmixed = alpha(roi).clone();
  const float contrast2 = float(options.edge.min_contrast * options.edge.min_contrast);
  for (int y = 0; y < roi.height; ++y) {
    for (int x = 0; x < roi.width; ++x) {
      if (!in_band.at<uint8_t>(y, x)) continue;
      const cv::Vec3f F = subject_colour.at<cv::Vec3f>(y, x), B = background.at<cv::Vec3f>(y, x);
      const float prior = smooth_mask.at<float>(y, x);
      if (F[0] < 0) {
        unmixed.at<float>(y, x) = prior;
        continue;
      }
      unmixed.at<float>(y, x) = unmix(colour.at<cv::Vec3f>(y, x), F, B, prior, contrast2);
    }
  }
  if (options.edge.guided_filter_radius_px > 0) {
    cv::Mat filtered;
    // Band pixels see 2 radii around them: the filter runs on the band's box grown by that.
    const cv::Rect near_band = grown(box, 2 * options.edge.guided_filter_radius_px + 1, photo8.size());
    const cv::Rect within_roi = near_band - roi.tl();
    cv::ximgproc::guidedFilter(photo8(near_band), unmixed(within_roi), filtered, options.edge.guided_filter_radius_px,
                               options.edge.guided_filter_eps);
    filtered.copyTo(unmixed(within_roi), in_band(within_roi));
  }
  cv::Mat target = alpha(roi);
  unmixed.copyTo(target, in_band);
  cv::min(cv::max(alpha, 0.0), 1.0, alpha);
  return image_of(alpha);
}

// The edge of an enlarged alpha unmixed again at full size: where it is
// fractional (the enlargement spreads the edge over about `shrink` pixels),
// each pixel of the photo is unmixed against its own clean-plate pixel with
// the subject colour of the small matte.
void unmix_enlarged_edge(const Image8& photo, const Image8& plate, const EdgeModel& edge, int shrink,
                         const MatteOptions& options, Image8& alpha) {
  const cv::Mat& colour = edge.subject_colour;
  const float contrast2 = float(options.edge.min_contrast * options.edge.min_contrast);
  const auto subject_colour_at = [&](int x, int y) {
    // Bilinear in the small image, whose pixel centres lie at (i + 0.5) * shrink.
    const float fx = std::clamp((x + 0.5f) / shrink - 0.5f - edge.roi.x, 0.0f, float(colour.cols - 1));
    const float fy = std::clamp((y + 0.5f) / shrink - 0.5f - edge.roi.y, 0.0f, float(colour.rows - 1));
    const int x0 = int(fx), y0 = int(fy), x1 = std::min(x0 + 1, colour.cols - 1), y1 = std::min(y0 + 1, colour.rows - 1);
    const float tx = fx - x0, ty = fy - y0;
    cv::Vec3f sum(0, 0, 0);
    float weight = 0;
    for (const auto& [cx, cy, w] : {std::tuple{x0, y0, (1 - tx) * (1 - ty)}, std::tuple{x1, y0, tx * (1 - ty)},
                                    std::tuple{x0, y1, (1 - tx) * ty}, std::tuple{x1, y1, tx * ty}}) {
      const cv::Vec3f c = colour.at<cv::Vec3f>(cy, cx);
      if (c[0] < 0 || w <= 0) continue;
      sum += w * c;
      weight += w;
    }
    return weight > 0 ? cv::Vec3f(sum / weight) : cv::Vec3f(-1, -1, -1);
  };
  // Outside the edge's box the small alpha is 0 or 1, and so the enlarged.
  const int x_end = std::min(photo.width, (edge.roi.x + edge.roi.width) * shrink);
  const int y_end = std::min(photo.height, (edge.roi.y + edge.roi.height) * shrink);
  for (int y = edge.roi.y * shrink; y < y_end; ++y) {
    for (int x = edge.roi.x * shrink; x < x_end; ++x) {
      uint8_t& a = alpha.at(x, y, 0);
      if (a == 0 || a == 255) continue;
      const cv::Vec3f F = subject_colour_at(x, y);
      if (F[0] < 0) continue;
      cv::Vec3f I, B;
      for (int c = 0; c < 3; ++c) {
        I[c] = photo.at(x, y, c) / 255.0f;
        B[c] = edge.gain[c] * plate.at(x, y, c) / 255.0f;
      }
      a = uint8_t(std::lround(255 * unmix(I, F, B, a / 255.0f, contrast2)));
    }
  }
}

// The photo's matte at 1/shrink of its size, enlarged back, its edge unmixed
// again at full size; `small_silhouette` and `small_plate` have that size.
Image8 shrunk_matte(const Image8& photo, const Image8* clean_plate, const Plate* small_plate,
                    const Image8& small_silhouette, int shrink, double margin_px, const MatteOptions& options) {
  EdgeModel edge;
  const Image8 small_alpha =
      matte_at_this_size(resized(photo, small_silhouette.width, small_silhouette.height, cv::INTER_AREA), small_plate,
                         small_silhouette, margin_px / shrink, options, &edge);
  Image8 alpha = resized(small_alpha, photo.width, photo.height, cv::INTER_LINEAR);
  if (clean_plate && !edge.subject_colour.empty()) unmix_enlarged_edge(photo, *clean_plate, edge, shrink, options, alpha);
  return alpha;
}

// Large photos are matted at 1/shrink of their size (area-averaged) and the
// alpha enlarged back: the time falls with the square of the factor.
int shrink_for(int width, const MatteOptions& options) {
  return (width + options.max_work_width - 1) / std::max(1, options.max_work_width);
}

bool same_size(const Image8& a, int width, int height) { return a.width == width && a.height == height; }

// MatteOptions::MeshPriorOptions::margin_m in pixels: at the mesh's depth in this camera.
double margin_in_pixels(const Camera& camera, const Vertices& world, double margin_m) {
  const Eigen::Vector3d centre = world.colwise().mean().transpose().cast<double>();
  const double depth = camera.world_to_camera.apply(centre).z();
  return depth > 0 ? camera.K(0, 0) * margin_m / depth : 0;
}

}  // namespace

Image8 compute_matte(const Image8& photo, const Image8* clean_plate, const Image8& silhouette, double margin_px,
                     const MatteOptions& options) {
  if (photo.channels != 3) throw Error("compute_matte: the photo must be RGB");
  if (!same_size(silhouette, photo.width, photo.height) || silhouette.channels != 1 ||
      (clean_plate && (!same_size(*clean_plate, photo.width, photo.height) || clean_plate->channels != 3)))
    throw Error("compute_matte: the photo, its clean plate and the mesh silhouette differ in size");
  const int shrink = shrink_for(photo.width, options);
  if (shrink <= 1) {
    const std::optional<Plate> plate = clean_plate ? std::optional(plate_of(*clean_plate)) : std::nullopt;
    return matte_at_this_size(photo, plate ? &*plate : nullptr, silhouette, margin_px, options);
  }
  const int width = photo.width / shrink, height = photo.height / shrink;
  Image8 small_silhouette = resized(silhouette, width, height, cv::INTER_AREA);
  for (auto& p : small_silhouette.pixels) p = p >= 128 ? 255 : 0;
  const Image8 small_plate = clean_plate ? resized(*clean_plate, width, height, cv::INTER_AREA) : Image8();
  const std::optional<Plate> plate = clean_plate ? std::optional(plate_of(small_plate)) : std::nullopt;
  return shrunk_matte(photo, clean_plate, plate ? &*plate : nullptr, small_silhouette, shrink, margin_px, options);
}

CameraMatting::CameraMatting(const Camera& camera, Image8 clean_plate, const MatteOptions& options)
    : camera_(camera), work_camera_(camera), shrink_(shrink_for(camera.width, options)),
      plate_(std::move(clean_plate)), options_(options) {
  if (!plate_.pixels.empty() && (!same_size(plate_, camera.width, camera.height) || plate_.channels != 3))
    throw Error("camera " + camera.name + ": its clean plate is " + std::to_string(plate_.width) + "x" +
                std::to_string(plate_.height) + "x" + std::to_string(plate_.channels) + ", not the camera's " +
                std::to_string(camera.width) + "x" + std::to_string(camera.height) + " RGB");
  if (shrink_ > 1) {
    // The size compute_matte shrinks to; the intrinsics scale by exactly 1/shrink.
    work_camera_ = camera.scaled(1.0 / shrink_);
    work_camera_.width = camera.width / shrink_;
    work_camera_.height = camera.height / shrink_;
    if (!plate_.pixels.empty()) work_plate_ = resized(plate_, work_camera_.width, work_camera_.height, cv::INTER_AREA);
  }
  if (plate_.pixels.empty()) return;
  work_plate_sums_ = Image16(work_plate().width, work_plate().height, 3);
  sums_3x3(view_of(work_plate()))
      .copyTo(cv::Mat(work_plate_sums_.height, work_plate_sums_.width, CV_16UC3, work_plate_sums_.pixels.data()));
}

Image8 CameraMatting::matte(const Image8& photo, const Vertices& world, const Triangles& faces) const {
  if (photo.channels != 3 || !same_size(photo, camera_.width, camera_.height))
    throw Error("camera " + camera_.name + ": the photo is " + std::to_string(photo.width) + "x" +
                std::to_string(photo.height) + "x" + std::to_string(photo.channels) + ", not the camera's " +
                std::to_string(camera_.width) + "x" + std::to_string(camera_.height) + " RGB");
  const double margin_px = margin_in_pixels(camera_, world, options_.mesh.margin_m);
  const Image8* plate = plate_.pixels.empty() ? nullptr : &plate_;
  const Plate work{view_of(work_plate()), cv::Mat(work_plate_sums_.height, work_plate_sums_.width, CV_16UC3,
                                                  const_cast<uint16_t*>(work_plate_sums_.pixels.data()))};
  // The silhouette is rasterised at the working size directly: at 26
  // megapixels the full-size raster costs more than the matte it feeds.
  // Only the surface facing the camera is sure subject: through the head
  // model's open neck a camera below sees whatever is there (the body, or a
  // backdrop), which the clean plate decides.
  const Image8 silhouette = mesh_silhouette(work_camera_, world, faces, Facing::toward_camera);
  if (shrink_ <= 1) return matte_at_this_size(photo, plate ? &work : nullptr, silhouette, margin_px, options_);
  return shrunk_matte(photo, plate, plate ? &work : nullptr, silhouette, shrink_, margin_px, options_);
}

void write_matte(const Image8& alpha, const std::filesystem::path& file) {
  if (alpha.channels != 1) throw Error(file, "a matte has one channel, not " + std::to_string(alpha.channels));
  write_png_view({alpha.pixels.data(), alpha.width, alpha.height, 1, 8, size_t(alpha.width)}, file, 1);
}

}  // namespace tega::matting
