#include "tega/trainer/trained_avatar.h"

#include "tega/core/error.h"
#include "tega/core/log.h"
#include "tega/core/options.h"
#include "tega/nn/module_io.h"
#include "tega/trainer/checkpoint.h"

namespace tega::trainer {

TrainedAvatar load_avatar(const std::filesystem::path& run, const Dataset& dataset, const at::Device& device) {
  TrainOptions options;
  load_options(options, run / "options.yaml");
  const auto file = run / "checkpoint.safetensors";
  if (!std::filesystem::exists(file)) throw Error(run, "has no checkpoint.safetensors (is it a training run?)");
  const Checkpoint checkpoint = read_checkpoint(file);

  TrainedAvatar avatar{options, AvatarModel(dataset, options, device), {}, checkpoint.iteration()};
  check_uv_layout(checkpoint, file, avatar.model, dataset.template_mesh, options.binding == "rigged");
  avatar.model.gaussians = gaussians_from_tensors(checkpoint.tensors, device, options.binding == "rigged",
                                                  avatar.model.lookup().num_triangles());
  nn::load_module_tensors(*avatar.model.network, checkpoint.tensors, file, "network.");
  avatar.phase.deformation = options.deformation_field;
  avatar.phase.shading = options.dynamic_shading;
  avatar.phase.sh_degree = options.sh_degree;
  const bool networks = options.deformation_field || options.dynamic_shading;
  if (networks && !dataset.eyeball_faces.empty() && !checkpoint.metadata.count(kTextureMetadataKey)) {
    logging::warn(
        "%s: trained before the displacement texture left the eyeballs out; where they share the face's UV "
        "tile (ICT-FaceKit) its networks learnt from a texture that hid the face's expression, and they now "
        "see it: retrain the run (docs/training.md#the-encoders-blind-spot)",
        file.string().c_str());
  }
  return avatar;
}

}  // namespace tega::trainer
