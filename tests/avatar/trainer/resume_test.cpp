#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/interrupt.h"
#include "tega/core/log.h"
#include "tega/trainer/checkpoint.h"
#include "tega/trainer/trainer.h"
#include "test_support.h"
#include "tiny_training.h"

namespace {

using namespace tega::trainer;
using tega::test::expect_same_parameters;
using tega::test::scaled_learning_rates;
using tega::test::tiny_options;

TEST(Trainer, ResumeReproducesAnUninterruptedRun) {
  tega::test::TempDir tmp;
  tega::test::write_tiny_dataset(tmp / "data", /*eyeball=*/false);
  const TrainOptions options = tiny_options();

  const TrainSummary straight = train(tmp / "data", tmp / "straight", options, {});
  EXPECT_EQ(straight.iterations, 6);

  const TrainSummary first = train(tmp / "data", tmp / "sliced", options, {.stop_at = 3});
  EXPECT_EQ(first.iterations, 3);
  const TrainSummary rest = train(tmp / "data", tmp / "sliced", options, {.resume = true});
  EXPECT_EQ(rest.iterations, 6);
  EXPECT_EQ(rest.gaussians, straight.gaussians);
  expect_same_parameters(tmp / "straight", tmp / "sliced");
  // The whole loss curve, before and after the interruption.
  const auto losses = [](const std::filesystem::path& file) {
    std::vector<double> values;
    std::istringstream lines(tega::read_text_file(file));
    std::string line;
    std::getline(lines, line);  // header: iteration,loss,...
    while (std::getline(lines, line)) values.push_back(std::stod(line.substr(line.find(',') + 1)));
    return values;
  };
  const auto straight_losses = losses(tmp / "straight/metrics.csv");
  const auto sliced_losses = losses(tmp / "sliced/metrics.csv");
  ASSERT_EQ(straight_losses.size(), 6u);
  ASSERT_EQ(sliced_losses.size(), 6u);
  for (size_t i = 0; i < 6; ++i) EXPECT_NEAR(straight_losses[i], sliced_losses[i], 1e-5 * straight_losses[i]) << i;
}

// SIGTERM (a scheduler's time limit, `tega run` stopping) or Ctrl-C stops a
// run at the end of a step, with a checkpoint there; resumed, it ends where an
// uninterrupted run ends.
TEST(Trainer, ASignalStopsTheRunWithACheckpointThatResumesExactly) {
  tega::test::TempDir tmp;
  tega::test::write_tiny_dataset(tmp / "data", /*eyeball=*/false);
  TrainOptions options = tiny_options();
  options.iterations = 24;
  const TrainSummary straight = train(tmp / "data", tmp / "straight", options, {});

  // Should the signal come after the run's own handler is gone, this one takes it.
  tega::InterruptGuard late_signal;
  std::thread scheduler([&] {
    // The run's first checkpoint (iteration 0) is written once its handler is in place.
    while (!std::filesystem::exists(tmp / "sliced/checkpoint.safetensors"))
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    std::raise(SIGTERM);
  });
  const TrainSummary first = train(tmp / "data", tmp / "sliced", options, {});
  scheduler.join();
  EXPECT_TRUE(first.interrupted);
  EXPECT_GE(first.iterations, 1);
  EXPECT_LT(first.iterations, 24);
  EXPECT_TRUE(std::isnan(first.heldout_psnr));
  EXPECT_EQ(read_checkpoint(tmp / "sliced/checkpoint.safetensors").iteration(), first.iterations);
  const auto report = nlohmann::json::parse(tega::read_text_file(tmp / "sliced/run.json"));
  EXPECT_EQ(report.at("iterations").get<int64_t>(), first.iterations);
  EXPECT_TRUE(report.at("interrupted").get<bool>());

  const TrainSummary rest = train(tmp / "data", tmp / "sliced", options, {.resume = true});
  EXPECT_FALSE(rest.interrupted);
  EXPECT_EQ(rest.iterations, 24);
  expect_same_parameters(tmp / "straight", tmp / "sliced");
  // Its times are the resumed invocation's: the steady steps are its own after its first.
  const auto resumed = nlohmann::json::parse(tega::read_text_file(tmp / "sliced/run.json"));
  EXPECT_EQ(resumed.at("steady_iterations").get<int64_t>(), 24 - first.iterations - 1);
  EXPECT_GT(resumed.at("checkpoint_seconds").get<double>(), 0.0);
  EXPECT_LE(resumed.at("steady_seconds").get<double>() + resumed.at("checkpoint_seconds").get<double>(),
            resumed.at("seconds").get<double>());
}

// A latest checkpoint cut short (a copy interrupted, a disk error): the
// resume falls back on the one before it and still ends where an
// uninterrupted run does.
TEST(Trainer, ADamagedLatestCheckpointResumesFromTheOneBefore) {
  tega::test::TempDir tmp;
  tega::test::write_tiny_dataset(tmp / "data", /*eyeball=*/false);
  TrainOptions options = tiny_options();
  options.checkpoint_every = 2;
  train(tmp / "data", tmp / "straight", options, {});
  train(tmp / "data", tmp / "sliced", options, {.stop_at = 5});  // checkpoints 2, 4 and 5
  const auto latest = tmp / "sliced/checkpoint.safetensors";
  ASSERT_EQ(read_checkpoint(tmp / "sliced/checkpoint.previous.safetensors").iteration(), 4);
  std::filesystem::resize_file(latest, std::filesystem::file_size(latest) / 2);
  const TrainSummary rest = train(tmp / "data", tmp / "sliced", options, {.resume = true});
  EXPECT_EQ(rest.iterations, 6);
  expect_same_parameters(tmp / "straight", tmp / "sliced");

  // With neither readable, the error names the latest.
  std::filesystem::resize_file(latest, 100);
  std::filesystem::remove(tmp / "sliced/checkpoint.previous.safetensors");
  try {
    train(tmp / "data", tmp / "sliced", options, {.resume = true});
    FAIL() << "expected an error";
  } catch (const tega::Error& e) {
    EXPECT_NE(std::string(e.what()).find(latest.string()), std::string::npos) << e.what();
  }
}

TEST(Trainer, ExistingRunIsNotOverwrittenByAccident) {
  tega::test::TempDir tmp;
  tega::test::write_tiny_dataset(tmp / "data", /*eyeball=*/false);
  TrainOptions options = tiny_options();
  options.iterations = 1;
  train(tmp / "data", tmp / "run", options, {});
  try {
    train(tmp / "data", tmp / "run", options, {});
    FAIL() << "expected an error";
  } catch (const tega::Error& e) {
    EXPECT_NE(std::string(e.what()).find("already holds a run"), std::string::npos) << e.what();
  }
}

// A NaN loss at iteration 5 rolls the run back to its checkpoint of
// iteration 3; it goes on with every learning rate halved, and ends where a
// run stopped at 3 and resumed with halved learning rates ends.
TEST(Trainer, ANonFiniteStepRollsBackToTheLastCheckpointWithLowerLearningRates) {
  tega::test::TempDir tmp;
  tega::test::write_tiny_dataset(tmp / "data", /*eyeball=*/false);
  TrainOptions options = tiny_options();
  options.checkpoint_every = 3;
  ASSERT_EQ(options.rollback_learning_rate_factor, 0.5);
  const TrainSummary rolled = train(tmp / "data", tmp / "rolled", options, {.poisoned_iterations = {5}});
  EXPECT_EQ(rolled.iterations, 6);
  const Checkpoint last = read_checkpoint(tmp / "rolled/checkpoint.safetensors");
  EXPECT_EQ(last.tensors.at("trainer.learning_rate_scale").item<double>(), 0.5);

  train(tmp / "data", tmp / "reference", options, {.stop_at = 3});
  train(tmp / "data", tmp / "reference", scaled_learning_rates(options, 0.5), {.resume = true});
  expect_same_parameters(tmp / "reference", tmp / "rolled");

  // ... which is not where the run would have ended without the NaN.
  train(tmp / "data", tmp / "straight", options, {});
  const Checkpoint straight = read_checkpoint(tmp / "straight/checkpoint.safetensors");
  double largest_difference = 0;
  for (const auto& [name, tensor] : last.tensors)
    if (name.rfind("network.", 0) == 0)
      largest_difference = std::max(largest_difference, (tensor - straight.tensors.at(name)).abs().max().item<double>());
  EXPECT_GT(largest_difference, 1e-6);
}

// Before the first periodic checkpoint, the roll-back goes to the start.
TEST(Trainer, ANonFiniteFirstStepRollsBackToTheStart) {
  tega::test::TempDir tmp;
  tega::test::write_tiny_dataset(tmp / "data", /*eyeball=*/false);
  TrainOptions options = tiny_options();
  train(tmp / "data", tmp / "rolled", options, {.poisoned_iterations = {1}});
  train(tmp / "data", tmp / "reference", scaled_learning_rates(options, 0.5), {});
  expect_same_parameters(tmp / "reference", tmp / "rolled");
}

// A second NaN after the roll-back stops training, naming both the step and
// the intact checkpoint.
TEST(Trainer, ASecondNonFiniteStepStopsTraining) {
  tega::test::TempDir tmp;
  tega::test::write_tiny_dataset(tmp / "data", /*eyeball=*/false);
  TrainOptions options = tiny_options();
  options.checkpoint_every = 2;
  try {
    train(tmp / "data", tmp / "run", options, {.poisoned_iterations = {3, 5}});
    FAIL() << "expected an error";
  } catch (const tega::Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("iteration 5: the loss or a gradient is NaN/Inf"), std::string::npos) << message;
    EXPECT_NE(message.find("again after a roll-back"), std::string::npos) << message;
    EXPECT_NE(message.find("the last checkpoint (iteration 4) is intact"), std::string::npos) << message;
  }
  EXPECT_EQ(read_checkpoint(tmp / "run/checkpoint.safetensors").iteration(), 4);
}

