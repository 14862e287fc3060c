// The built-in head: a bust (head ellipsoid, facial features as smooth
// bumps, ears, neck) sampled on a latitude/longitude grid whose UV seam runs
// down the back of the head, plus two eyeball spheres that poke a few
// millimetres out of the eye sockets. Expressions are smooth displacement
// fields of the neutral positions, so the coarse mesh can carry them.

#include <cmath>
#include <functional>
#include <numbers>

#include "tega/synth/head.h"
#include "tega/synth/random.h"

namespace tega::synth {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kColumns = 88;  // around the head
constexpr int kRows = 72;     // pole to pole
constexpr int kEyeLatitudes = 12;
constexpr int kEyeLongitudes = 16;
constexpr double kEyeRadius = 0.0125;
constexpr double kEyeProtrusion = 0.0035;  // eyeball front beyond the socket's skin
const Eigen::Vector2d kEyeLeft{0.032, 0.022};  // (x, y); the right eye mirrors it
constexpr double kSkinUvBottom = 0.2;           // skin uses v in [0.2, 1]; eyeballs below

double gauss2(double dx, double dy, double sx, double sy) {
  return std::exp(-0.5 * (dx * dx / (sx * sx) + dy * dy / (sy * sy)));
}

// The undeformed bust for s in [0, 1] (top to bottom) and azimuth a
// (0 at the back of the head, pi at the face).
Eigen::Vector3d bust_point(double s, double a) {
  constexpr double head_end = 0.72, theta_end = 0.78 * kPi;
  constexpr double ry = 0.112, rx_head = 0.078, rzf_head = 0.098, rzb_head = 0.090, y_head = 0.01;
  double y, rx, rzf, rzb, zshift = 0;
  if (s <= head_end) {
    const double th = s / head_end * theta_end;
    y = y_head + ry * std::cos(th);
    rx = rx_head * std::sin(th);
    rzf = rzf_head * std::sin(th);
    rzb = rzb_head * std::sin(th);
  } else {
    const double t = (s - head_end) / (1 - head_end);
    const double y0 = y_head + ry * std::cos(theta_end), k = std::sin(theta_end);
    const double b = smoothstep(0.0, 0.35, t);
    y = y0 + (-0.21 - y0) * t;
    rx = rx_head * k + (0.05 - rx_head * k) * b;
    rzf = rzf_head * k + (0.052 - rzf_head * k) * b;
    rzb = rzb_head * k + (0.050 - rzb_head * k) * b;
    zshift = -0.018 * b;
  }
  const double dx = -std::sin(a), dz = -std::cos(a);
  Eigen::Vector3d p(rx * dx, y, (dz > 0 ? rzf : rzb) * dz + zshift);

  // Facial features push the front of the surface forwards or back.
  const double front = smoothstep(0.2, 0.6, dz);
  double bump = 0;
  bump += 0.024 * gauss2(p.x(), p.y() + 0.005, 0.011, 0.022);        // nose bridge and body
  bump += 0.008 * gauss2(p.x(), p.y() + 0.022, 0.009, 0.008);        // nose tip
  bump += 0.008 * gauss2(p.x(), p.y() + 0.076, 0.016, 0.012);        // chin
  bump += 0.005 * gauss2(p.x(), p.y() + 0.040, 0.016, 0.005);        // upper lip
  bump += 0.004 * gauss2(p.x(), p.y() + 0.052, 0.014, 0.005);        // lower lip
  for (double side : {-1.0, 1.0}) {
    bump -= 0.010 * gauss2(p.x() - side * kEyeLeft.x(), p.y() - kEyeLeft.y(), 0.016, 0.011);  // sockets
    bump += 0.004 * gauss2(p.x() - side * 0.030, p.y() - 0.040, 0.022, 0.007);  // brow ridges
    bump += 0.004 * gauss2(p.x() - side * 0.045, p.y() + 0.005, 0.015, 0.015);  // cheekbones
  }
  p.z() += front * bump;

  const double side_weight = smoothstep(0.75, 0.95, std::abs(dx));
  p.x() += (dx > 0 ? 1 : -1) * 0.012 * side_weight * gauss2(p.y(), p.z() + 0.005, 0.022, 0.015);  // ears
  return p;
}

// Skin depth in front of (x, y) on the face, by search over the bust.
double face_z_at(const Eigen::Vector2d& xy) {
  double best = 1e9, z = 0;
  for (double s = 0.25; s <= 0.55; s += 0.0005) {
    for (double a = kPi - 0.8; a <= kPi + 0.8; a += 0.001) {
      const Eigen::Vector3d p = bust_point(s, a);
      const double d = (p.head<2>() - xy).squaredNorm();
      if (d < best) best = d, z = p.z();
    }
  }
  return z;
}

struct MeshBuilder {
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector2f> uvs;
  std::vector<Eigen::Vector3i> faces, uv_faces;

