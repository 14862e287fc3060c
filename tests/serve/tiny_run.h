#pragma once
// A tiny trained run on disk for the server's tests: the tiny avatar of
// tests/avatar/tools (300 random Gaussians on a one-triangle template, a
// perturbed network: it deforms and shades) written as RUN/options.yaml,
// checkpoint.safetensors and run.json, on write_tiny_dataset's dataset with
// a second frame of another expression, two cameras of kWidth × kHeight looking at the triangle from either side
// of its normal and images whose matte is the triangle.

#include <filesystem>
#include <nlohmann/json.hpp>

#include "tega/core/image.h"
#include "tega/core/options.h"
#include "tega/nn/module_io.h"
#include "tega/tools/render_avatar.h"
#include "tega/trainer/checkpoint.h"
#include "tiny_avatar.h"

namespace tega::test {

struct TinyRun : TinyAvatar {
  static constexpr int kWidth = 96, kHeight = 72;
  std::filesystem::path run = tmp / "run";

  TinyRun() {
    dataset.rig.cameras[0].world_to_camera = tools::look_at({0.25, 0.35, -1.1}, {0.34, 0.34, 0}, {0, -1, 0});
    dataset.rig.cameras[1].world_to_camera = tools::look_at({0.6, 0.2, -1.0}, {0.34, 0.34, 0}, {0, -1, 0});
    for (Camera& c : dataset.rig.cameras) {
      c.width = kWidth;
      c.height = kHeight;
      c.K << 80, 0, 47.5, 0, 80, 35.5, 0, 0, 1;
    }
    // An expression, so that the two frames differ.
    Vertices blink = dataset.load_mesh("blink_000000");
    blink.row(2) += Eigen::RowVector3f(0.08f, -0.05f, 0.03f);
    write_vertices_bin(blink, dataset.mesh_path("blink_000000"));
    for (const DatasetFrame& f : dataset.frames)
      for (const Camera& c : dataset.rig.cameras) write_image(matted_image(c, f), dataset.image_path(c.name, f.id));
    write_dataset_manifest(dataset);  // without the eyeball TinyAvatar dropped

    // The tiny network's shading is near 1 everywhere; the stream's shading
    // byte needs a range to be tested (as export_test.cpp does).
    {
      at::NoGradGuard no_grad;
      auto parameters = model().network->named_parameters();
      parameters["shading.output.bias"].add_(0.4);
      parameters["shading.output.weight"].add_(at::randn_like(parameters["shading.output.weight"]) * 0.5);
    }
    std::filesystem::create_directories(run);
    write_text(run / "options.yaml", options_to_yaml(avatar->options));
    trainer::Checkpoint checkpoint;
    for (const auto& [name, tensor] : model().gaussians.tensors()) checkpoint.tensors[name] = tensor;
    for (const auto& [name, tensor] : nn::module_tensors(*model().network, "network.")) checkpoint.tensors[name] = tensor;
    checkpoint.tensors["trainer.iteration"] = at::tensor({int64_t{100}}, at::kLong);
    checkpoint.metadata = {{trainer::kTextureMetadataKey, trainer::kTextureWithoutEyeballs},
                           {trainer::kUvLayoutMetadataKey, trainer::kUvLayoutChartsApartPacked}};
    trainer::write_checkpoint(run / "checkpoint.safetensors", checkpoint);
    write_text(run / "run.json", nlohmann::json{{"dataset", dataset.root.string()}}.dump());
  }

  // A grey pattern, opaque over the frame's triangle as the camera sees it.
  Image8 matted_image(const Camera& camera, const DatasetFrame& frame) const {
    const Vertices v = dataset.load_mesh(frame.id);
    Eigen::Vector2d p[3];
    for (int k = 0; k < 3; ++k) p[k] = *camera.project(frame.head_to_world.apply(v.row(k).transpose().cast<double>()));
    const auto edge = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& q) {
      return (b - a).x() * (q - a).y() - (b - a).y() * (q - a).x();
    };
    Image8 image(camera.width, camera.height, 4, 0);
    for (int y = 0; y < camera.height; ++y)
      for (int x = 0; x < camera.width; ++x) {
        const Eigen::Vector2d q(x, y);
        const double e0 = edge(p[0], p[1], q), e1 = edge(p[1], p[2], q), e2 = edge(p[2], p[0], q);
        const bool inside = (e0 >= 0 && e1 >= 0 && e2 >= 0) || (e0 <= 0 && e1 <= 0 && e2 <= 0);
        for (int ch = 0; ch < 3; ++ch) image.at(x, y, ch) = static_cast<uint8_t>(60 + 40 * ch + (x + y) % 50);
        image.at(x, y, 3) = inside ? 255 : 0;
      }
    return image;
  }
};

}  // namespace tega::test
