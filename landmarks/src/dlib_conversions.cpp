#include "dlib_conversions.h"

#include <cmath>

#include "tega/core/error.h"

namespace tega::landmarks {

dlib::array2d<unsigned char> to_dlib_grey(const Image8& image) {
  if (image.empty() || image.channels < 1 || image.channels > 4)
    throw Error("landmark image: expected 8-bit grey or RGB(A) pixels, got a " + std::to_string(image.width) + "x" +
                std::to_string(image.height) + " image with " + std::to_string(image.channels) + " channels");
  dlib::array2d<unsigned char> grey(image.height, image.width);
  const bool colour = image.channels >= 3;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      grey[y][x] = colour ? static_cast<unsigned char>(
                                (unsigned{image.at(x, y, 0)} + image.at(x, y, 1) + image.at(x, y, 2)) / 3)
                          : image.at(x, y, 0);
  return grey;
}

dlib::rectangle to_dlib_rectangle(const FaceBox& box) {
  return dlib::rectangle(std::lround(box.min().x()), std::lround(box.min().y()), std::lround(box.max().x()),
                         std::lround(box.max().y()));
}

FaceBox from_dlib_rectangle(const dlib::rectangle& rectangle) {
  return FaceBox(Eigen::Vector2d(rectangle.left(), rectangle.top()),
                 Eigen::Vector2d(rectangle.right(), rectangle.bottom()));
}

dlib::full_object_detection to_dlib_shape(const FaceBox& box, const std::vector<Eigen::Vector2d>& landmarks) {
  std::vector<dlib::point> parts;
  parts.reserve(landmarks.size());
  for (const Eigen::Vector2d& landmark : landmarks)
    parts.push_back(landmark.allFinite() ? dlib::point(std::lround(landmark.x()), std::lround(landmark.y()))
                                         : dlib::OBJECT_PART_NOT_PRESENT);
  return dlib::full_object_detection(to_dlib_rectangle(box), parts);
}

std::vector<Eigen::Vector2d> from_dlib_shape(const dlib::full_object_detection& shape) {
  std::vector<Eigen::Vector2d> landmarks;
  landmarks.reserve(shape.num_parts());
  for (unsigned long i = 0; i < shape.num_parts(); ++i)
    landmarks.emplace_back(static_cast<double>(shape.part(i).x()), static_cast<double>(shape.part(i).y()));
  return landmarks;
}

}  // namespace tega::landmarks