  void triangle(const Eigen::Vector3i& f, const Eigen::Vector3i& uvf) {
    faces.push_back(f);
    uv_faces.push_back(uvf);
  }
  Mesh build() const {
    Mesh m;
    m.positions.resize(positions.size(), 3);
    for (size_t i = 0; i < positions.size(); ++i) m.positions.row(i) = positions[i].transpose();
    m.uvs.resize(uvs.size(), 2);
    for (size_t i = 0; i < uvs.size(); ++i) m.uvs.row(i) = uvs[i].transpose();
    m.faces.resize(faces.size(), 3);
    m.uv_faces.resize(faces.size(), 3);
    for (size_t i = 0; i < faces.size(); ++i) {
      m.faces.row(i) = faces[i].transpose();
      m.uv_faces.row(i) = uv_faces[i].transpose();
      m.triangle_polygon.push_back(static_cast<int32_t>(i));
    }
    return m;
  }
};

void add_skin(MeshBuilder& b) {
  const auto vertex = [](int row, int column) {
    if (row == 0) return 0;
    if (row == kRows) return 1 + (kRows - 1) * kColumns;
    return 1 + (row - 1) * kColumns + column % kColumns;
  };
  b.positions.push_back(bust_point(0, 0).cast<float>());
  for (int i = 1; i < kRows; ++i)
    for (int j = 0; j < kColumns; ++j)
      b.positions.push_back(bust_point(double(i) / kRows, 2 * kPi * j / kColumns).cast<float>());
  b.positions.push_back(bust_point(1, 0).cast<float>());

  // UVs keep the seam: column kColumns repeats column 0's positions at u = 1.
  const auto uv = [](int row, int column) { return row * (kColumns + 1) + column; };
  for (int i = 0; i <= kRows; ++i)
    for (int j = 0; j <= kColumns; ++j)
      b.uvs.emplace_back(float(j) / kColumns, float(1.0 - double(i) / kRows * (1 - kSkinUvBottom)));

  for (int i = 0; i < kRows; ++i) {
    for (int j = 0; j < kColumns; ++j) {
      const Eigen::Vector3i lower(vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1));
      const Eigen::Vector3i lower_uv(uv(i, j), uv(i + 1, j), uv(i + 1, j + 1));
      const Eigen::Vector3i upper(vertex(i, j), vertex(i + 1, j + 1), vertex(i, j + 1));
      const Eigen::Vector3i upper_uv(uv(i, j), uv(i + 1, j + 1), uv(i, j + 1));
      // At the poles one triangle of each quad collapses: the fans keep one per column.
      if (i > 0) b.triangle(upper, upper_uv);
      if (i < kRows - 1) b.triangle(lower, lower_uv);
    }
  }
}

// A UV sphere around `centre` with its pole (the pupil) looking along +z,
// textured by its own UV island [u0, u1] x [0.01, kSkinUvBottom - 0.01].
void add_eyeball(MeshBuilder& b, const Eigen::Vector3d& centre, double u0, double u1) {
  const int first = static_cast<int>(b.positions.size());
  const int first_uv = static_cast<int>(b.uvs.size());
  const double v0 = 0.01, v1 = kSkinUvBottom - 0.01;
  for (int i = 0; i <= kEyeLatitudes; ++i) {
    const double phi = kPi * i / kEyeLatitudes;
    for (int j = 0; j <= kEyeLongitudes; ++j) {
      const double lambda = 2 * kPi * j / kEyeLongitudes;
      if (j < kEyeLongitudes)
        b.positions.push_back((centre + kEyeRadius * Eigen::Vector3d(std::sin(phi) * std::cos(lambda),
                                                                     std::sin(phi) * std::sin(lambda),
                                                                     std::cos(phi)))
                                  .cast<float>());
      b.uvs.emplace_back(float(u0 + (u1 - u0) * j / kEyeLongitudes),
                         float(v1 - (v1 - v0) * i / kEyeLatitudes));
    }
  }
  // Poles are kept as rings of coincident vertices: simple, and harmless.
  const auto vertex = [&](int i, int j) { return first + i * kEyeLongitudes + j % kEyeLongitudes; };
  const auto uv = [&](int i, int j) { return first_uv + i * (kEyeLongitudes + 1) + j; };
  for (int i = 0; i < kEyeLatitudes; ++i) {
    for (int j = 0; j < kEyeLongitudes; ++j) {
      // Seen from outside at the front pole, longitude turns counter-clockwise
      // and latitude moves outwards, so this winding faces outwards.
      if (i > 0) b.triangle({vertex(i, j), vertex(i + 1, j + 1), vertex(i, j + 1)},
                            {uv(i, j), uv(i + 1, j + 1), uv(i, j + 1)});
      if (i < kEyeLatitudes - 1) b.triangle({vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1)},
                                            {uv(i, j), uv(i + 1, j), uv(i + 1, j + 1)});
    }
  }
}

