// Issue 5: a capture in Multiface's exact layout (generated, never real
// Multiface files) -> tega ingest multiface -> a dataset the trainer accepts
// -> a short training run that fits the training views.

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include "multiface_fixture.h"
#include "tega/core/dataset.h"
#include "tega/ingest/multiface.h"
#include "tega/trainer/trainer.h"
#include "test_support.h"

namespace {

TEST(EndToEnd, MultifaceCaptureIngestsAndTrains) {
  tega::test::TempDir tmp;
  const auto fixture = tega::test::write_multiface_fixture(tmp / "capture");

  tega::ingest::IngestOptions ingest;
  ingest.width = 168;
  ingest.height = 256;
  ingest.frames = 4;
  ingest.test_frames = 2;
  ingest.matte_dilation_px = 3;
  ingest.matte_feather_px = 2;
  ingest.threads = 2;
  tega::ingest::ingest_multiface(fixture.root, tmp / "dataset", ingest);
  const tega::Dataset dataset = tega::read_dataset(tmp / "dataset");
  tega::validate_dataset(dataset);
  EXPECT_EQ(dataset.template_mesh.num_vertices(), fixture.head.num_vertices());

  tega::trainer::TrainOptions o;
  o.iterations = 60;
  o.initial_gaussians = 3000;
  o.densify.interval = 0.25;
  o.densify.opacity_reset_interval = 1.0;
  o.densify.max_gaussians = 6000;
  o.loss.smoothness_samples = 300;
  o.network.texture_size = 32;
  o.network.unet_widths = {8, 16};
  o.network.latent_channels = 8;
  o.network.mlp_hidden = 16;
  o.uv_lookup.resolution = 256;
  o.log_every = 10;
  o.checkpoint_every = 1000;
  o.loader_threads = 2;
  const auto first = tega::trainer::train(tmp / "dataset", tmp / "run", o, {.stop_at = 10});
  const auto last = tega::trainer::train(tmp / "dataset", tmp / "run", o, {.resume = true});
  EXPECT_EQ(last.iterations, 60);
  // The training views are fitted: the recent loss is well below the early one.
  EXPECT_LT(last.final_loss, 0.9 * first.final_loss) << first.final_loss << " -> " << last.final_loss;
  EXPECT_TRUE(std::filesystem::exists(tmp / "run/checkpoint.safetensors"));
}

}  // namespace
