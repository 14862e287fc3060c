#include "tega/serve/frame_stream.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include "tega/core/error.h"

namespace tega::serve {

static_assert(std::endian::native == std::endian::little, "the stream is little-endian and written by memcpy");

namespace {

constexpr char kStaticMagic[4] = {'T', 'G', 'S', 'S'};
constexpr char kFrameMagic[4] = {'T', 'G', 'S', 'F'};
constexpr size_t kStaticHeader = 28;
constexpr size_t kFrameHeader = 52;
constexpr double kPositionSteps = 65535, kByteSteps = 255, kRotationSteps = 1023;
const double kSqrt2 = std::sqrt(2.0);

int sh_coefficients(int degree) { return (degree + 1) * (degree + 1); }

template <typename T>
void put(std::string& out, size_t offset, T value) {
  std::memcpy(out.data() + offset, &value, sizeof(T));
}

template <typename T>
T get(std::string_view in, size_t offset) {
  T value;
  std::memcpy(&value, in.data() + offset, sizeof(T));
  return value;
}

void check_finite(const std::vector<float>& values, const char* name) {
  for (float v : values)
    if (!std::isfinite(v)) throw Error(std::string("frame stream: non-finite ") + name);
}

// [lo, hi] of `values`, every `stride`-th from `first`, as float32 (what the stream stores).
std::array<float, 2> range(const std::vector<float>& values, size_t first, size_t stride, float floor) {
  float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
  for (size_t i = first; i < values.size(); i += stride) {
    const float v = std::max(values[i], floor);
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  if (lo > hi) return {0.0f, 0.0f};  // no Gaussians
  return {lo, hi};
}

uint32_t quantise(double value, float lo, float hi, double steps) {
  if (!(hi > lo)) return 0;
  const double q = std::round((value - lo) / (double(hi) - lo) * steps);
  return static_cast<uint32_t>(std::clamp(q, 0.0, steps));
}

double dequantise(uint32_t code, float lo, float hi, double steps) { return lo + code * ((double(hi) - lo) / steps); }

// Smallest three: the largest component (made positive) is left out and
// recovered from the unit norm; the others lie within ±1/√2.
uint32_t pack_rotation(const float* q) {
  double c[4] = {q[0], q[1], q[2], q[3]};
  const double norm = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2] + c[3] * c[3]);
  int largest = 0;
  for (int k = 0; k < 4; ++k) {
    c[k] = norm > 0 ? c[k] / norm : (k == 0 ? 1.0 : 0.0);
    if (std::abs(c[k]) > std::abs(c[largest])) largest = k;
  }
  const double sign = c[largest] < 0 ? -1.0 : 1.0;
  uint32_t packed = static_cast<uint32_t>(largest) << 30;
  int shift = 20;
  for (int k = 0; k < 4; ++k) {
    if (k == largest) continue;
    const double unit = (sign * c[k] * kSqrt2 + 1.0) / 2.0;
    packed |= static_cast<uint32_t>(std::clamp(std::round(unit * kRotationSteps), 0.0, kRotationSteps)) << shift;
    shift -= 10;
  }
  return packed;
}

void unpack_rotation(uint32_t packed, float* q) {
  const int largest = static_cast<int>(packed >> 30);
  double c[4], sum = 0;
  int shift = 20;
  for (int k = 0; k < 4; ++k) {
    if (k == largest) continue;
    c[k] = (((packed >> shift) & 1023u) / kRotationSteps * 2.0 - 1.0) / kSqrt2;
    sum += c[k] * c[k];
    shift -= 10;
  }
  c[largest] = std::sqrt(std::max(0.0, 1.0 - sum));
  for (int k = 0; k < 4; ++k) q[k] = static_cast<float>(c[k]);
}

void check_header(std::string_view bytes, const char* magic, size_t header, const std::string& what) {
  if (bytes.size() < header) throw Error(what + ": " + std::to_string(bytes.size()) + " bytes, shorter than its header");
  if (std::memcmp(bytes.data(), magic, 4) != 0)
    throw Error(what + ": not a tega frame stream (magic " + std::string(magic, 4) + " expected)");
  if (const uint32_t version = get<uint32_t>(bytes, 4); version != kStreamVersion)
    throw Error(what + ": stream version " + std::to_string(version) + ", this tega reads " +
                std::to_string(kStreamVersion));
}

void check_size(std::string_view bytes, size_t expected, const std::string& what) {
  if (bytes.size() != expected)
    throw Error(what + ": " + std::to_string(bytes.size()) + " bytes where its header says " + std::to_string(expected));
}

}  // namespace

