// Issue 5: a capture in Multiface's exact layout (generated, never real
// Multiface files) -> tega ingest multiface -> a dataset the trainer accepts
// -> a short training run that fits the training views.

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "multiface_fixture.h"
#include "tega/core/dataset.h"
#include "tega/ingest/multiface.h"
#include "tega/trainer/trainer.h"
#include "test_support.h"

namespace {

tega::ingest::IngestOptions multiface_tiny_ingest_options() {
  tega::ingest::IngestOptions ingest;
  ingest.width = 168;
  ingest.height = 256;
  ingest.frames = 4;
  ingest.test_frames = 2;
  ingest.matte_dilation_px = 3;
  ingest.matte_feather_px = 2;
  ingest.threads = 2;
  return ingest;
}

tega::trainer::TrainOptions multiface_tiny_train_options() {
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
  return o;
}

TEST(EndToEnd, MultifaceCaptureIngestsAndTrains) {
  tega::test::TempDir tmp;
  const auto fixture = tega::test::write_multiface_fixture(tmp / "capture");

  tega::ingest::ingest_multiface(fixture.root, tmp / "dataset", multiface_tiny_ingest_options());
  const tega::Dataset dataset = tega::read_dataset(tmp / "dataset");
  tega::validate_dataset(dataset);
  EXPECT_EQ(dataset.template_mesh.num_vertices(), fixture.head.num_vertices());

  const tega::trainer::TrainOptions o = multiface_tiny_train_options();
  const auto first = tega::trainer::train(tmp / "dataset", tmp / "run", o, {.stop_at = 10});
  const auto last = tega::trainer::train(tmp / "dataset", tmp / "run", o, {.resume = true});
  EXPECT_EQ(last.iterations, 60);
  // The training views are fitted: the recent loss is well below the early one.
  EXPECT_LT(last.final_loss, 0.9 * first.final_loss) << first.final_loss << " -> " << last.final_loss;
  EXPECT_TRUE(std::filesystem::exists(tmp / "run/checkpoint.safetensors"));
}

}  // namespace

namespace {

// Issue 22: a capture with a deleted and a truncated camera image ingests
// without them, and training and its held-out evaluation skip them: a run
// long enough to draw every training view never tries to load one.
TEST(EndToEnd, MultifaceCaptureWithLostImagesTrainsOnTheRest) {
  tega::test::TempDir tmp;
  const auto fixture = tega::test::write_multiface_fixture(tmp / "capture");
  const tega::ingest::MultifaceCapture layout{fixture.root};
  const auto& ring = fixture.ring;  // train cameras 0, 2, 4, 6; held out 1, 3, 5
  const tega::ingest::MultifaceFrame& train_frame = fixture.frames[2];
  std::filesystem::remove(layout.image(ring[2], train_frame));
  const auto truncated = layout.image(ring[3], train_frame);  // a held-out view of a train frame
  std::filesystem::resize_file(truncated, std::filesystem::file_size(truncated) / 2);

  tega::ingest::ingest_multiface(fixture.root, tmp / "dataset", multiface_tiny_ingest_options());
  const tega::Dataset dataset = tega::read_dataset(tmp / "dataset");
  tega::validate_dataset(dataset);
  ASSERT_EQ(dataset.missing_images.size(), 2u);
  EXPECT_FALSE(dataset.has_image(ring[2], train_frame.id()));
  EXPECT_FALSE(dataset.has_image(ring[3], train_frame.id()));

  tega::trainer::TrainOptions o = multiface_tiny_train_options();
  o.iterations = 20;  // 4 frames x 4 train cameras - 1 missing = 15 views: every one is drawn
  const auto summary = tega::trainer::train(tmp / "dataset", tmp / "run", o, {});
  EXPECT_EQ(summary.iterations, 20);
  EXPECT_TRUE(std::isfinite(summary.final_loss));
  EXPECT_GT(summary.heldout_psnr, 0.0);  // the held-out views that exist were scored
}

}  // namespace
