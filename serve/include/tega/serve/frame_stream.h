#pragma once
// The compact stream `tega serve` sends a browser: a run's static part once
// (opacities and unshaded SH coefficients, float32) and, per frame, only what
// the frame changes, quantised: positions (16 bits an axis in the frame's
// bounding box), log scales (8 bits over the frame's range), rotations
// (smallest three, 10 bits each, in 32 bits) and the dynamic shading S
// (8 bits over the frame's range). Byte by byte in
// docs/render-eval-export.md#frame-stream. A Gaussian's colour from a view is
// S·max(SH(dir) + 0.5, 0), as the avatar renders it.
//
// Plain C++ (no torch): the codec and its tests need no model.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace tega::serve {

inline constexpr uint32_t kStreamVersion = 1;
inline constexpr double kMinStreamLogScale = -14.0;  // σ = 0.8 µm: thinner axes are sent as this

struct StaticPart {
  int sh_degree = 0;
  bool antialiased = false;               // the run trained with Mip-Splatting's 2D filter
  std::array<float, 3> background{};      // the run's background, linear RGB
  std::vector<float> opacities;           // [N] in (0, 1)
  std::vector<float> sh;                  // [N][K][3], K = (degree + 1)², without the shading

  int64_t size() const { return static_cast<int64_t>(opacities.size()); }
};

struct FramePart {
  std::vector<float> means;       // [N][3] world, metres
  std::vector<float> log_scales;  // [N][3] log standard deviations
  std::vector<float> rotations;   // [N][4] unit quaternion (w, x, y, z)
  std::vector<float> shading;     // [N] S > 0 (all 1 when the run has no shading)

  int64_t size() const { return static_cast<int64_t>(shading.size()); }
};

// Throw tega::Error for inconsistent sizes or non-finite values.
std::string encode_static(const StaticPart& part);
std::string encode_frame(const FramePart& part);

// Decode what the encoders wrote; throw tega::Error naming `what` (a file or
// URL) for a bad magic number, another version or a wrong size.
StaticPart decode_static(std::string_view bytes, const std::string& what);
FramePart decode_frame(std::string_view bytes, const std::string& what);

// The largest error decoding leaves, per quantity, for a frame's ranges:
// half a step of each quantiser (positions per axis).
struct FrameTolerance {
  std::array<double, 3> position{};
  double log_scale = 0, shading = 0;
  double rotation_component = 0;  // of the three smallest quaternion components
};
FrameTolerance frame_tolerance(std::string_view encoded_frame, const std::string& what);

}  // namespace tega::serve
