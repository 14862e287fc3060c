#pragma once
// The photos the image terms read (landmarks, eyelids, flow): at an integer
// fraction of the recorded size, so that a studio's 3072 x 2048 (or a raw
// 6144 x 4096 Bayer mosaic) costs a few megapixels per camera, not tens.
#include <vector>

#include "tega/core/camera.h"
#include "tega/core/image.h"
#include "tega/core/take.h"
#include "tega/core/thread_pool.h"

namespace tega::tracking {

// The smallest whole factor that brings every camera's longer side to at most
// `max_side` pixels; 1 for max_side <= 0 (full size).
int photo_downsample(const std::vector<Camera>& cameras, int max_side);

// The cameras of photos downsampled by `factor`: sizes as the photos come out
// (the size divided, rounded down), pixel centres kept consistent.
std::vector<Camera> photo_cameras(const std::vector<Camera>& cameras, int factor);

// A frame's photos as RGB, downsampled by `factor` (area average; a raw Bayer
// mosaic is demosaiced at half size first where the factor is even); an empty
// image where a camera has none.
std::vector<Image8> frame_photos(const TakeInfo& take, int frame, int factor, ThreadPool& pool);

}  // namespace tega::tracking