std::string encode_static(const StaticPart& part) {
  const int64_t n = part.size();
  if (part.sh_degree < 0 || part.sh_degree > 3) throw Error("frame stream: SH degree " + std::to_string(part.sh_degree));
  const size_t k = sh_coefficients(part.sh_degree);
  if (part.sh.size() != size_t(n) * k * 3) throw Error("frame stream: SH coefficients do not match the Gaussians");
  check_finite(part.opacities, "opacity");
  check_finite(part.sh, "SH coefficient");
  std::string out(kStaticHeader + 4 * (part.opacities.size() + part.sh.size()), '\0');
  std::memcpy(out.data(), kStaticMagic, 4);
  put<uint32_t>(out, 4, kStreamVersion);
  put<uint32_t>(out, 8, static_cast<uint32_t>(n));
  put<uint8_t>(out, 12, static_cast<uint8_t>(part.sh_degree));
  put<uint8_t>(out, 13, part.antialiased ? 1 : 0);
  for (int c = 0; c < 3; ++c) put<float>(out, 16 + 4 * c, part.background[c]);
  std::memcpy(out.data() + kStaticHeader, part.opacities.data(), 4 * part.opacities.size());
  std::memcpy(out.data() + kStaticHeader + 4 * part.opacities.size(), part.sh.data(), 4 * part.sh.size());
  return out;
}

StaticPart decode_static(std::string_view bytes, const std::string& what) {
  check_header(bytes, kStaticMagic, kStaticHeader, what);
  StaticPart part;
  const size_t n = get<uint32_t>(bytes, 8);
  part.sh_degree = get<uint8_t>(bytes, 12);
  if (part.sh_degree > 3) throw Error(what + ": SH degree " + std::to_string(part.sh_degree));
  part.antialiased = (get<uint8_t>(bytes, 13) & 1) != 0;
  for (int c = 0; c < 3; ++c) part.background[c] = get<float>(bytes, 16 + 4 * c);
  const size_t sh = n * sh_coefficients(part.sh_degree) * 3;
  check_size(bytes, kStaticHeader + 4 * (n + sh), what);
  part.opacities.resize(n);
  part.sh.resize(sh);
  std::memcpy(part.opacities.data(), bytes.data() + kStaticHeader, 4 * n);
  std::memcpy(part.sh.data(), bytes.data() + kStaticHeader + 4 * n, 4 * sh);
  return part;
}

