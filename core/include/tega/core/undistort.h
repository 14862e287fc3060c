#pragma once
// Undistorting captured images. Datasets hold undistorted images with
// distortion-free cameras because the avatar renders through a pinhole; a
// capture whose lenses have distortion (Multiface's KRT, a calibrated studio)
// is resampled once, at ingest.

#include "tega/core/camera.h"
#include "tega/core/image.h"

namespace tega {

// The camera of an undistorted image: the same intrinsics, pose and size,
// with zero distortion.
Camera without_distortion(const Camera& camera);

// The image `camera` would have taken without its lens distortion: pixel
// (u, v) of the result is `captured` sampled bilinearly at the distorted
// position of (u, v) (Camera::undistortion_maps()). Any channel count. Where
// that position lies outside the captured image the result is 0. Throws
// tega::Error when the image size differs from the camera's.
Image8 undistort_image(const Image8& captured, const Camera& camera);

// Same with the camera's maps computed once, for the many images of one camera.
Image8 undistort_image(const Image8& captured, const UndistortionMaps& maps);

// Undistorted and shrunk by `factor` in one pass: exactly
// box_downsample(undistort_image(captured, maps), factor) (downsample.h),
// without the full-size intermediate, which at 26 megapixels costs more to
// write and read back than to compute. Throws tega::Error unless factor
// divides both sides.
Image8 undistort_image(const Image8& captured, const UndistortionMaps& maps, int factor);

}  // namespace tega
