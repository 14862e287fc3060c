// COLMAP text models (docs/rig-files.md#colmap-text-model).
#include <spdlog/fmt/fmt.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <map>
#include <string>

#include "rig_text.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/rig.h"

namespace tega {
namespace {

// COLMAP puts the centre of the top-left pixel at (0.5, 0.5), tega at (0, 0).
constexpr double kColmapPixelOffset = 0.5;

struct Intrinsics {
  int width = 0, height = 0;
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  std::array<double, 5> distortion{};
};

struct ModelLayout {
  std::string_view name;
  size_t parameter_count;
};

constexpr ModelLayout kModels[] = {{"SIMPLE_PINHOLE", 3}, {"PINHOLE", 4}, {"SIMPLE_RADIAL", 4},
                                   {"RADIAL", 5},         {"OPENCV", 8},  {"FULL_OPENCV", 12}};

bool is_data_line(const std::vector<std::string_view>& words) {
  return !words.empty() && words[0][0] != '#';
}

void check_metres_per_unit(double metres_per_unit, const std::filesystem::path& directory) {
  if (!(metres_per_unit > 0) || !std::isfinite(metres_per_unit))
    throw Error(directory, fmt::format("metres_per_unit must be positive, got {}", metres_per_unit));
}

Intrinsics parse_camera(const rig_text::LineReader& in, const std::vector<std::string_view>& words) {
  const std::string_view model = words[1];
  const ModelLayout* layout = nullptr;
  for (const ModelLayout& m : kModels)
    if (m.name == model) layout = &m;
  if (!layout)
    in.fail("unsupported camera model '" + std::string(model) +
            "' (tega reads SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, FULL_OPENCV)");
  if (words.size() != 4 + layout->parameter_count)
    in.fail(fmt::format("camera model {} takes {} parameters, found {}", model,
                        layout->parameter_count, words.size() - 4));
  Intrinsics out;
  out.width = static_cast<int>(in.integer(words[2], "the WIDTH"));
  out.height = static_cast<int>(in.integer(words[3], "the HEIGHT"));
  std::vector<double> p;
  for (size_t i = 4; i < words.size(); ++i)
    p.push_back(in.number(words[i], "a parameter of model " + std::string(model)));

  // Models with one focal length list f, cx, cy; the others fx, fy, cx, cy.
  const bool single_focal = layout->name.starts_with("SIMPLE_") || layout->name == "RADIAL";
  const size_t first_distortion = single_focal ? 3 : 4;
  const double fx = p[0], fy = single_focal ? p[0] : p[1];
  const double cx = p[first_distortion - 2], cy = p[first_distortion - 1];
  out.K << fx, 0, cx - kColmapPixelOffset, 0, fy, cy - kColmapPixelOffset, 0, 0, 1;
  // Distortion follows in OpenCV's order (k1 k2 p1 p2 k3): the radial models stop
  // after k1 or k2, FULL_OPENCV goes on with the rational k4 k5 k6.
  for (size_t i = first_distortion; i < std::min(p.size(), first_distortion + 5); ++i)
    out.distortion[i - first_distortion] = p[i];
  if (model == "FULL_OPENCV" && (p[9] != 0 || p[10] != 0 || p[11] != 0))
    in.fail("FULL_OPENCV with rational distortion (k4, k5, k6 non-zero) is not supported");
  return out;
}

std::map<long, Intrinsics> read_cameras(const std::filesystem::path& file) {
  rig_text::LineReader in(file);
  std::map<long, Intrinsics> cameras;
  while (const std::optional<std::string> line = in.next()) {
    const std::vector<std::string_view> words = rig_text::split_words(*line);
    if (!is_data_line(words)) continue;
    if (words.size() < 4) in.fail("expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]");
    const long id = in.integer(words[0], "a CAMERA_ID");
    if (!cameras.emplace(id, parse_camera(in, words)).second)
      in.fail("CAMERA_ID " + std::to_string(id) + " appears twice");
  }
  return cameras;
}

std::string colmap_camera_line(const Camera& c, size_t id, const std::filesystem::path& file) {
  if (c.K(0, 1) != 0)
    throw Error(file, "camera '" + c.name + "': COLMAP has no skew, but K[0][1] is " +
                          rig_text::format_number(c.K(0, 1)));
  const auto [k1, k2, p1, p2, k3] = c.distortion;
  std::vector<double> params{c.K(0, 0), c.K(1, 1), c.K(0, 2) + kColmapPixelOffset,
                             c.K(1, 2) + kColmapPixelOffset};
  std::string model = "PINHOLE";
  if (k3 != 0) {
    model = "FULL_OPENCV";
    params.insert(params.end(), {k1, k2, p1, p2, k3, 0, 0, 0});
  } else if (c.has_distortion()) {
    model = "OPENCV";
    params.insert(params.end(), {k1, k2, p1, p2});
  }
  return fmt::format("{} {} {} {} {}\n", id, model, c.width, c.height,
                     rig_text::format_numbers(params));
}

// Per camera, the points it sees as (pixel, POINT3D_ID), in order of POINT2D_IDX.
using Observations = std::vector<std::vector<std::pair<Eigen::Vector2d, size_t>>>;

Observations observations_per_camera(const Rig& rig, const std::vector<ColmapPoint>& points,
                                     const std::filesystem::path& file) {
  Observations per_camera(rig.cameras.size());
  for (size_t p = 0; p < points.size(); ++p)
    for (const auto& [camera, pixel] : points[p].observations) {
      if (camera < 0 || static_cast<size_t>(camera) >= rig.cameras.size())
        throw Error(file, fmt::format("point {} is observed by camera index {}, but the rig has {} cameras",
                                      p + 1, camera, rig.cameras.size()));
      per_camera[static_cast<size_t>(camera)].emplace_back(pixel, p + 1);
    }
  return per_camera;
}

std::string colmap_image_lines(const Camera& c, size_t id, double metres_per_unit,
                               std::string_view image_name_suffix,
                               const std::vector<std::pair<Eigen::Vector2d, size_t>>& observations) {
  Eigen::Quaterniond q(c.world_to_camera.R);
  if (q.w() < 0) q.coeffs() *= -1;  // COLMAP writes the hemisphere with QW >= 0
  const Eigen::Vector3d t = c.world_to_camera.t / metres_per_unit;
  std::string points2d;
  for (const auto& [pixel, point_id] : observations)
    points2d += fmt::format("{}{} {}", points2d.empty() ? "" : " ",
                            rig_text::format_numbers({pixel.x() + kColmapPixelOffset,
                                                      pixel.y() + kColmapPixelOffset}),
                            point_id);
  return fmt::format("{} {} {} {}{}\n{}\n", id,
                     rig_text::format_numbers({q.w(), q.x(), q.y(), q.z(), t.x(), t.y(), t.z()}),
                     id, c.name, image_name_suffix, points2d);
}

std::string colmap_points(const std::vector<ColmapPoint>& points, const Observations& per_camera,
                          double metres_per_unit) {
  // A point's track lists (IMAGE_ID, POINT2D_IDX): where it sits in each image's POINTS2D.
  std::vector<std::string> tracks(points.size());
  for (size_t camera = 0; camera < per_camera.size(); ++camera)
    for (size_t index = 0; index < per_camera[camera].size(); ++index)
      tracks[per_camera[camera][index].second - 1] += fmt::format(" {} {}", camera + 1, index);
  std::string text =
      "# 3D point list with one line of data per point:\n"
      "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
      "# Number of points: " + std::to_string(points.size()) + "\n";
  for (size_t p = 0; p < points.size(); ++p)
    text += fmt::format("{} {} 0 0 0 0{}\n", p + 1,
                        rig_text::format_numbers({points[p].position.x() / metres_per_unit,
                                                  points[p].position.y() / metres_per_unit,
                                                  points[p].position.z() / metres_per_unit}),
                        tracks[p]);
  return text;
}

}  // namespace

Rig read_colmap_text(const std::filesystem::path& directory, double metres_per_unit) {
  check_metres_per_unit(metres_per_unit, directory);
  const std::map<long, Intrinsics> intrinsics = read_cameras(directory / "cameras.txt");

  const std::filesystem::path images_file = directory / "images.txt";
  rig_text::LineReader in(images_file);
  Rig rig;
  while (const std::optional<std::string> line = in.next()) {
    const std::vector<std::string_view> words = rig_text::split_words(*line);
    if (!is_data_line(words)) continue;
    if (words.size() != 10)
      in.fail(fmt::format("expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME, found {} values",
                          words.size()));
    in.integer(words[0], "an IMAGE_ID");
    double v[7];
    for (int i = 0; i < 7; ++i) v[i] = in.number(words[1 + i], "a number for QW QX QY QZ TX TY TZ");
    const long camera_id = in.integer(words[8], "a CAMERA_ID");
    const auto found = intrinsics.find(camera_id);
    if (found == intrinsics.end())
      in.fail("CAMERA_ID " + std::to_string(camera_id) + " is not in cameras.txt");
    Eigen::Quaterniond q(v[0], v[1], v[2], v[3]);
    if (!(q.norm() > 0)) in.fail("the quaternion QW QX QY QZ is zero");
    q.normalize();

    Camera camera;
    camera.name = colmap_camera_name(words[9]);
    camera.width = found->second.width;
    camera.height = found->second.height;
    camera.K = found->second.K;
    camera.distortion = found->second.distortion;
    camera.world_to_camera.R = q.toRotationMatrix();
    camera.world_to_camera.t = Eigen::Vector3d(v[4], v[5], v[6]) * metres_per_unit;
    rig.cameras.push_back(std::move(camera));
    in.next();  // the image's POINTS2D line: tega has no use for the observations
  }
  rig.validate(images_file);
  return rig;
}

void write_colmap_text(const Rig& rig, const std::filesystem::path& directory, double metres_per_unit,
                       std::string_view image_name_suffix, const std::vector<ColmapPoint>& points) {
  check_metres_per_unit(metres_per_unit, directory);
  rig.validate(directory);
  const Observations per_camera = observations_per_camera(rig, points, directory / "points3D.txt");
  size_t observation_count = 0;
  for (const auto& seen : per_camera) observation_count += seen.size();
  std::string cameras =
      "# Camera list with one line of data per camera:\n"
      "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
      "# Number of cameras: " + std::to_string(rig.cameras.size()) + "\n";
  std::string images =
      "# Image list with two lines of data per image:\n"
      "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
      "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
      "# Number of images: " + std::to_string(rig.cameras.size()) +
      ", mean observations per image: " +
      rig_text::format_number(static_cast<double>(observation_count) / static_cast<double>(rig.cameras.size())) +
      "\n";
  for (size_t i = 0; i < rig.cameras.size(); ++i) {
    cameras += colmap_camera_line(rig.cameras[i], i + 1, directory / "cameras.txt");
    images += colmap_image_lines(rig.cameras[i], i + 1, metres_per_unit, image_name_suffix, per_camera[i]);
  }

  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (error) throw Error(directory, "cannot create the directory: " + error.message());
  write_text_atomic(directory / "cameras.txt", cameras);
  write_text_atomic(directory / "images.txt", images);
  write_text_atomic(directory / "points3D.txt", colmap_points(points, per_camera, metres_per_unit));
}

std::string colmap_camera_name(std::string_view image_name) {
  const size_t dot = image_name.rfind('.');
  if (dot == std::string_view::npos || dot == 0) return std::string(image_name);
  std::string extension(image_name.substr(dot + 1));
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  constexpr std::string_view kImageExtensions[] = {"png", "jpg", "jpeg", "tif", "tiff", "exr", "bmp"};
  if (std::find(std::begin(kImageExtensions), std::end(kImageExtensions), extension) == std::end(kImageExtensions))
    return std::string(image_name);
  return std::string(image_name.substr(0, dot));
}

}  // namespace tega
