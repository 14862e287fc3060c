#pragma once
// The dataset's landmark vertices in `tega eval`
// (docs/render-eval-export.md#landmark-drift): where the tracked mesh puts them,
// projected into a view (the boxes of the close-ups and of the landmark
// detector), and where the avatar moves them (landmark_drift_px).
//
// landmark_drift_px is a diagnostic of the deformation field, not the
// paper's detector-based landmark error (that is landmark_px,
// detected_landmarks.h): for each landmark vertex the reference is the
// tracked mesh's vertex projected into the camera, and the avatar's landmark
// is the same surface point moved by the avatar, F(uv, d = 0) +
// R_head D(uv, 0; f_uv) (eyeball triangles excepted, as in pose()),
// projected too. The drift is the mean pixel distance over the landmarks in
// front of the camera: how far the learned deformation drags the landmarks
// off the tracked surface in the image. It is 0 for an avatar without
// deformation field.

#include <ATen/ATen.h>

#include <optional>
#include <vector>

#include "tega/core/camera.h"
#include "tega/core/dataset.h"
#include "tega/trainer/avatar_model.h"

namespace tega::tools {

class LandmarkProbe {
 public:
  // For the model's avatar: its device and UV layout. Throws tega::Error when
  // a landmark vertex is out of range or in no face with UVs.
  LandmarkProbe(const Dataset& dataset, const trainer::AvatarModel& model);

  bool empty() const { return vertices_.empty(); }

  // World positions [L,3] (double, CPU): the tracked mesh's landmark vertices,
  // and the avatar's landmark points for the frame.
  at::Tensor reference(const Vertices& world_vertices) const;
  at::Tensor avatar(trainer::AvatarModel& model, const trainer::FrameInput& frame, const trainer::Phase& phase) const;

 private:
  std::vector<int32_t> vertices_;
  at::Tensor uvd_;         // [L,3] float on the model's device: the vertex's uv, d = 0
  at::Tensor eyeball_;     // [F] bool: triangles the deformation leaves rigid
};

// Mean pixel distance between the projections of two point sets [L,3]
// (pairs with a point behind the camera are left out; NaN when none is left).
double landmark_drift_px(const at::Tensor& reference, const at::Tensor& avatar, const Camera& camera);

// The pixels of points [L,3] (world) in `camera`; nullopt behind it.
std::vector<std::optional<Eigen::Vector2d>> project_landmarks(const at::Tensor& points, const Camera& camera);

}  // namespace tega::tools
