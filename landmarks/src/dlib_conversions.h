#pragma once
// The one place where tega's images, boxes and landmarks become dlib's, so
// that training and detection see a face identically.

#include <dlib/array2d.h>
#include <dlib/geometry/rectangle.h>
#include <dlib/image_processing/full_object_detection.h>

#include <Eigen/Core>
#include <vector>

#include "tega/core/image.h"
#include "tega/landmarks/landmarks.h"

namespace tega::landmarks {

// Grey as dlib computes it from RGB (the plain mean of R, G and B), so a
// predictor trained by dlib's own tools on colour images sees the same values.
// Alpha is ignored. Throws tega::Error unless the image has 1 to 4 channels.
dlib::array2d<unsigned char> to_dlib_grey(const Image8& image);

dlib::rectangle to_dlib_rectangle(const FaceBox& box);
FaceBox from_dlib_rectangle(const dlib::rectangle& rectangle);

// A landmark with a non-finite coordinate becomes a part dlib's trainer skips.
dlib::full_object_detection to_dlib_shape(const FaceBox& box, const std::vector<Eigen::Vector2d>& landmarks);
std::vector<Eigen::Vector2d> from_dlib_shape(const dlib::full_object_detection& shape);

}  // namespace tega::landmarks
