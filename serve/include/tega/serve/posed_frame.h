#pragma once
// A trained avatar as the frame stream's parts: what never changes (opacities,
// SH coefficients without the shading) and one frame's posed Gaussians with
// their shading S apart. Folding S back into the coefficients as
// tools::export_frame does gives that frame's exported cloud.

#include "tega/serve/frame_stream.h"
#include "tega/tools/render_avatar.h"
#include "tega/trainer/trained_avatar.h"

namespace tega::serve {

StaticPart static_part(const trainer::TrainedAvatar& avatar);

// Not thread-safe for one avatar: callers serialise posing.
FramePart posed_frame(trainer::TrainedAvatar& avatar, const tools::RenderFrame& frame);

}  // namespace tega::serve
