#include "tega/trainer/render.h"

namespace tega::trainer {

splat::RasterCamera raster_camera(const Camera& camera) {
  splat::RasterCamera c;
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) c.rotation[3 * r + k] = camera.world_to_camera.R(r, k);
    c.translation[r] = camera.world_to_camera.t[r];
  }
  c.fx = camera.K(0, 0);
  c.fy = camera.K(1, 1);
  c.cx = camera.K(0, 2);
  c.cy = camera.K(1, 2);
  return c;
}

splat::RasterSettings raster_settings(const Camera& camera, bool antialiased) {
  splat::RasterSettings s;
  s.width = camera.width;
  s.height = camera.height;
  s.antialiased = antialiased;
  return s;
}

at::Tensor composite_target(const at::Tensor& rgba, const at::Tensor& background) {
  const at::Tensor pixels = rgba.to(at::kFloat).div_(255.0).permute({2, 0, 1});  // [4,H,W]
  const at::Tensor alpha = pixels.slice(0, 3, 4);
  return pixels.slice(0, 0, 3) * alpha + background.view({3, 1, 1}) * (1.0 - alpha);
}

at::Tensor render_view(AvatarModel& model, const FrameInput& frame, const Camera& camera, const Phase& phase,
                       const at::Tensor& background, bool antialiased) {
  const PosedGaussians posed = model.pose(frame, phase);
  splat::RasterSettings settings = raster_settings(camera, antialiased);
  settings.sh_degree = posed.sh_degree;
  const splat::RasterOutput out = splat::rasterize(posed.means, posed.covariances, posed.sh, posed.opacities,
                                                   background, {raster_camera(camera)}, settings);
  return out.rgb[0].permute({2, 0, 1});
}

}  // namespace tega::trainer
