#include "tega/nn/expression_network.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>
#include <gtest/gtest.h>

#include "tega/core/error.h"
#include "tega/core/options.h"
#include "tega/nn/module_io.h"
#include "tega/nn/safetensors.h"
#include "test_support.h"

namespace tega::nn {
namespace {

NetworkOptions small_options(const std::string& latent) {
  NetworkOptions o;
  o.latent = latent;
  o.texture_size = 16;
  o.latent_channels = 6;
  o.unet_widths = {4, 8, 8};
  o.global_layers = 4;
  o.mlp_hidden = 12;
  o.pe_frequencies = 3;
  return o;
}

at::Tensor uvd_points(int64_t n) {
  at::Tensor uvd = at::rand({n, 3});
  uvd.select(1, 2).mul_(0.25).sub_(0.05);
  return uvd;
}

// A trained-looking network: the zero-initialised output layers of both MLPs
// get random weights; the rest keeps its (fan-in scaled) default init.
void randomise_outputs(torch::nn::Module& module) {
  at::NoGradGuard no_grad;
  for (auto& item : module.named_parameters())
    if (item.key().find(".output.") != std::string::npos) item.value().normal_(0.0, 0.3);
}

TEST(UNet, OutputsTwoFullResolutionLatents) {
  UNetOptions options;
  options.widths = {4, 8, 16};
  options.latent_channels = 64;
  UNet unet(options);
  const LatentPair out = unet->forward(at::randn({2, 3, 16, 16}) * 0.01);
  EXPECT_EQ(out.deformation.sizes(), (std::vector<int64_t>{2, 64, 16, 16}));
  EXPECT_EQ(out.shading.sizes(), (std::vector<int64_t>{2, 64, 16, 16}));
  // Duplicated last layer: separately initialised heads give different latents.
  EXPECT_FALSE(at::allclose(out.deformation, out.shading));
  EXPECT_THROW(unet->forward(at::randn({1, 3, 18, 18})), c10::Error);  // 18 is not divisible by 4
}

TEST(GlobalEncoder, OutputsOneCodePerFrame) {
  GlobalEncoderOptions options;
  options.layers = 8;
  options.latent_channels = 64;
  GlobalEncoder encoder(options);
  const LatentPair out = encoder->forward(at::randn({3, 3, 32, 32}) * 0.01);
  EXPECT_EQ(out.deformation.sizes(), (std::vector<int64_t>{3, 64, 1, 1}));
  EXPECT_EQ(out.shading.sizes(), (std::vector<int64_t>{3, 64, 1, 1}));
}

TEST(SampleLatent, FollowsTheObjUvConvention) {
  // Texel (r, c) holds 10 r + c; its centre is u = (c + .5)/W, v = 1 - (r + .5)/H.
  const int64_t h = 4, w = 5;
  const at::Tensor latent = (at::arange(h).view({h, 1}) * 10 + at::arange(w).view({1, w})).to(at::kFloat).unsqueeze(0);
  std::vector<float> uv;
  std::vector<float> expected;
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) {
      uv.insert(uv.end(), {(c + 0.5f) / w, 1 - (r + 0.5f) / h});
      expected.push_back(10.0f * r + c);
    }
  // Halfway between texels (1,2) and (2,3) in both directions: their mean, 17.5.
  uv.insert(uv.end(), {3.0f / w, 1 - 2.0f / h});
  expected.push_back(17.5f);
  // u = 0, v = 0 is beyond the outermost centres: the bottom-left texel extends.
  uv.insert(uv.end(), {0.0f, 0.0f});
  expected.push_back(30.0f);
  const at::Tensor sampled = sample_latent(latent, at::tensor(uv).view({-1, 2}));
  ASSERT_EQ(sampled.sizes(), (std::vector<int64_t>{static_cast<int64_t>(expected.size()), 1}));
  EXPECT_TRUE(at::allclose(sampled.squeeze(1), at::tensor(expected), 1e-5, 1e-5)) << sampled;
}

class ExpressionNetworkModes : public ::testing::TestWithParam<std::string> {};

TEST_P(ExpressionNetworkModes, StartsWithNullDeformationAndUnitShading) {
  ExpressionNetwork net(small_options(GetParam()));
  const Latents latents = net->encode(at::randn({3, 16, 16}) * 0.01);
  const at::Tensor uvd = uvd_points(50);
  const FieldWithJacobian d = net->deform(uvd, latents, /*with_jacobian=*/true);
  EXPECT_EQ(d.value.sizes(), (std::vector<int64_t>{50, 3}));
  EXPECT_EQ(d.jacobian.sizes(), (std::vector<int64_t>{50, 3, 3}));
  EXPECT_TRUE(at::equal(d.value, at::zeros({50, 3})));
  EXPECT_TRUE(at::equal(d.jacobian, at::zeros({50, 3, 3})));
  EXPECT_FALSE(net->deform(uvd, latents, /*with_jacobian=*/false).jacobian.defined());
  const at::Tensor s = net->shade(uvd, latents);
  EXPECT_EQ(s.sizes(), (std::vector<int64_t>{50}));
  EXPECT_TRUE(at::equal(s, at::ones({50})));
}

TEST_P(ExpressionNetworkModes, ExpressionReachesTheFieldsUnlessThereIsNoLatent) {
  ExpressionNetwork net(small_options(GetParam()));
  randomise_outputs(*net);
  const at::Tensor uvd = uvd_points(30);
  const Latents smile = net->encode(at::randn({3, 16, 16}) * 0.01);
  const Latents frown = net->encode(at::randn({3, 16, 16}) * 0.01);
  const bool same_deformation =
      at::allclose(net->deform(uvd, smile, false).value, net->deform(uvd, frown, false).value);
  const bool same_shading = at::allclose(net->shade(uvd, smile), net->shade(uvd, frown));
  EXPECT_EQ(same_deformation, GetParam() == "none");
  EXPECT_EQ(same_shading, GetParam() == "none");
  const at::Tensor s = net->shade(uvd, smile);
  EXPECT_TRUE((s > 0).all().item<bool>() && (s < 2).all().item<bool>());
}

INSTANTIATE_TEST_SUITE_P(Latents, ExpressionNetworkModes, ::testing::Values("unet", "global", "none"));

TEST(ExpressionNetwork, RejectsBadOptions) {
  EXPECT_THROW(ExpressionNetwork(small_options("mlp")), Error);
  NetworkOptions odd = small_options("unet");
  odd.texture_size = 18;
  EXPECT_THROW(ExpressionNetwork{odd}, Error);
}

TEST(ExpressionNetwork, MlpPrecisionLoadsFromYamlAndRejectsUnknownValues) {
  NetworkOptions options = small_options("unet");
  EXPECT_EQ(options.mlp_precision, "bfloat16");
  load_options_from_string(options, "network: {mlp_precision: float32}\n", "network", "train.yaml");
  EXPECT_EQ(options.mlp_precision, "float32");
  EXPECT_NO_THROW(ExpressionNetwork{options});

  load_options_from_string(options, "network: {mlp_precision: float16}\n", "network", "train.yaml");
  try {
    ExpressionNetwork{options};
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    const std::string message = e.what();
    for (const char* word : {"mlp_precision", "float32", "bfloat16", "float16"})
      EXPECT_NE(message.find(word), std::string::npos) << message;
  }
}

TEST(ExpressionNetwork, CheckpointsThroughSafetensors) {
  test::TempDir dir;
  ExpressionNetwork saved(small_options("unet"));
  randomise_outputs(*saved);
  const auto file = dir / "network.safetensors";
  write_safetensors(file, module_tensors(*saved, "network."), {{"latent", "unet"}});

  ExpressionNetwork loaded(small_options("unet"));
  const SafetensorsFile contents = read_safetensors(file);
  load_module_tensors(*loaded, contents.tensors, file, "network.");
  const at::Tensor texture = at::randn({3, 16, 16}) * 0.01;
  const at::Tensor uvd = uvd_points(10);
  EXPECT_TRUE(at::equal(saved->deform(uvd, saved->encode(texture), false).value,
                        loaded->deform(uvd, loaded->encode(texture), false).value));

  NetworkOptions wider = small_options("unet");
  wider.mlp_hidden = 13;
  ExpressionNetwork mismatched(wider);
  try {
    load_module_tensors(*mismatched, contents.tensors, file, "network.");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
    EXPECT_NE(message.find("network.deformation.input.weight"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace tega::nn
