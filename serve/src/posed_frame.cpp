#include "tega/serve/posed_frame.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>

#include "tega/tools/export.h"
#include "tega/trainer/spherical_harmonics.h"

namespace tega::serve {

namespace {

std::vector<float> to_vector(const at::Tensor& tensor) {
  const at::Tensor values = tensor.detach().to(at::kCPU, at::kFloat).contiguous();
  return {values.data_ptr<float>(), values.data_ptr<float>() + values.numel()};
}

}  // namespace

StaticPart static_part(const trainer::TrainedAvatar& avatar) {
  at::NoGradGuard no_grad;
  const trainer::Gaussians& g = avatar.model.gaussians;
  const int64_t used = trainer::sh_coefficients(avatar.phase.sh_degree);
  StaticPart part;
  part.sh_degree = avatar.phase.sh_degree;
  part.antialiased = avatar.options.antialiased;
  for (int c = 0; c < 3; ++c) part.background[c] = static_cast<float>(avatar.options.background.at(c));
  part.opacities = to_vector(at::sigmoid(g.opacity_logit));
  part.sh = to_vector(used > 1 ? at::cat({g.sh_dc, g.sh_rest.narrow(1, 0, used - 1)}, 1) : g.sh_dc);
  return part;
}

FramePart posed_frame(trainer::TrainedAvatar& avatar, const tools::RenderFrame& frame) {
  at::NoGradGuard no_grad;
  trainer::AvatarModel& model = avatar.model;
  const trainer::PosedGaussians posed =
      model.pose(model.frame_input(frame.world_vertices, frame.head_to_world), avatar.phase);
  const tools::ScaleRotation shape = tools::decompose_covariances(posed.covariances);
  FramePart part;
  part.means = to_vector(posed.means);
  part.log_scales = to_vector(shape.log_scale);
  part.rotations = to_vector(shape.rotation);
  part.shading = posed.shading.defined() ? to_vector(posed.shading.reshape({-1}))
                                         : std::vector<float>(static_cast<size_t>(model.gaussians.size()), 1.0f);
  return part;
}

}  // namespace tega::serve