// An absurd colour step size makes the second step's loss non-finite, and
// again after the roll-back. The run stops with an error naming it, and the
// checkpoint it leaves is the last finite one.
TEST(Trainer, NonFiniteStepStopsTrainingAndKeepsTheLastFiniteCheckpoint) {
  tega::test::TempDir tmp;
  tega::test::write_tiny_dataset(tmp / "data", /*eyeball=*/false);
  TrainOptions options = tiny_options();
  options.learning_rates.sh_dc = 1e30;
  options.checkpoint_every = 1;
  try {
    train(tmp / "data", tmp / "run", options, {});
    FAIL() << "expected an error";
  } catch (const tega::Error& e) {
    EXPECT_NE(std::string(e.what()).find("is NaN/Inf"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("the last checkpoint"), std::string::npos) << e.what();
  }
  const Checkpoint c = read_checkpoint(tmp / "run/checkpoint.safetensors");
  EXPECT_GE(c.iteration(), 1);
  EXPECT_LT(c.iteration(), options.iterations);
  for (const auto& [name, tensor] : c.tensors)
    if (tensor.is_floating_point()) EXPECT_TRUE(at::isfinite(tensor).all().item<bool>()) << name;
}

// A field that runs away stays finite while it renders the head away: an
// absurd network step size moves the Gaussians kilometres once the field
// has made its first step (iteration 3), and again after the roll-back. The
// run stops naming the field and keeps the checkpoint from before it.
TEST(Trainer, ARunawayDeformationFieldIsRolledBackLikeANonFiniteStep) {
  tega::test::TempDir tmp;
  tega::test::write_tiny_dataset(tmp / "data", /*eyeball=*/false);
  TrainOptions options = tiny_options();
  options.learning_rates.network = options.learning_rates.network_final = 1e3;
  options.dynamic_shading = false;  // a runaway shading network blacks the head out before the field moves it
  options.checkpoint_every = 2;
  try {
    train(tmp / "data", tmp / "run", options, {});
    FAIL() << "expected an error";
  } catch (const tega::Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(": the deformation field moved a Gaussian"), std::string::npos) << message;
    EXPECT_NE(message.find("more than max_deformation (0.05 m): Gaussian "), std::string::npos) << message;
    EXPECT_NE(message.find(" at uv ("), std::string::npos) << message;
    EXPECT_NE(message.find("template triangle "), std::string::npos) << message;
    EXPECT_NE(message.find("again after a roll-back"), std::string::npos) << message;
  }
  EXPECT_EQ(read_checkpoint(tmp / "run/checkpoint.safetensors").iteration(), 2);

  // Unbounded, the same run ends, its field far beyond any tracking error.
  options.max_deformation = 0;
  EXPECT_EQ(train(tmp / "data", tmp / "unbounded", options, {}).iterations, options.iterations);
}

