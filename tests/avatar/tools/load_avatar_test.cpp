// load_avatar on a run whose networks learnt from the displacement texture
// before it left the eyeballs out: it still loads, with a warning that says
// to retrain; a run trained since loads without one. A run from an earlier
// UV layout is refused.

#include "tega/trainer/trained_avatar.h"

#include <gtest/gtest.h>

#include <string>

#include "tega/core/error.h"
#include "tega/core/log.h"
#include "tega/core/options.h"
#include "tega/nn/module_io.h"
#include "tega/trainer/checkpoint.h"

#include "tiny_avatar.h"

namespace tega::trainer {
namespace {

// The tiny avatar as a run directory, its checkpoint with `metadata`.
std::filesystem::path write_run(test::TinyAvatar& tiny, const std::map<std::string, std::string>& metadata) {
  const std::filesystem::path run = tiny.tmp / "run";
  std::filesystem::create_directories(run);
  test::write_text(run / "options.yaml", options_to_yaml(tiny.avatar->options));
  Checkpoint checkpoint;
  for (const auto& [name, tensor] : tiny.model().gaussians.tensors()) checkpoint.tensors[name] = tensor;
  for (const auto& [name, tensor] : nn::module_tensors(*tiny.model().network, "network."))
    checkpoint.tensors[name] = tensor;
  checkpoint.tensors["trainer.iteration"] = at::tensor({int64_t{100}}, at::kLong);
  checkpoint.metadata = metadata;
  write_checkpoint(run / "checkpoint.safetensors", checkpoint);
  return run;
}

std::string warnings_of_loading(const std::filesystem::path& run, const Dataset& dataset) {
  init_logging(0);
  testing::internal::CaptureStderr();
  const TrainedAvatar avatar = load_avatar(run, dataset, at::kCPU);
  EXPECT_EQ(avatar.iteration, 100);
  return testing::internal::GetCapturedStderr();
}

TEST(LoadAvatar, ARunTrainedOnTheTextureWithEyeballsIsLoadedWithAWarningToRetrain) {
  test::TinyAvatar tiny;
  Dataset with_eyeballs = tiny.dataset;
  with_eyeballs.eyeball_faces = {0};

  const auto before = write_run(tiny, {});
  const std::string warned = warnings_of_loading(before, with_eyeballs);
  EXPECT_NE(warned.find("checkpoint.safetensors: trained before the displacement texture left the eyeballs out"),
            std::string::npos)
      << warned;
  EXPECT_NE(warned.find("retrain the run"), std::string::npos) << warned;
  // Without eyeballs the texture is what it was: nothing to say.
  EXPECT_EQ(warnings_of_loading(before, tiny.dataset), "");

  const auto since = write_run(tiny, {{kTextureMetadataKey, kTextureWithoutEyeballs}});
  EXPECT_EQ(warnings_of_loading(since, with_eyeballs), "");
}

// A run of TeGA Gaussians from before the layout was packed into the unit
// square is refused on a template that packing changes (its Gaussians' uv
// would name other points); one trained since, or on a template packing
// leaves as it is, loads.
TEST(LoadAvatar, ARunFromAnEarlierUvLayoutOfItsTemplateIsRefused) {
  test::TinyAvatar tiny;
  Dataset two_tiles = tiny.dataset;
  two_tiles.template_mesh.uvs.col(0).array() += 1.0f;  // tile 1: packing moves it

  const auto before = write_run(tiny, {});
  try {
    load_avatar(before, two_tiles, at::kCPU);
    FAIL() << "expected an error";
  } catch (const tega::Error& e) {
    EXPECT_NE(std::string(e.what()).find("checkpoint.safetensors: was trained in an earlier UV layout"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("retrain the run"), std::string::npos) << e.what();
  }
  EXPECT_EQ(warnings_of_loading(before, tiny.dataset), "");

  const auto since = write_run(tiny, {{kUvLayoutMetadataKey, kUvLayoutChartsApartPacked}});
  EXPECT_EQ(warnings_of_loading(since, two_tiles), "");
}

}  // namespace
}  // namespace tega::trainer
