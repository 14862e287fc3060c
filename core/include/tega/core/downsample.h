#pragma once
// Area-correct downsampling by an integer factor: datasets are trained at a
// fraction of the captured resolution (the paper halves 6144 x 4096 to
// 3072 x 2048; Multiface is ingested at a chosen factor). Each output pixel
// is the mean of the block it covers, so its centre is the block's centre,
// which is what Camera::scaled(1.0 / factor) assumes.

#include "tega/core/image.h"

namespace tega {

// Averages each factor x factor block (each channel, rounded). Throws
// tega::Error unless factor divides both sides.
Image8 box_downsample(const Image8& image, int factor);

// As box_downsample, for any size: the last width % factor columns and
// height % factor rows are dropped, so that output pixel x still averages
// the block around factor * (x + 0.5) - 0.5 (images a stage only looks at,
// such as tracking's photos and the mattes' recorded frames).
Image8 box_downsample_dropping_remainder(const Image8& image, int factor);

}  // namespace tega
