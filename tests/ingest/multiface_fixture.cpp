#include "multiface_fixture.h"

#include <cmath>
#include <cstdio>
#include <limits>

#include "tega/core/files.h"

namespace tega::test {
namespace fs = std::filesystem;

namespace {

constexpr double kRadiusX = 0.075, kRadiusY = 0.10, kRadiusZ = 0.09;  // metres; face towards +z, up +y
constexpr int kRings = 12, kSegments = 24;

// A lat-long ellipsoid with a UV seam at the back of the head: positions are
// shared across the seam, UVs are not (as in Multiface's OBJ files).
Mesh ellipsoid_head() {
  Mesh mesh;
  const int positions = (kRings - 1) * kSegments + 2;
  mesh.positions.resize(positions, 3);
  mesh.uvs.resize((kRings + 1) * (kSegments + 1), 2);
  const auto position_index = [](int ring, int segment) {
    if (ring == 0) return 0;
    if (ring == kRings) return (kRings - 1) * kSegments + 1;
    return 1 + (ring - 1) * kSegments + segment % kSegments;
  };
  const auto uv_index = [](int ring, int segment) { return ring * (kSegments + 1) + segment; };
  for (int r = 0; r <= kRings; ++r) {
    const double polar = M_PI * r / kRings;  // 0 at the crown
    for (int s = 0; s <= kSegments; ++s) {
      const double around = 2 * M_PI * s / kSegments;  // 0 at the back, pi at the face
      mesh.positions.row(position_index(r, s)) << static_cast<float>(kRadiusX * std::sin(polar) * std::sin(around)),
          static_cast<float>(kRadiusY * std::cos(polar)), static_cast<float>(-kRadiusZ * std::sin(polar) * std::cos(around));
      mesh.uvs.row(uv_index(r, s)) << static_cast<float>(s) / kSegments, 1.0f - static_cast<float>(r) / kRings;
    }
  }
  std::vector<std::array<int, 3>> faces, uv_faces;
  for (int r = 0; r < kRings; ++r) {
    for (int s = 0; s < kSegments; ++s) {
      const int a = position_index(r, s), b = position_index(r + 1, s), c = position_index(r + 1, s + 1),
                d = position_index(r, s + 1);
      const int ua = uv_index(r, s), ub = uv_index(r + 1, s), uc = uv_index(r + 1, s + 1), ud = uv_index(r, s + 1);
      if (r != kRings - 1) faces.push_back({a, b, c}), uv_faces.push_back({ua, ub, uc});
      if (r != 0) faces.push_back({a, c, d}), uv_faces.push_back({ua, uc, ud});
    }
  }
  mesh.faces.resize(static_cast<Eigen::Index>(faces.size()), 3);
  mesh.uv_faces.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) {
    mesh.faces.row(static_cast<Eigen::Index>(f)) << faces[f][0], faces[f][1], faces[f][2];
    mesh.uv_faces.row(static_cast<Eigen::Index>(f)) << uv_faces[f][0], uv_faces[f][1], uv_faces[f][2];
  }
  return mesh;
}

// An expression: the lower face pushed out by `amount` metres at most.
Vertices with_expression(const Vertices& neutral, double amount) {
  Vertices v = neutral;
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    const double lower = std::max(0.0, -v(i, 1) / kRadiusY), front = std::max(0.0, v(i, 2) / kRadiusZ);
    v(i, 2) += static_cast<float>(amount * lower * front);
  }
  return v;
}

// The studio: head up +y and face +z in studio coordinates; the world is the
// studio turned by kWorldFromStudio and shifted to kHeadCentre.
const Eigen::Matrix3d& world_from_studio() {
  static const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, 1.0, 0.2).normalized()).toRotationMatrix();
  return R;
}
const Eigen::Vector3d kHeadCentre(0.05, -0.03, 0.9);