// A capped run ("Ours (200K Gaussians)") never holds more than its cap, not
// even before its first densification.
TEST(Trainer, TheGaussianCapBoundsTheInitialSampleToo) {
  tega::test::TempDir tmp;
  tega::test::write_tiny_dataset(tmp / "data", /*eyeball=*/false);
  TrainOptions options = tiny_options();
  options.densify.max_gaussians = 40;
  const TrainSummary first = train(tmp / "data", tmp / "run", options, {.stop_at = 1});
  EXPECT_EQ(first.gaussians, 40);
  const TrainSummary last = train(tmp / "data", tmp / "run", options, {.resume = true});
  EXPECT_LE(last.gaussians, 40);
}

// A deformation field trained on a few expressions learns them by heart: the
// run says so, and not when there is no field to mislead.
TEST(Trainer, TrainingTheFieldOnFewExpressionsWarns) {
  tega::test::TempDir tmp;
  tega::test::write_tiny_dataset(tmp / "data", /*eyeball=*/false);
  const auto warnings = [&](const TrainOptions& options, const std::string& run) {
    tega::init_logging(0);
    testing::internal::CaptureStderr();
    train(tmp / "data", tmp / run, options, {.stop_at = 1});
    const std::string captured = testing::internal::GetCapturedStderr();
    tega::init_logging(1);
    return captured;
  };
  const std::string with_field = warnings(tiny_options(), "field");
  EXPECT_NE(with_field.find("1 training frame: the deformation field may learn their expressions by heart"),
            std::string::npos)
      << with_field;
  EXPECT_NE(with_field.find("docs/training.md#how-many-expressions-the-deformation-field-needs"), std::string::npos);

  TrainOptions no_warp = tiny_options();
  no_warp.deformation_field = false;
  const std::string without_field = warnings(no_warp, "no-warp");
  EXPECT_EQ(without_field.find("deformation field"), std::string::npos) << without_field;
}

TEST(Trainer, BadDatasetFailsBeforeTraining) {
  tega::test::TempDir tmp;
  tega::test::write_tiny_dataset(tmp / "data", /*eyeball=*/false);
  std::filesystem::remove(tmp / "data/images/cam01/smile_000000.png");
  try {
    train(tmp / "data", tmp / "run", tiny_options(), {});
    FAIL() << "expected an error";
  } catch (const tega::Error& e) {
    EXPECT_NE(std::string(e.what()).find("cam01/smile_000000.png: is missing"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(tmp / "run/checkpoint.safetensors"));
}

}  // namespace
