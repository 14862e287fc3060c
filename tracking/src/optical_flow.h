#pragma once
// Dense optical flow between a camera's consecutive photos (OpenCV's DIS),
// both ways, so that a point is followed only where the round trip returns
// to where it started.

#include <Eigen/Core>
#include <memory>
#include <optional>

#include "tega/core/image.h"

namespace tega::tracking {

class FlowField {
 public:
  // `from` and `to`: 8-bit RGB or grey photos of one camera, same size. The
  // flow runs on copies downsampled so that the longer side is at most
  // `max_side` pixels.
  FlowField(const Image8& from, const Image8& to, double max_side);
  ~FlowField();
  FlowField(FlowField&&) noexcept;

  // Where the point at `pixel` of `from` went in `to` (full-size pixels);
  // nullopt outside the image or where forward and backward flow disagree by
  // more than `max_round_trip_px`.
  std::optional<Eigen::Vector2d> follow(const Eigen::Vector2d& pixel, double max_round_trip_px) const;

 private:
  struct Fields;
  std::unique_ptr<Fields> fields_;
};

}  // namespace tega::tracking
