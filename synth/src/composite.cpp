#include <algorithm>
#include <cmath>
#include <cstdio>

#include "studio.h"
#include "tega/core/take.h"
#include "tega/synth/random.h"

namespace tega::synth {
namespace {

uint8_t to_u8(double v) { return static_cast<uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); }

double noise(uint64_t seed, double sigma, int64_t pixel, int channel) {
  return sigma > 0 ? sigma * gaussian(seed, pixel, channel) : 0.0;
}

}  // namespace

Image8 capture_image(const ImageF* fg, const ImageF& bg, uint64_t noise_seed, double sigma) {
  Image8 out(bg.width, bg.height, 3);
  for (int y = 0; y < bg.height; ++y) {
    for (int x = 0; x < bg.width; ++x) {
      const double a = fg ? fg->at(x, y, 3) : 0.0;
      for (int c = 0; c < 3; ++c) {
        const double premultiplied = fg ? fg->at(x, y, c) : 0.0;
        out.at(x, y, c) = to_u8(premultiplied + (1 - a) * bg.at(x, y, c) + noise(noise_seed, sigma, int64_t(y) * bg.width + x, c));
      }
    }
  }
  return out;
}

Image8 alpha_image(const ImageF& fg) {
  Image8 out(fg.width, fg.height, 1);
  for (int y = 0; y < fg.height; ++y)
    for (int x = 0; x < fg.width; ++x) out.at(x, y, 0) = to_u8(fg.at(x, y, 3));
  return out;
}

Image8 matte_image(const ImageF& fg, uint64_t noise_seed, double sigma) {
  Image8 out(fg.width, fg.height, 4);
  for (int y = 0; y < fg.height; ++y) {
    for (int x = 0; x < fg.width; ++x) {
      const double a = fg.at(x, y, 3);
      if (a <= 0) continue;
      for (int c = 0; c < 3; ++c)
        out.at(x, y, c) = to_u8(fg.at(x, y, c) / a + noise(noise_seed, sigma, int64_t(y) * fg.width + x, c));
      out.at(x, y, 3) = to_u8(a);
    }
  }
  return out;
}

nlohmann::json pose_json(const RigidTransform& pose) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({pose.R(r, 0), pose.R(r, 1), pose.R(r, 2), pose.t[r]});
  return rows;
}

std::string frame_name(int frame) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%06d", frame);
  return buf;
}

void write_take_json(const Studio& studio, const std::string& take, const std::string& kind, int frames) {
  TakeInfo info;  // the defaults describe capture_image(): 8-bit RGB PNGs
  info.name = take;
  info.kind = kind;
  info.cameras = studio.rig.camera_names();
  info.frames = frames;
  info.fps = studio.options.fps;
  write_take(info, studio.root / "takes" / take);
}

void write_studio_image(const Image8& image, const std::filesystem::path& file) {
  if (file.extension() != ".png") return write_image(image, file);
  write_png_view({image.pixels.data(), image.width, image.height, image.channels, 8,
                  size_t(image.width) * image.channels},
                 file, 1);
}

}  // namespace tega::synth