std::string encode_frame(const FramePart& part) {
  const size_t n = part.shading.size();
  if (part.means.size() != 3 * n || part.log_scales.size() != 3 * n || part.rotations.size() != 4 * n)
    throw Error("frame stream: a frame's means, scales, rotations and shading differ in count");
  check_finite(part.means, "position");
  check_finite(part.log_scales, "log scale");
  check_finite(part.rotations, "rotation");
  check_finite(part.shading, "shading");
  const float no_floor = std::numeric_limits<float>::lowest();
  std::array<std::array<float, 2>, 3> box;
  for (int a = 0; a < 3; ++a) box[a] = range(part.means, a, 3, no_floor);
  const auto scales = range(part.log_scales, 0, 1, static_cast<float>(kMinStreamLogScale));
  const auto shading = range(part.shading, 0, 1, no_floor);

  std::string out(kFrameHeader + 14 * n, '\0');
  std::memcpy(out.data(), kFrameMagic, 4);
  put<uint32_t>(out, 4, kStreamVersion);
  put<uint32_t>(out, 8, static_cast<uint32_t>(n));
  for (int a = 0; a < 3; ++a) {
    put<float>(out, 12 + 4 * a, box[a][0]);
    put<float>(out, 24 + 4 * a, box[a][1]);
  }
  put<float>(out, 36, scales[0]);
  put<float>(out, 40, scales[1]);
  put<float>(out, 44, shading[0]);
  put<float>(out, 48, shading[1]);
  const size_t rotations = kFrameHeader, positions = rotations + 4 * n, log_scales = positions + 6 * n,
               shades = log_scales + 3 * n;
  for (size_t i = 0; i < n; ++i) {
    put<uint32_t>(out, rotations + 4 * i, pack_rotation(&part.rotations[4 * i]));
    for (int a = 0; a < 3; ++a) {
      put<uint16_t>(out, positions + 2 * (3 * i + a),
                    static_cast<uint16_t>(quantise(part.means[3 * i + a], box[a][0], box[a][1], kPositionSteps)));
      const double log_scale = std::max(double(part.log_scales[3 * i + a]), kMinStreamLogScale);
      put<uint8_t>(out, log_scales + 3 * i + a,
                   static_cast<uint8_t>(quantise(log_scale, scales[0], scales[1], kByteSteps)));
    }
    put<uint8_t>(out, shades + i, static_cast<uint8_t>(quantise(part.shading[i], shading[0], shading[1], kByteSteps)));
  }
  return out;
}

FramePart decode_frame(std::string_view bytes, const std::string& what) {
  check_header(bytes, kFrameMagic, kFrameHeader, what);
  const size_t n = get<uint32_t>(bytes, 8);
  check_size(bytes, kFrameHeader + 14 * n, what);
  std::array<float, 3> lo, hi;
  for (int a = 0; a < 3; ++a) {
    lo[a] = get<float>(bytes, 12 + 4 * a);
    hi[a] = get<float>(bytes, 24 + 4 * a);
  }
  const float scale_lo = get<float>(bytes, 36), scale_hi = get<float>(bytes, 40);
  const float shade_lo = get<float>(bytes, 44), shade_hi = get<float>(bytes, 48);
  FramePart part;
  part.means.resize(3 * n);
  part.log_scales.resize(3 * n);
  part.rotations.resize(4 * n);
  part.shading.resize(n);
  const size_t rotations = kFrameHeader, positions = rotations + 4 * n, log_scales = positions + 6 * n,
               shades = log_scales + 3 * n;
  for (size_t i = 0; i < n; ++i) {
    unpack_rotation(get<uint32_t>(bytes, rotations + 4 * i), &part.rotations[4 * i]);
    for (int a = 0; a < 3; ++a) {
      part.means[3 * i + a] = static_cast<float>(
          dequantise(get<uint16_t>(bytes, positions + 2 * (3 * i + a)), lo[a], hi[a], kPositionSteps));
      part.log_scales[3 * i + a] =
          static_cast<float>(dequantise(get<uint8_t>(bytes, log_scales + 3 * i + a), scale_lo, scale_hi, kByteSteps));
    }
    part.shading[i] = static_cast<float>(dequantise(get<uint8_t>(bytes, shades + i), shade_lo, shade_hi, kByteSteps));
  }
  return part;
}

FrameTolerance frame_tolerance(std::string_view encoded_frame, const std::string& what) {
  check_header(encoded_frame, kFrameMagic, kFrameHeader, what);
  const auto half_step = [&](size_t lo_offset, size_t hi_offset, double steps) {
    return 0.5 * (double(get<float>(encoded_frame, hi_offset)) - get<float>(encoded_frame, lo_offset)) / steps;
  };
  FrameTolerance t;
  for (int a = 0; a < 3; ++a) t.position[a] = half_step(12 + 4 * a, 24 + 4 * a, kPositionSteps);
  t.log_scale = half_step(36, 40, kByteSteps);
  t.shading = half_step(44, 48, kByteSteps);
  t.rotation_component = 0.5 * kSqrt2 / kRotationSteps;
  return t;
}

}  // namespace tega::serve
