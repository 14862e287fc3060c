// SPZ export (tega/tools/gaussian_spz.h): round trips within the format's
// quantisation, the bytes of a hand-made cloud against values worked out by
// hand from Niantic's reference layout, the frame conversion against the
// rasterizer, renders against the PLY's, and corrupt files.

#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <utility>
#include <vector>

#include "tega/core/error.h"
#include "tega/tools/export.h"
#include "tega/tools/gaussian_ply.h"
#include "tega/tools/gaussian_spz.h"
#include "test_support.h"
#include "tiny_avatar.h"

namespace {

using namespace tega;
using namespace tega::tools;
namespace fs = std::filesystem;

std::vector<uint8_t> file_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const fs::path& file, const std::vector<uint8_t>& bytes) {
  std::ofstream out(file, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

// zlib directly, independent of the code under test: gzip's windowBits 16 + 15.
std::vector<uint8_t> gunzip(const std::vector<uint8_t>& compressed) {
  z_stream s{};
  EXPECT_EQ(inflateInit2(&s, 16 + MAX_WBITS), Z_OK);
  std::vector<uint8_t> out(1 << 20);
  s.next_in = const_cast<Bytef*>(compressed.data());
  s.avail_in = static_cast<uInt>(compressed.size());
  s.next_out = out.data();
  s.avail_out = static_cast<uInt>(out.size());
  EXPECT_EQ(inflate(&s, Z_FINISH), Z_STREAM_END);
  out.resize(s.total_out);
  inflateEnd(&s);
  return out;
}

std::vector<uint8_t> gzip(const std::vector<uint8_t>& data) {
  z_stream s{};
  EXPECT_EQ(deflateInit2(&s, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY), Z_OK);
  std::vector<uint8_t> out(deflateBound(&s, data.size()));
  s.next_in = const_cast<Bytef*>(data.data());
  s.avail_in = static_cast<uInt>(data.size());
  s.next_out = out.data();
  s.avail_out = static_cast<uInt>(out.size());
  EXPECT_EQ(deflate(&s, Z_FINISH), Z_STREAM_END);
  out.resize(s.total_out);
  deflateEnd(&s);
  return out;
}

// A random cloud over SPZ's whole range: positions within ±3 m, opacities from
// 1e-5 to 1 - 1e-5 (beyond SPZ's 0.5/255 from 0 and 1), log scales over
// [-10, 5], DC coefficients within ±3.3, higher coefficients within [-1, 1],
// rotations uniform and unnormalised, with either sign of w.
GaussianCloud random_cloud(int64_t n, int degree) {
  const int64_t k = (degree + 1) * (degree + 1);
  GaussianCloud c;
  c.means = (at::rand({n, 3}) * 2 - 1) * 3;
  c.sh = at::cat({(at::rand({n, 1, 3}) * 2 - 1) * 3.3, (at::rand({n, k - 1, 3}) * 2 - 1)}, 1);
  c.opacity_logit = (at::rand({n}) * 2 - 1) * 11.5;
  c.log_scale = at::rand({n, 3}) * 15 - 10;
  c.rotation = at::randn({n, 4}) * (at::rand({n, 1}) + 0.5);
  return c;
}

// Per row, the sign (+1 or -1) that brings `b`'s quaternion nearer to `a`'s.
at::Tensor nearer_sign(const at::Tensor& a, const at::Tensor& b) {
  return at::where((a - b).norm(2, 1, true).le((a + b).norm(2, 1, true)), at::ones({1}), -at::ones({1}));
}

double max_abs(const at::Tensor& t) { return t.abs().max().item<double>(); }

TEST(GaussianSpz, RoundTripIsWithinTheFormatsQuantisation) {
  test::TempDir tmp;
  at::manual_seed(11);
  for (int degree = 0; degree <= 3; ++degree) {
    SCOPED_TRACE("SH degree " + std::to_string(degree));
    const GaussianCloud cloud = random_cloud(2000, degree);
    const fs::path file = tmp / ("cloud" + std::to_string(degree) + ".spz");
    const bool antialiased = degree % 2 == 1;
    write_gaussian_spz(cloud, file, antialiased);
    const SpzCloud read = read_gaussian_spz(file);
    const GaussianCloud& back = read.gaussians;
    ASSERT_EQ(back.size(), cloud.size());
    ASSERT_EQ(back.sh_degree(), degree);
    EXPECT_EQ(read.antialiased, antialiased);
    constexpr double kFloat = 1e-6;  // float32 rounding of values of a few units

    // Positions: 24-bit fixed point with 12 fractional bits, half a step of 1/4096 m.
    EXPECT_LE(max_abs(back.means - cloud.means), std::ldexp(1.0, -13) + kFloat);
    // Opacity: sigmoid(logit) in steps of 1/255, half a step; bytes 0 and 255 read as 0.5/255 from 0 and 1.
    EXPECT_LE(max_abs(back.opacities() - cloud.opacities()), 0.5 / 255 + kFloat);
    EXPECT_TRUE(at::isfinite(back.opacity_logit).all().item<bool>());
    // DC: steps of 1/(0.15 * 255) of the coefficient, half a step.
    EXPECT_LE(max_abs(back.sh.select(1, 0) - cloud.sh.select(1, 0)), 0.5 / (0.15 * 255) + kFloat);
    // Log scales: steps of 1/16, half a step.
    EXPECT_LE(max_abs(back.log_scale - cloud.log_scale), 1.0 / 32 + kFloat);
    // Higher SH: rounded to 1/128 (half a step), then to a multiple of 8 steps
    // for degree 1 (4 more) and of 16 for degrees 2 and 3 (8 more).
    if (degree >= 1) EXPECT_LE(max_abs(back.sh.slice(1, 1, 4) - cloud.sh.slice(1, 1, 4)), 4.5 / 128 + kFloat);
    if (degree >= 2) EXPECT_LE(max_abs(back.sh.slice(1, 4) - cloud.sh.slice(1, 4)), 8.5 / 128 + kFloat);
    // Rotations, as ±q of the unit quaternion: x, y, z in steps of 1/127.5,
    // half a step, and up to |xyz| - 1 <= sqrt(3)/255 more where rounding took
    // them outside the unit sphere and they are renormalised. w = sqrt(1 - |xyz|²)
    // moves by at most sqrt(2 |xyz| |Δxyz| + |Δxyz|²) <= sqrt(2 sqrt(3)/255 + 3/255²).
    const at::Tensor unit = cloud.rotation / cloud.rotation.norm(2, 1, true);
    const at::Tensor expected = unit * nearer_sign(back.rotation, unit);
    EXPECT_LE(max_abs(back.rotation.norm(2, 1) - 1), kFloat);
    EXPECT_LE(max_abs(back.rotation.slice(1, 1) - expected.slice(1, 1)), (1 + std::sqrt(3.0)) / 255 + kFloat);
    EXPECT_LE(max_abs(back.rotation.select(1, 0) - expected.select(1, 0)),
              std::sqrt(2 * std::sqrt(3.0) / 255 + 3.0 / (255 * 255)) + kFloat);
  }
}

TEST(GaussianSpz, ValuesBeyondTheFormatAreClampedOrRefused) {
  test::TempDir tmp;
  GaussianCloud c = random_cloud(3, 1);
  c.log_scale[0] = at::tensor({-27.6f, 7.0f, 0.0f});  // a flat Gaussian (tega's 1e-24 variance floor); 1100 m
  c.sh[0][1] = at::tensor({1.5f, -2.0f, 0.0f});
  c.sh[0][0] = at::tensor({5.0f, -5.0f, 0.0f});
  write_gaussian_spz(c, tmp / "clamped.spz", false);
  const GaussianCloud back = read_gaussian_spz(tmp / "clamped.spz").gaussians;
  EXPECT_FLOAT_EQ(back.log_scale[0][0].item<float>(), -10.0f);
  EXPECT_FLOAT_EQ(back.log_scale[0][1].item<float>(), 255 / 16.0f - 10);
  EXPECT_FLOAT_EQ(back.sh[0][0][0].item<float>(), 0.5f / 0.15f);
  EXPECT_FLOAT_EQ(back.sh[0][0][1].item<float>(), -0.5f / 0.15f);
  // Byte 255 (127/128) at the top, byte 0 (-1) at the bottom; the y-basis coefficient changes sign in SPZ's frame.
  EXPECT_FLOAT_EQ(back.sh[0][1][0].item<float>(), 1.0f);
  EXPECT_FLOAT_EQ(back.sh[0][1][1].item<float>(), -127.0f / 128);

  c.means[1][2] = 2048.1f;
  const std::string message = test::error_message([&] { write_gaussian_spz(c, tmp / "far.spz", false); });
  EXPECT_NE(message.find("far.spz"), std::string::npos) << message;
  EXPECT_NE(message.find("2048"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(tmp / "far.spz"));
}

// Two Gaussians of SH degree 1, their bytes worked out by hand from the layout
// of nianticlabs/spz (load-spz.cc): tega's (x, y, z) is SPZ's (x, -y, -z).
TEST(GaussianSpz, FileHoldsTheReferenceLayoutInSpzsFrame) {
  test::TempDir tmp;
  const double half_angle = M_PI / 6;  // a 60° turn about tega's y axis
  GaussianCloud c;
  c.means = at::tensor({0.5f, 0.25f, 1.0f, -1.0f, 0.0f, 2047.0f}).view({2, 3});
  c.sh = at::zeros({2, 4, 3});
  c.sh[0][0] = at::tensor({0.0f, 1.0f, -1.0f});   // DC
  c.sh[0][1] = at::tensor({0.5f, 0.0f, 0.0f});    // the y basis function's coefficient
  c.sh[0][2] = at::tensor({0.25f, 0.0f, 0.0f});   // z's
  c.sh[0][3] = at::tensor({0.25f, -0.3f, 0.0f});  // x's
  c.opacity_logit = at::tensor({0.0f, 20.0f});
  c.log_scale = at::tensor({-2.0f, -2.0f, -2.0f, -10.0f, 0.0f, 5.0f}).view({2, 3});
  const float cos = static_cast<float>(std::cos(half_angle)), sin = static_cast<float>(std::sin(half_angle));
  c.rotation = at::tensor({cos, 0.0f, sin, 0.0f, -cos, 0.0f, -sin, 0.0f}).view({2, 4});  // the same turn, ±q
  write_gaussian_spz(c, tmp / "two.spz", true);

  const std::vector<uint8_t> compressed = file_bytes(tmp / "two.spz");
  ASSERT_GE(compressed.size(), 2u);
  EXPECT_EQ(compressed[0], 0x1f);  // gzip
  EXPECT_EQ(compressed[1], 0x8b);
  const std::vector<uint8_t> b = gunzip(compressed);
  const std::vector<uint8_t> expected{
      // header: "NGSP", version 2, 2 points, degree 1, 12 fractional bits, antialiased, reserved
      0x4e, 0x47, 0x53, 0x50, 2, 0, 0, 0, 2, 0, 0, 0, 1, 12, 1, 0,
      // positions ×4096, 24-bit little-endian: (2048, -1024, -4096), (-4096, 0, -8384512)
      0x00, 0x08, 0x00, 0x00, 0xfc, 0xff, 0x00, 0xf0, 0xff, 0x00, 0xf0, 0xff, 0x00, 0x00, 0x00, 0x00, 0x10, 0x80,
      // opacity ×255: 127.5 rounds to 128; sigmoid(20) to 255
      128, 255,
      // DC ×(0.15 · 255) + 127.5: 0 -> 128, 1 -> 165.75, -1 -> 89.25; then zeros
      128, 166, 89, 128, 128, 128,
      // (log scale + 10) ×16, clamped to [0, 255]
      128, 128, 128, 0, 160, 240,
      // x, y, z ×127.5 + 127.5 of the quaternion with w >= 0: (cos, 0, -sin, 0) in SPZ's frame, both
      128, 64, 128, 128, 64, 128,
      // degree 1, coefficient-major, 1/128 steps around 128 in buckets of 8: y's 0.5 -> -0.5 -> 64,
      // z's 0.25 -> -0.25 -> 96, x's (0.25, -0.3) -> 160, round(-38.4) + 128 = 90 -> 88
      64, 128, 128, 96, 128, 128, 160, 88, 128,
      128, 128, 128, 128, 128, 128, 128, 128, 128};
  EXPECT_EQ(b, expected);
}

// A camera looking at the origin from 1.2 m; `spz_frame` flips its world's y and z.
Camera spz_probe_camera(bool spz_frame) {
  Camera c;
  c.name = "probe";
  c.width = 64;
  c.height = 48;
  c.K << 60, 0, 31.5, 0, 60, 23.5, 0, 0, 1;
  c.world_to_camera.R = Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.3, 1, 0.2).normalized()).toRotationMatrix();
  c.world_to_camera.t = Eigen::Vector3d(0, 0, 1.2);
  if (spz_frame) c.world_to_camera.R = c.world_to_camera.R * Eigen::Vector3d(1, -1, -1).asDiagonal();
  return c;
}

// Gaussians a few centimetres wide within 0.3 m of the origin, every SH band well away from zero.
GaussianCloud probe_cloud() {
  at::manual_seed(5);
  GaussianCloud c = random_cloud(300, 3);
  c.means = (at::rand({300, 3}) * 2 - 1) * 0.3;
  c.log_scale = at::log(at::rand({300, 3}) * 0.03 + 0.01);
  c.sh = at::cat({at::randn({300, 1, 3}) * 0.8, at::randn({300, 15, 3}) * 0.3}, 1);
  c.opacity_logit = at::randn({300}) * 2;
  return c;
}

// The half turn is a change of frame: the turned cloud seen from the turned
// camera renders as before, view-dependent colour included. A wrong sign in
// any SH band, quaternion or position component shows.
TEST(GaussianSpz, HalfTurnIsAChangeOfFrame) {
  const GaussianCloud cloud = probe_cloud();
  const at::Tensor background = at::full({3}, 0.1);
  const at::Tensor expected = render_cloud(cloud, spz_probe_camera(false), background, false);
  const at::Tensor turned = render_cloud(half_turn_about_x(cloud), spz_probe_camera(true), background, false);
  ASSERT_GT((expected - 0.1).abs().mean().item<double>(), 0.05) << "the cloud must be in view";
  EXPECT_LE(max_abs(turned - expected), 1e-4);
  // Without the change of frame the view differs: the test can tell.
  EXPECT_GT(max_abs(render_cloud(cloud, spz_probe_camera(true), background, false) - expected), 0.1);
  // And every SH band has coefficients that change sign.
  const GaussianCloud turned_cloud = half_turn_about_x(cloud);
  for (const auto& [first, end] : {std::pair{1, 4}, std::pair{4, 9}, std::pair{9, 16}})
    EXPECT_GT(max_abs(turned_cloud.sh.slice(1, first, end) - cloud.sh.slice(1, first, end)), 0.1) << first;
}

double psnr(const at::Tensor& image, const at::Tensor& reference) {
  return -10 * std::log10((image - reference).pow(2).mean().item<double>());
}

// An avatar's frame exported to both formats: the SPZ renders within 30 dB of
// the PLY from the front and from behind (measured 32.4 and 33.1 dB). Version
// 2's 8-bit rotations dominate the difference: with the PLY's rotations the
// SPZ's other attributes alone give 37.0 and 38.5 dB.
TEST(GaussianSpz, ExportedFrameRendersLikeThePly) {
  test::TinyAvatar avatar;
  Vertices vertices = avatar.dataset.load_mesh("blink_000000");
  const trainer::FrameInput frame =
      avatar.model().frame_input(vertices, avatar.dataset.frame("blink_000000").head_to_world);
  const GaussianCloud cloud = export_frame(avatar.model(), frame, trainer::Phase{true, true, 3});
  write_gaussian_ply(cloud, avatar.tmp / "frame.ply");
  write_gaussian_spz(cloud, avatar.tmp / "frame.spz", false);
  const GaussianCloud ply = read_gaussian_ply(avatar.tmp / "frame.ply");
  const GaussianCloud spz = read_gaussian_spz(avatar.tmp / "frame.spz").gaussians;

  Camera camera = spz_probe_camera(false);
  camera.world_to_camera.t = -camera.world_to_camera.R * Eigen::Vector3d(0.33, 0.33, 0) + Eigen::Vector3d(0, 0, 1.2);
  Camera behind = camera;
  behind.world_to_camera.R = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix() * camera.world_to_camera.R;
  behind.world_to_camera.t = -behind.world_to_camera.R * Eigen::Vector3d(0.33, 0.33, 0) + Eigen::Vector3d(0, 0, 1.2);
  const at::Tensor background = at::zeros({3});
  for (const auto& [name, view] : {std::pair{"front", camera}, std::pair{"behind", behind}}) {
    const at::Tensor reference = render_cloud(ply, view, background, false);
    ASSERT_GT(reference.mean().item<double>(), 0.05) << "the avatar must be in view";
    const double db = psnr(render_cloud(spz, view, background, false), reference);
    RecordProperty(std::string("psnr_db_") + name, std::to_string(db));
    EXPECT_GE(db, 30.0) << name;
  }
}

struct SpzFiles {
  test::TempDir tmp;
  fs::path good = tmp / "good.spz";
  std::vector<uint8_t> stream;  // good.spz uncompressed

  SpzFiles() {
    at::manual_seed(3);
    write_gaussian_spz(random_cloud(50, 2), good, false);
    stream = gunzip(file_bytes(good));
  }
  // `bytes` gzipped as `name`: the error reading it.
  std::string error_reading(const std::string& name, const std::vector<uint8_t>& bytes, bool compress = true) {
    write_bytes(tmp / name, compress ? gzip(bytes) : bytes);
    const std::string message = test::error_message([&] { read_gaussian_spz(tmp / name); });
    EXPECT_NE(message.find((tmp / name).string()), std::string::npos) << message;
    return message;
  }
};

TEST(GaussianSpz, ReaderNamesTheFileAndWhatIsWrong) {
  SpzFiles f;
  ASSERT_EQ(f.stream.size(), 16u + 50 * (19 + 3 * 8));
  EXPECT_EQ(read_gaussian_spz(f.good).gaussians.size(), 50);  // the unchanged stream reads

  std::vector<uint8_t> bytes = f.stream;
  bytes[0] = 'X';
  EXPECT_NE(f.error_reading("magic.spz", bytes).find("magic"), std::string::npos);

  bytes = f.stream;
  bytes[4] = 3;
  const std::string version = f.error_reading("version.spz", bytes);
  EXPECT_NE(version.find("version 3"), std::string::npos) << version;

  bytes = f.stream;
  bytes[14] = 0x2;
  EXPECT_NE(f.error_reading("extensions.spz", bytes).find("extensions"), std::string::npos);

  // A whole gzip stream whose data stops inside the rotations.
  bytes.assign(f.stream.begin(), f.stream.begin() + 16 + 50 * (9 + 1 + 3 + 3 + 2));
  const std::string short_data = f.error_reading("short.spz", bytes);
  EXPECT_NE(short_data.find("truncated"), std::string::npos) << short_data;
  EXPECT_NE(short_data.find("rotations"), std::string::npos) << short_data;

  // The file cut: the gzip stream itself ends early.
  const std::vector<uint8_t> compressed = file_bytes(f.good);
  const std::string cut = f.error_reading("cut.spz", {compressed.begin(), compressed.begin() + compressed.size() / 2}, false);
  EXPECT_NE(cut.find("truncated"), std::string::npos) << cut;

  // A flipped bit in the compressed data: zlib's checks catch it.
  std::vector<uint8_t> flipped = compressed;
  flipped[flipped.size() / 2] ^= 0x10;
  const std::string corrupt = f.error_reading("flipped.spz", flipped, false);
  EXPECT_TRUE(corrupt.find("corrupt") != std::string::npos || corrupt.find("truncated") != std::string::npos) << corrupt;

  // Not gzip at all: the uncompressed stream, or a PLY named .spz.
  EXPECT_NE(f.error_reading("plain.spz", f.stream, false).find("not gzip"), std::string::npos);
  test::write_text(f.tmp / "ply.spz", "ply\nformat ascii 1.0\n");
  EXPECT_NE(test::error_message([&] { read_gaussian_spz(f.tmp / "ply.spz"); }).find("not gzip"), std::string::npos);
  EXPECT_NE(test::error_message([&] { read_gaussian_spz(f.tmp / "missing.spz"); }).find("missing.spz"),
            std::string::npos);
}

}  // namespace
