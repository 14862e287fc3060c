#include "tega/tools/gaussian_spz.h"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "tega/core/error.h"
#include "tega/core/files.h"

namespace tega::tools {

namespace {

namespace fs = std::filesystem;

constexpr uint32_t kMagic = 0x5053474e;  // "NGSP" read as a little-endian uint32
constexpr uint32_t kVersion = 2;
constexpr size_t kHeaderBytes = 16;
constexpr uint8_t kFlagAntialiased = 0x1;
constexpr uint8_t kFlagExtensions = 0x2;  // newer writers: extension records follow the header
constexpr int kFractionalBits = 12;       // steps of 1/4096 m (0.24 mm), positions within ±2048 m
constexpr int32_t kLargestFixed = (1 << 23) - 1;
// SPZ stores the DC coefficient times 0.15 rather than times SH C0 (0.282):
// colours a little outside [0, 1], which the higher bands bring back, still fit.
constexpr float kColorScale = 0.15f;
// Higher SH coefficients are steps of 1/128 in [-1, 1], of which the degree-1
// ones keep 5 bits (every 8th step) and those of degrees 2 and 3 keep 4 bits.
constexpr int kDegree1Bucket = 8, kHigherBucket = 16;
// Opacities SPZ rounds to 0 or 255 (fully transparent or opaque) have no
// finite logit; the reader takes the edge of their rounding interval instead.
constexpr double kOpacityFloor = 0.5 / 255;
// Deflate expands its input at most 1032-fold: a header claiming more
// Gaussians than that is corrupt, and is rejected before allocating for them.
constexpr uint64_t kMaxDeflateRatio = 1032;

// Sign of each higher SH coefficient under the half turn about x (y -> -y,
// z -> -z): the parity in y and z of its basis function, in 3DGS's order.
constexpr std::array<float, 15> kHalfTurnShSign{
    -1, -1, 1,                 // y, z, x
    -1, 1, 1, -1, 1,           // xy, yz, 3z²-1, xz, x²-y²
    -1, 1, -1, -1, 1, -1, 1};  // y(3x²-y²), xyz, y(5z²-1), z(5z²-3), x(5z²-1), z(x²-y²), x(x²-3y²)

uint8_t to_byte(double x) { return static_cast<uint8_t>(std::clamp(std::round(x), 0.0, 255.0)); }

// SPZ's rounding: to the nearest 1/128 step, then half up to the bucket's multiple.
uint8_t quantize_sh(float x, int bucket) {
  const int step = static_cast<int>(std::round(std::clamp(x, -1.0f, 1.0f) * 128.0f)) + 128;
  return static_cast<uint8_t>(std::min((step + bucket / 2) / bucket * bucket, 255));
}

void put_u32(std::vector<uint8_t>& bytes, uint32_t v) {
  for (int shift = 0; shift < 32; shift += 8) bytes.push_back(static_cast<uint8_t>(v >> shift));
}

uint32_t get_u32(const uint8_t* p) { return p[0] | p[1] << 8 | p[2] << 16 | static_cast<uint32_t>(p[3]) << 24; }

int64_t bytes_per_gaussian(int64_t higher_coefficients) { return 9 + 1 + 3 + 3 + 3 + 3 * higher_coefficients; }

void check_finite(const at::Tensor& t, const char* what, const fs::path& file) {
  if (!at::isfinite(t).all().item<bool>()) throw Error(file, std::string("cannot be written: the cloud has non-finite ") + what);
}

// The uncompressed stream: header, then each attribute for all Gaussians.
std::vector<uint8_t> pack(const GaussianCloud& spz_frame, bool antialiased, const fs::path& file) {
  const int64_t n = spz_frame.size();
  const int64_t higher = spz_frame.sh.size(1) - 1;
  if (n > UINT32_MAX) throw Error(file, "cannot hold " + std::to_string(n) + " Gaussians (SPZ counts them in 32 bits)");
  std::vector<uint8_t> bytes;
  bytes.reserve(kHeaderBytes + n * bytes_per_gaussian(higher));
  put_u32(bytes, kMagic);
  put_u32(bytes, kVersion);
  put_u32(bytes, static_cast<uint32_t>(n));
  bytes.push_back(static_cast<uint8_t>(spz_frame.sh_degree()));
  bytes.push_back(kFractionalBits);
  bytes.push_back(antialiased ? kFlagAntialiased : 0);
  bytes.push_back(0);  // reserved

  const float* means = spz_frame.means.data_ptr<float>();
  for (int64_t i = 0; i < 3 * n; ++i) {
    const double fixed = std::round(static_cast<double>(means[i]) * (1 << kFractionalBits));
    if (std::abs(fixed) > kLargestFixed)
      throw Error(file, "cannot hold a Gaussian " + std::to_string(std::abs(means[i])) +
                            " m from the origin along an axis: SPZ's positions reach ±2048 m");
    const auto v = static_cast<int32_t>(fixed);  // 24-bit two's complement, little-endian
    for (int shift = 0; shift < 24; shift += 8) bytes.push_back(static_cast<uint8_t>(v >> shift));
  }
  const float* logits = spz_frame.opacity_logit.data_ptr<float>();
  for (int64_t i = 0; i < n; ++i) bytes.push_back(to_byte(255.0 / (1.0 + std::exp(-static_cast<double>(logits[i])))));
  const float* sh = spz_frame.sh.data_ptr<float>();
  const int64_t sh_stride = 3 * (higher + 1);
  for (int64_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) bytes.push_back(to_byte(sh[i * sh_stride + c] * (kColorScale * 255.0) + 127.5));
  const float* log_scales = spz_frame.log_scale.data_ptr<float>();
  for (int64_t i = 0; i < 3 * n; ++i) bytes.push_back(to_byte((log_scales[i] + 10.0) * 16.0));
  // x, y, z of the unit quaternion with w >= 0 (w follows from them).
  const float* rotations = spz_frame.rotation.data_ptr<float>();
  for (int64_t i = 0; i < n; ++i) {
    const float* q = rotations + 4 * i;
    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (norm == 0) throw Error(file, "cannot be written: Gaussian " + std::to_string(i) + " has a zero quaternion");
    const double scale = (q[0] < 0 ? -127.5 : 127.5) / norm;
    for (int k = 1; k < 4; ++k) bytes.push_back(to_byte(q[k] * scale + 127.5));
  }
  // Coefficient-major, channel-minor: r, g, b of coefficient 1, then of 2, ...
  for (int64_t i = 0; i < n; ++i)
    for (int64_t k = 1; k <= higher; ++k)
      for (int c = 0; c < 3; ++c)
        bytes.push_back(quantize_sh(sh[i * sh_stride + 3 * k + c], k <= 3 ? kDegree1Bucket : kHigherBucket));
  return bytes;
}

void write_gzip(const std::vector<uint8_t>& data, const fs::path& temp, const fs::path& file) {
  std::ofstream out(temp, std::ios::binary);
  z_stream stream{};
  // windowBits 16 + 15: a gzip header and trailer around the deflate stream.
  if (deflateInit2(&stream, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    throw Error(file, "could not be written: zlib failed to start");
  std::vector<uint8_t> chunk(1 << 16);
  size_t offset = 0;
  int flush = Z_NO_FLUSH;
  while (flush != Z_FINISH) {
    const size_t take = std::min<size_t>(data.size() - offset, 1u << 30);  // avail_in is 32-bit
    stream.next_in = const_cast<Bytef*>(data.data() + offset);
    stream.avail_in = static_cast<uInt>(take);
    offset += take;
    flush = offset == data.size() ? Z_FINISH : Z_NO_FLUSH;
    do {
      stream.next_out = chunk.data();
      stream.avail_out = static_cast<uInt>(chunk.size());
      deflate(&stream, flush);  // cannot fail with valid buffers
      out.write(reinterpret_cast<const char*>(chunk.data()),
                static_cast<std::streamsize>(chunk.size() - stream.avail_out));
    } while (stream.avail_out == 0);
  }
  deflateEnd(&stream);
  if (!out) throw Error(file, "could not be written");
}

// Inflates a gzip file on demand, naming the file in every error.
class GzipReader {
 public:
  GzipReader(std::vector<uint8_t> compressed, fs::path file) : compressed_(std::move(compressed)), file_(std::move(file)) {
    if (compressed_.size() < 2 || compressed_[0] != 0x1f || compressed_[1] != 0x8b)
      throw Error(file_, "is not gzip-compressed (an SPZ file is a gzip stream)");
    if (inflateInit2(&stream_, 16 + MAX_WBITS) != Z_OK) throw Error(file_, "could not be read: zlib failed to start");
    stream_.next_in = compressed_.data();
    stream_.avail_in = static_cast<uInt>(std::min<size_t>(compressed_.size(), UINT32_MAX));
  }
  ~GzipReader() { inflateEnd(&stream_); }
  GzipReader(const GzipReader&) = delete;
  GzipReader& operator=(const GzipReader&) = delete;

  size_t compressed_size() const { return compressed_.size(); }

  // Fills `out` with the next `size` bytes, the `what` of the file.
  void read(uint8_t* out, size_t size, const std::string& what) {
    while (size > 0) {
      if (ended_) throw Error(file_, "is truncated: its data ends inside the " + what);
      const size_t take = std::min<size_t>(size, UINT32_MAX);
      stream_.next_out = out;
      stream_.avail_out = static_cast<uInt>(take);
      step("the " + what);
      const size_t produced = take - stream_.avail_out;
      out += produced;
      size -= produced;
    }
  }

  // Inflates what is left (trailing data no reader needs) to check the
  // stream's end and its CRC.
  void finish() {
    std::array<uint8_t, 1 << 14> sink;
    while (!ended_) {
      stream_.next_out = sink.data();
      stream_.avail_out = static_cast<uInt>(sink.size());
      step("its gzip trailer");
    }
  }

 private:
  void step(const std::string& where) {
    const int result = inflate(&stream_, Z_NO_FLUSH);
    if (result == Z_STREAM_END) ended_ = true;
    else if (result == Z_BUF_ERROR) throw Error(file_, "is truncated: its gzip data ends inside " + where);
    else if (result != Z_OK)
      throw Error(file_, std::string("has corrupt gzip data (") + (stream_.msg ? stream_.msg : "zlib error") + ")");
  }

  std::vector<uint8_t> compressed_;
  fs::path file_;
  z_stream stream_{};
  bool ended_ = false;
};

std::vector<uint8_t> read_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(file, "cannot be opened");
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw Error(file, "could not be read");
  return bytes;
}

std::string hex(uint32_t v) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%08x", v);
  return text;
}

}  // namespace

// Tega's frame is x right, y down, z forward; SPZ's x right, y up, z back.
// The half turn is a proper rotation: scales are untouched.
GaussianCloud half_turn_about_x(const GaussianCloud& c) {
  const int64_t k = c.sh.size(1);
  const at::Tensor sh_sign = at::cat({at::ones({1}), at::tensor(at::ArrayRef<float>(kHalfTurnShSign.data(), k - 1))});
  GaussianCloud turned = c;
  turned.means = c.means * at::tensor({1.f, -1.f, -1.f});
  turned.rotation = c.rotation * at::tensor({1.f, 1.f, -1.f, -1.f});  // (w, x, y, z) of D R D, D = diag(1, -1, -1)
  turned.sh = c.sh * sh_sign.view({1, k, 1});
  return turned;
}

void write_gaussian_spz(const GaussianCloud& cloud, const fs::path& file, bool antialiased) {
  const GaussianCloud c = cloud.to(at::kCPU, at::kFloat);
  check_finite(c.means, "means", file);
  check_finite(c.sh, "SH coefficients", file);
  check_finite(c.opacity_logit, "opacity logits", file);
  check_finite(c.log_scale, "log scales", file);
  check_finite(c.rotation, "rotations", file);
  GaussianCloud spz_frame = half_turn_about_x(c);
  for (at::Tensor* t : {&spz_frame.means, &spz_frame.sh, &spz_frame.opacity_logit, &spz_frame.log_scale,
                        &spz_frame.rotation})
    *t = t->contiguous();
  const std::vector<uint8_t> bytes = pack(spz_frame, antialiased, file);
  write_file_atomic(file, [&](const fs::path& temp) { write_gzip(bytes, temp, file); });
}

SpzCloud read_gaussian_spz(const fs::path& file) {
  GzipReader in(read_bytes(file), file);
  std::array<uint8_t, kHeaderBytes> header;
  in.read(header.data(), header.size(), "16-byte header");
  const uint32_t magic = get_u32(&header[0]);
  if (magic != kMagic)
    throw Error(file, "is not an SPZ file: its magic number is " + hex(magic) + ", not " + hex(kMagic) + " (\"NGSP\")");
  const uint32_t version = get_u32(&header[4]);
  if (version != kVersion)
    throw Error(file, "is SPZ version " + std::to_string(version) + "; tega reads version " + std::to_string(kVersion));
  const int64_t n = get_u32(&header[8]);
  const int degree = header[12], fractional_bits = header[13], flags = header[14];
  if (degree > 3) throw Error(file, "has SH degree " + std::to_string(degree) + "; tega reads degrees 0 to 3");
  if (fractional_bits > 23)
    throw Error(file, "has " + std::to_string(fractional_bits) + " fractional bits; 24-bit positions hold at most 23");
  if (flags & kFlagExtensions) throw Error(file, "has SPZ extensions (flag 0x2), which tega does not read");
  const int64_t higher = (degree + 1) * (degree + 1) - 1;
  if (static_cast<uint64_t>(n * bytes_per_gaussian(higher)) > kMaxDeflateRatio * in.compressed_size())
    throw Error(file, "claims " + std::to_string(n) + " Gaussians, more than its " +
                          std::to_string(in.compressed_size()) + " compressed bytes can hold");

  std::vector<uint8_t> positions(9 * n), alphas(n), colors(3 * n), scales(3 * n), rotations(3 * n), sh(3 * higher * n);
  in.read(positions.data(), positions.size(), "positions");
  in.read(alphas.data(), alphas.size(), "opacities");
  in.read(colors.data(), colors.size(), "colours");
  in.read(scales.data(), scales.size(), "scales");
  in.read(rotations.data(), rotations.size(), "rotations");
  in.read(sh.data(), sh.size(), "SH coefficients");
  in.finish();

  GaussianCloud c;
  c.means = at::empty({n, 3});
  c.sh = at::empty({n, higher + 1, 3});
  c.opacity_logit = at::empty({n});
  c.log_scale = at::empty({n, 3});
  c.rotation = at::empty({n, 4});
  float* means = c.means.data_ptr<float>();
  const double step = 1.0 / (1 << fractional_bits);
  for (int64_t i = 0; i < 3 * n; ++i) {
    const uint8_t* b = &positions[3 * i];
    int32_t fixed = b[0] | b[1] << 8 | b[2] << 16;
    if (fixed & 0x800000) fixed -= 1 << 24;  // sign of the 24-bit value
    means[i] = static_cast<float>(fixed * step);
  }
  float* logits = c.opacity_logit.data_ptr<float>();
  for (int64_t i = 0; i < n; ++i) {
    const double opacity = std::clamp(alphas[i] / 255.0, kOpacityFloor, 1 - kOpacityFloor);
    logits[i] = static_cast<float>(std::log(opacity / (1 - opacity)));
  }
  float* coefficients = c.sh.data_ptr<float>();
  const int64_t sh_stride = 3 * (higher + 1);
  for (int64_t i = 0; i < n; ++i)
    for (int ch = 0; ch < 3; ++ch)
      coefficients[i * sh_stride + ch] = static_cast<float>((colors[3 * i + ch] / 255.0 - 0.5) / kColorScale);
  for (int64_t i = 0; i < n; ++i)
    for (int64_t j = 0; j < 3 * higher; ++j)
      coefficients[i * sh_stride + 3 + j] = static_cast<float>((sh[3 * higher * i + j] - 128) / 128.0);
  float* log_scales = c.log_scale.data_ptr<float>();
  for (int64_t i = 0; i < 3 * n; ++i) log_scales[i] = static_cast<float>(scales[i] / 16.0 - 10.0);
  float* quaternions = c.rotation.data_ptr<float>();
  for (int64_t i = 0; i < n; ++i) {
    std::array<double, 3> xyz;
    double squared = 0;
    for (int k = 0; k < 3; ++k) {
      xyz[k] = rotations[3 * i + k] / 127.5 - 1;
      squared += xyz[k] * xyz[k];
    }
    // Rounding can take x, y, z a little beyond the unit sphere: then w = 0 and xyz is renormalised.
    const double shrink = squared > 1 ? 1 / std::sqrt(squared) : 1;
    quaternions[4 * i] = static_cast<float>(std::sqrt(std::max(0.0, 1 - squared)));
    for (int k = 0; k < 3; ++k) quaternions[4 * i + 1 + k] = static_cast<float>(xyz[k] * shrink);
  }
  return {half_turn_about_x(c), (flags & kFlagAntialiased) != 0};
}

}  // namespace tega::tools