// A camera at (azimuth, elevation) from the head, looking at it with its
// image upright. Azimuth turns towards the subject's left (+x).
Camera studio_camera(const std::string& name, double azimuth_deg, double elevation_deg,
                     const MultifaceFixtureOptions& o, int index) {
  const double a = azimuth_deg * M_PI / 180, e = elevation_deg * M_PI / 180, distance = 0.45;
  const Eigen::Vector3d up_studio(0, 1, 0);
  const Eigen::Vector3d position_studio =
      distance * Eigen::Vector3d(std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a));
  const Eigen::Vector3d z = -position_studio.normalized();
  const Eigen::Vector3d y = -(up_studio - up_studio.dot(z) * z).normalized();
  const Eigen::Vector3d x = y.cross(z);
  Eigen::Matrix3d camera_from_studio;
  camera_from_studio << x.transpose(), y.transpose(), z.transpose();

  Camera c;
  c.name = name;
  c.width = o.width;
  c.height = o.height;
  c.K << 350.0 + index, 0.0, o.width / 2.0 - 0.5 + 0.7 * index - 3, 0.0, 351.0 + index, o.height / 2.0 - 0.5 - 0.4 * index + 1,
      0.0, 0.0, 1.0;
  // Strong enough that the head, near the image centre, moves by pixels.
  if (o.distortion) c.distortion = {1.0 + 0.02 * index, 0.1, 0.001, -0.0015, 0.0};
  // world -> camera = (camera <- studio) o (studio <- world)
  c.world_to_camera.R = camera_from_studio * world_from_studio().transpose();
  const Eigen::Vector3d centre_world = world_from_studio() * position_studio + kHeadCentre;
  c.world_to_camera.t = -c.world_to_camera.R * centre_world;
  return c;
}

Eigen::Vector3d checker(const Eigen::Vector2f& uv) {
  const int cell = (static_cast<int>(std::floor(uv.x() * 24)) + static_cast<int>(std::floor(uv.y() * 12))) & 1;
  return cell ? Eigen::Vector3d(0.9, 0.75 * uv.y() + 0.2, 0.3) : Eigen::Vector3d(0.2, 0.35, 0.8 * uv.x() + 0.1);
}

// Z-buffered triangles between projected (distorted) vertices, coloured by a
// texture lookup in UV, or 255 for coverage.
Image8 rasterize(const Camera& camera, const Mesh& topology, const Vertices& world, bool coverage_only) {
  Image8 image(camera.width, camera.height, coverage_only ? 1 : 3, 0);
  std::vector<double> depth(static_cast<size_t>(camera.width) * camera.height, std::numeric_limits<double>::infinity());
  if (!coverage_only) {
    for (int y = 0; y < camera.height; ++y)
      for (int x = 0; x < camera.width; ++x) image.at(x, y, 0) = 40, image.at(x, y, 1) = 60, image.at(x, y, 2) = 90;
  }
  for (Eigen::Index f = 0; f < topology.faces.rows(); ++f) {
    Eigen::Vector2d p[3];
    double z[3];
    bool visible = true;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d w = world.row(topology.faces(f, k)).transpose().cast<double>();
      const auto pixel = camera.project(w);
      if (!pixel) visible = false;
      else p[k] = *pixel, z[k] = camera.world_to_camera.apply(w).z();
    }
    if (!visible) continue;
    const double area = (p[1] - p[0]).x() * (p[2] - p[0]).y() - (p[1] - p[0]).y() * (p[2] - p[0]).x();
    if (area == 0) continue;
    const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({p[0].x(), p[1].x(), p[2].x()}))));
    const int x1 = std::min(camera.width - 1, static_cast<int>(std::floor(std::max({p[0].x(), p[1].x(), p[2].x()}))));
    const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({p[0].y(), p[1].y(), p[2].y()}))));
    const int y1 = std::min(camera.height - 1, static_cast<int>(std::floor(std::max({p[0].y(), p[1].y(), p[2].y()}))));
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        double b[3];
        for (int k = 0; k < 3; ++k) {
          const Eigen::Vector2d& q = p[(k + 1) % 3];
          const Eigen::Vector2d& r = p[(k + 2) % 3];
          b[k] = ((r - q).x() * (y - q.y()) - (r - q).y() * (x - q.x())) / area;
        }
        if (b[0] < 0 || b[1] < 0 || b[2] < 0) continue;
        const double d = b[0] * z[0] + b[1] * z[1] + b[2] * z[2];
        double& stored = depth[static_cast<size_t>(y) * camera.width + x];
        if (d >= stored) continue;
        stored = d;
        if (coverage_only) {
          image.at(x, y, 0) = 255;
          continue;
        }
        Eigen::Vector2f uv = Eigen::Vector2f::Zero();
        for (int k = 0; k < 3; ++k) uv += static_cast<float>(b[k]) * topology.uvs.row(topology.uv_faces(f, k)).transpose();
        const Eigen::Vector3d colour = checker(uv);
        for (int c = 0; c < 3; ++c) image.at(x, y, c) = static_cast<uint8_t>(std::lround(255 * colour[c]));
      }
    }
  }
  return image;
}

