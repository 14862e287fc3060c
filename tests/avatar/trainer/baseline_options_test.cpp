// The GaussianAvatars baseline and the Gaussian-cap ablation as options, and
// the combinations the trainer refuses.

#include <gtest/gtest.h>

#include "tega/core/error.h"
#include "tega/trainer/options.h"

namespace tega::trainer {
namespace {

TEST(BaselineOptions, GaussianAvatarsIsRiggedWithoutNetworksOnGasSchedule) {
  TrainOptions o;
  o.loss.vgg_weights = "vgg16.safetensors";
  o.loss.pyramid_l1 = 0.5;
  apply_baseline(o, "gaussian-avatars");
  EXPECT_EQ(o.binding, "rigged");
  EXPECT_FALSE(o.deformation_field);
  EXPECT_FALSE(o.dynamic_shading);
  EXPECT_TRUE(o.loss.vgg_weights.empty());
  EXPECT_EQ(o.loss.pyramid_l1, 0);  // GA's losses: L1 + D-SSIM and its regularisers
  EXPECT_EQ(o.densify.max_gaussians, 200000);
  // 600K iterations: densify from 10K to the end every 2K, reset opacity every 60K.
  EXPECT_EQ(at_fraction(o.densify.start, 600000), 10000);
  EXPECT_EQ(at_fraction(o.densify.stop, 600000), 600000);
  EXPECT_EQ(period(o.densify.interval, 600000), 2000);
  EXPECT_EQ(period(o.densify.opacity_reset_interval, 600000), 60000);
  EXPECT_NO_THROW(validate_train_options(o));
}

TEST(BaselineOptions, UnknownNamesAreErrorsListingTheKnownOnes) {
  TrainOptions o;
  try {
    apply_baseline(o, "gaussian-avatar");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("gaussian-avatars"), std::string::npos) << e.what();
  }
  EXPECT_THROW(apply_ablation(o, "cap-100k"), Error);
}

TEST(BaselineOptions, CapAblationCapsAt200kGaussians) {
  TrainOptions o;
  apply_ablation(o, "cap-200k");
  EXPECT_EQ(o.densify.max_gaussians, 200000);
  EXPECT_EQ(o.binding, "uvd");
  EXPECT_TRUE(o.deformation_field);
}

TEST(BaselineOptions, RiggedGaussiansRefuseTheNetworks) {
  TrainOptions o;
  o.binding = "rigged";
  EXPECT_THROW(validate_train_options(o), Error);
  o.deformation_field = false;
  EXPECT_THROW(validate_train_options(o), Error);
  o.dynamic_shading = false;
  EXPECT_NO_THROW(validate_train_options(o));
  o.binding = "free";
  EXPECT_THROW(validate_train_options(o), Error);
}

TEST(BaselineOptions, APyramidTermNeedsAWeightOfZeroOrMoreAndALevel) {
  TrainOptions o;
  o.loss.pyramid_l1 = 0.5;
  EXPECT_NO_THROW(validate_train_options(o));
  o.loss.pyramid_levels = 0;
  EXPECT_THROW(validate_train_options(o), Error);
  o.loss.pyramid_l1 = 0;
  EXPECT_NO_THROW(validate_train_options(o));  // off: its levels are unused
  o.loss.pyramid_l1 = -1;
  EXPECT_THROW(validate_train_options(o), Error);
}

TEST(BaselineOptions, TheSmoothnessWeightsAreBothPositiveOrBothZero) {
  TrainOptions o;
  o.loss.smoothness_initial = 0;
  EXPECT_THROW(validate_train_options(o), Error);  // no geometric decay from 0 to 0.1
  o.loss.smoothness_final = 0;
  EXPECT_NO_THROW(validate_train_options(o));  // off
  o.loss.smoothness_initial = 1;
  EXPECT_THROW(validate_train_options(o), Error);
  o.loss.smoothness_final = -0.1;
  EXPECT_THROW(validate_train_options(o), Error);
}

}  // namespace
}  // namespace tega::trainer
