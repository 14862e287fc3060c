// The photos the image terms read: downsampled by a whole factor, from RGB
// or raw Bayer takes, with cameras whose pixels land where the photos' do.
#include <gtest/gtest.h>

#include "tega/core/error.h"
#include "tega/tracking/photos.h"
#include "test_support.h"

namespace tega::tracking {
namespace {

Camera camera_of(int width, int height) {
  Camera c;
  c.name = "cam00";
  c.width = width;
  c.height = height;
  c.K << 0.9 * width, 0, 0.5 * width + 3.2, 0, 0.9 * width, 0.5 * height - 1.7, 0, 0, 1;
  c.world_to_camera.t = Eigen::Vector3d(0.01, -0.02, 1.0);
  return c;
}

TakeInfo one_camera_take(const test::TempDir& dir, const std::string& pixel_format) {
  TakeInfo take;
  take.name = "expressions";
  take.kind = "performance";
  take.cameras = {"cam00"};
  take.frames = 1;
  take.pixel_format = pixel_format;
  take.folder = dir.path();
  return take;
}

TEST(Photos, TheFactorBringsTheLongerSideWithinTheBound) {
  EXPECT_EQ(photo_downsample({camera_of(3072, 2048)}, 1536), 2);
  EXPECT_EQ(photo_downsample({camera_of(6144, 4096)}, 1536), 4);
  EXPECT_EQ(photo_downsample({camera_of(3000, 2000)}, 1536), 2);
  EXPECT_EQ(photo_downsample({camera_of(1024, 768)}, 1536), 1);
  EXPECT_EQ(photo_downsample({camera_of(1024, 768), camera_of(4000, 3000)}, 1536), 3);  // the largest camera's
  EXPECT_EQ(photo_downsample({camera_of(3072, 2048)}, 0), 1);                           // full size
}

TEST(Photos, ScaledCamerasProjectWherePixelBlocksAverage) {
  const Camera full = camera_of(3001, 2001);
  const Camera half = photo_cameras({full}, 2)[0];
  EXPECT_EQ(half.width, 1500);
  EXPECT_EQ(half.height, 1000);
  const Eigen::Vector3d point(0.05, -0.03, 0.1);
  const Eigen::Vector2d p = *full.project(point), q = *half.project(point);
  // Pixel x of the half-size photo averages full-size pixels 2x and 2x + 1.
  EXPECT_NEAR(q.x(), (p.x() + 0.5) / 2 - 0.5, 1e-9);
  EXPECT_NEAR(q.y(), (p.y() + 0.5) / 2 - 0.5, 1e-9);
}

TEST(Photos, RgbPhotosAreBlockAverages) {
  const test::TempDir dir;
  const TakeInfo take = one_camera_take(dir, "RGB8");
  Image8 image(13, 9, 3);  // odd sizes: the last column and row are dropped
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) image.at(x, y, 0) = uint8_t(20 * x), image.at(x, y, 1) = uint8_t(25 * y), image.at(x, y, 2) = 7;
  write_image(image, take.image_path("cam00", 0));
  ThreadPool pool(1);
  const Image8 half = frame_photos(take, 0, 2, pool)[0];
  ASSERT_EQ(half.width, 6);
  ASSERT_EQ(half.height, 4);
  for (int y = 0; y < half.height; ++y)
    for (int x = 0; x < half.width; ++x) {
      EXPECT_NEAR(half.at(x, y, 0), 40 * x + 10, 1) << x << ", " << y;
      EXPECT_NEAR(half.at(x, y, 1), 50 * y + 12.5, 1) << x << ", " << y;
      EXPECT_EQ(half.at(x, y, 2), 7);
    }
  EXPECT_EQ(frame_photos(take, 0, 1, pool)[0].pixels, image.pixels);
}

TEST(Photos, RawBayerMosaicsComeOutInTheirColour) {
  const test::TempDir dir;
  const TakeInfo take = one_camera_take(dir, "BayerRG8");
  Image8 mosaic(24, 16, 1);  // BayerRG: R G on even rows, G B on odd rows
  for (int y = 0; y < mosaic.height; ++y)
    for (int x = 0; x < mosaic.width; ++x) mosaic.at(x, y, 0) = y % 2 == 0 ? (x % 2 == 0 ? 200 : 100) : (x % 2 == 0 ? 100 : 50);
  write_image(mosaic, take.image_path("cam00", 0));
  ThreadPool pool(1);
  for (const int factor : {1, 2, 3, 4}) {
    const Image8 photo = frame_photos(take, 0, factor, pool)[0];
    ASSERT_EQ(photo.width, 24 / factor);
    ASSERT_EQ(photo.height, 16 / factor);
    ASSERT_EQ(photo.channels, 3);
    for (int y = 1; y + 1 < photo.height; ++y)  // inside: a demosaic may treat the border apart
      for (int x = 1; x + 1 < photo.width; ++x) {
        EXPECT_NEAR(photo.at(x, y, 0), 200, 2) << "factor " << factor;
        EXPECT_NEAR(photo.at(x, y, 1), 100, 2) << "factor " << factor;
        EXPECT_NEAR(photo.at(x, y, 2), 50, 2) << "factor " << factor;
      }
  }
}

}  // namespace
}  // namespace tega::tracking
