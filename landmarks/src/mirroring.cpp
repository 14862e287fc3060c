#include "mirroring.h"

#include <array>

namespace tega::landmarks {

namespace {

// The mirror partner of each landmark of the 68-point Multi-PIE markup.
constexpr std::array<int, kLandmarkCount> kMirrorPartner = {
    16, 15, 14, 13, 12, 11, 10, 9,  8,  7,  6,  5,  4,  3,  2,  1,  0,   // jaw line
    26, 25, 24, 23, 22, 21, 20, 19, 18, 17,                              // brows
    27, 28, 29, 30,                                                      // nose bridge
    35, 34, 33, 32, 31,                                                  // nostrils
    45, 44, 43, 42, 47, 46, 39, 38, 37, 36, 41, 40,                      // eyes
    54, 53, 52, 51, 50, 49, 48, 59, 58, 57, 56, 55,                      // outer lips
    64, 63, 62, 61, 60, 67, 66, 65};                                     // inner lips

}  // namespace

LandmarkSample mirrored(const LandmarkSample& sample) {
  const Image8& image = sample.image;
  // Pixel centres are integers, so x mirrors to (width - 1) - x.
  const double mirror_x = image.width - 1;
  LandmarkSample result;
  result.image = Image8(image.width, image.height, image.channels);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < image.channels; ++c) result.image.at(image.width - 1 - x, y, c) = image.at(x, y, c);
  result.box = FaceBox(Eigen::Vector2d(mirror_x - sample.box.max().x(), sample.box.min().y()),
                       Eigen::Vector2d(mirror_x - sample.box.min().x(), sample.box.max().y()));
  result.landmarks.resize(sample.landmarks.size());
  for (size_t i = 0; i < sample.landmarks.size(); ++i) {
    const Eigen::Vector2d& landmark = sample.landmarks[i];
    result.landmarks[kMirrorPartner[i]] = Eigen::Vector2d(mirror_x - landmark.x(), landmark.y());
  }
  return result;
}

}  // namespace tega::landmarks
