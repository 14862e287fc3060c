#pragma once
// Glue between the avatar and the rasterizer, shared by training, evaluation
// and rendering.

#include <ATen/ATen.h>

#include "tega/core/camera.h"
#include "tega/splat/rasterize.h"
#include "tega/trainer/avatar_model.h"

namespace tega::trainer {

// Dataset cameras are undistorted pinholes (validate_dataset checks it).
splat::RasterCamera raster_camera(const Camera& camera);
splat::RasterSettings raster_settings(const Camera& camera, bool antialiased);

// uint8 RGBA [H,W,4] (alpha = matte) -> float RGB [3,H,W] composited over `background` [3].
at::Tensor composite_target(const at::Tensor& rgba, const at::Tensor& background);

// The avatar of one frame seen from `camera`: float RGB [3,H,W].
at::Tensor render_view(AvatarModel& model, const FrameInput& frame, const Camera& camera, const Phase& phase,
                       const at::Tensor& background, bool antialiased);

}  // namespace tega::trainer