// Displacements act on the skin only; the front weight keeps them off the
// back of the head.
Vertices skin_delta(const Mesh& neutral, int skin_vertices,
                    const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& field) {
  Vertices d = Vertices::Zero(neutral.num_vertices(), 3);
  for (int i = 0; i < skin_vertices; ++i) {
    const Eigen::Vector3d p = neutral.positions.row(i).cast<double>().transpose();
    d.row(i) = (smoothstep(0.0, 0.05, p.z()) * field(p)).cast<float>().transpose();
  }
  return d;
}

}  // namespace

Head make_procedural_head() {
  MeshBuilder b;
  add_skin(b);
  const int skin_vertices = static_cast<int>(b.positions.size());
  const int skin_faces = static_cast<int>(b.faces.size());
  const double eye_z = face_z_at(kEyeLeft) - kEyeRadius + kEyeProtrusion;
  const Eigen::Vector3d eye_left(kEyeLeft.x(), kEyeLeft.y(), eye_z);
  const Eigen::Vector3d eye_right(-kEyeLeft.x(), kEyeLeft.y(), eye_z);
  add_eyeball(b, eye_left, 0.52, 0.98);
  add_eyeball(b, eye_right, 0.02, 0.48);

  Head head;
  head.source = "procedural";
  head.model.neutral = b.build();
  for (int f = skin_faces; f < head.model.neutral.num_faces(); ++f) head.eyeball_faces.push_back(f);

  const Mesh& neutral = head.model.neutral;
  const double eye_front_z = eye_z + kEyeRadius;
  const auto add = [&](const std::string& name, const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& f) {
    head.model.expression_names.push_back(name);
    head.model.expression_deltas.push_back(skin_delta(neutral, skin_vertices, f));
  };
  for (const auto& [suffix, side] : {std::pair{"_L", 1.0}, std::pair{"_R", -1.0}}) {
    const Eigen::Vector2d eye(side * kEyeLeft.x(), kEyeLeft.y());
    // The lid: skin over the eye opening moves forwards over the eyeball
    // (and slightly down); a flat-topped window keeps the whole opening shut.
    add(std::string("eyeBlink") + suffix, [=](const Eigen::Vector3d& p) -> Eigen::Vector3d {
      const double q = std::pow((p.x() - eye.x()) / 0.015, 2) + std::pow((p.y() - eye.y()) / 0.010, 2);
      const double w = std::exp(-q * q);
      return Eigen::Vector3d(0, -0.002 * w, std::max(0.0, eye_front_z + 0.0015 - p.z()) * w);
    });
    add(std::string("browInnerUp") + suffix, [=](const Eigen::Vector3d& p) -> Eigen::Vector3d {
      return Eigen::Vector3d(0, 0.007, 0.001) * gauss2(p.x() - side * 0.013, p.y() - 0.042, 0.013, 0.014);
    });
    add(std::string("browOuterUp") + suffix, [=](const Eigen::Vector3d& p) -> Eigen::Vector3d {
      return Eigen::Vector3d(0, 0.007, 0) * gauss2(p.x() - side * 0.038, p.y() - 0.040, 0.014, 0.014);
    });
    add(std::string("mouthSmile") + suffix, [=](const Eigen::Vector3d& p) -> Eigen::Vector3d {
      return Eigen::Vector3d(side * 0.005, 0.006, -0.003) * gauss2(p.x() - side * 0.022, p.y() + 0.046, 0.014, 0.012);
    });
  }
  // The jaw turns about a left-right axis behind the mouth; the weight fades
  // above the mouth, towards the back and down the neck.
  add("jawOpen", [](const Eigen::Vector3d& p) -> Eigen::Vector3d {
    const double angle = 20.0 * kPi / 180.0;
    const Eigen::Vector3d axis_point(0, -0.035, -0.01);
    const Eigen::Vector3d r = p - axis_point;
    const Eigen::Vector3d turned(r.x(), r.y() * std::cos(angle) - r.z() * std::sin(angle),
                                 r.y() * std::sin(angle) + r.z() * std::cos(angle));
    const double w = smoothstep(-0.038, -0.060, p.y()) * smoothstep(-0.17, -0.10, p.y()) *
                     smoothstep(-0.01, 0.04, p.z());
    return Eigen::Vector3d(w * (turned - r));
  });

  finish_head(head);
  // The lips part where the jaw opens: a dark, recessed gap.
  WrinkleRegion mouth;
  mouth.name = "mouth_gap";
  mouth.drivers = {"jawOpen"};
  mouth.centre = {0, (-0.046 - kEyeLeft.y()) / head.frame.interocular};
  mouth.sigma = {0.3, 0.12};
  mouth.groove_width = 0.06;
  mouth.depth_scale = 3.0;
  mouth.darkening_scale = 1.6;
  head.wrinkles.push_back(mouth);
  return head;
}

}  // namespace tega::synth