std::string six_digits(int n) {
  char text[16];
  std::snprintf(text, sizeof text, "%06d", n);
  return text;
}

}  // namespace

Vertices MultifaceFixture::world(const std::string& frame_id) const {
  return transformed(poses.at(frame_id), head_space.at(frame_id));
}

Image8 MultifaceFixture::render(const Camera& camera, const std::string& frame_id) const {
  return rasterize(camera, head, world(frame_id), false);
}

Image8 MultifaceFixture::coverage(const Camera& camera, const std::string& frame_id) const {
  return rasterize(camera, head, world(frame_id), true);
}

MultifaceFixture write_multiface_fixture(const fs::path& root, const MultifaceFixtureOptions& options) {
  MultifaceFixture fixture;
  fixture.root = root;
  fixture.head = ellipsoid_head();
  const Vertices neutral = fixture.head.positions;

  const double ring_azimuths[] = {-75, -50, -25, 0, 25, 50, 75};
  int index = 0;
  for (double azimuth : ring_azimuths) {
    const std::string name = std::to_string(400002 + 2 * index);
    fixture.rig.cameras.push_back(studio_camera(name, azimuth, 5.0 * (index % 3), options, index));
    fixture.ring.push_back(name);
    ++index;
  }
  fixture.behind = "400016";
  fixture.rig.cameras.push_back(studio_camera(fixture.behind, 180, 10, options, index++));
  fixture.above = "400018";
  fixture.rig.cameras.push_back(studio_camera(fixture.above, 0, 80, options, index++));
  write_krt(fixture.rig, root / "KRT");

  std::string frame_list;
  int number = 102;
  int sequence_index = 0;
  for (const char* sequence : {MultifaceFixture::kNeutral, MultifaceFixture::kTrainExpression,
                               MultifaceFixture::kTestExpression}) {
    for (int k = 0; k < options.frames_per_sequence; ++k, number += 3) {
      const ingest::MultifaceFrame frame{sequence, six_digits(number)};
      fixture.frames.push_back(frame);
      frame_list += frame.sequence + " " + frame.frame + "\n";
      const double step = static_cast<double>(fixture.frames.size() - 1);
      // The first neutral frame is the neutral itself.
      fixture.head_space[frame.id()] = with_expression(neutral, 0.004 * sequence_index + 0.002 * k);
      RigidTransform head_from_studio_pose;
      head_from_studio_pose.R = Eigen::AngleAxisd(0.04 * std::sin(step), Eigen::Vector3d::UnitY()).toRotationMatrix() *
                                Eigen::AngleAxisd(0.03 * std::cos(step), Eigen::Vector3d::UnitX()).toRotationMatrix();
      head_from_studio_pose.t = Eigen::Vector3d(0.004 * std::sin(step), 0.002 * step / 8, -0.003 * std::cos(step));
      RigidTransform pose;
      pose.R = world_from_studio() * head_from_studio_pose.R;
      pose.t = world_from_studio() * head_from_studio_pose.t + kHeadCentre;
      fixture.poses[frame.id()] = pose;

      // Multiface's files: millimetres, head space, with the pose beside them.
      Vertices millimetres = fixture.head_space[frame.id()] * 1000.0f;
      const ingest::MultifaceCapture capture{root};
      write_vertices_bin(millimetres, capture.mesh_bin(frame));
      Mesh obj = fixture.head;
      obj.positions = millimetres;
      write_obj(obj, capture.mesh_obj(frame));
      std::string transform;
      for (int r = 0; r < 3; ++r) {
        char row[160];
        std::snprintf(row, sizeof row, "%.9f %.9f %.9f %.6f\n", pose.R(r, 0), pose.R(r, 1), pose.R(r, 2),
                      pose.t(r) * 1000.0);
        transform += row;
      }
      write_text_atomic(capture.transform(frame), transform);
      for (const Camera& camera : fixture.rig.cameras)
        write_image(fixture.render(camera, frame.id()), capture.image(camera.name, frame));
    }
    ++sequence_index;
  }
  fixture.head.positions = neutral;
  write_text_atomic(root / "frame_list.txt", frame_list);
  return fixture;
}

}  // namespace tega::test
