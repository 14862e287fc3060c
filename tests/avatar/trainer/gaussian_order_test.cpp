// uv_order puts Gaussians that read the same four latent texels next to each
// other, as sample_latent reads them: the latent sampling's backward adds a
// run of such Gaussians' gradients to the latent once.

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include "tega/nn/encoders.h"
#include "tega/trainer/gaussians.h"

namespace tega::trainer {
namespace {

// The top-left texel each uv reads, as sample_latent sees it: sampling a
// texture whose channels hold each texel's column and row gives the point's
// pixel coordinate, whose floor is that texel (double: no rounding up to the
// next one).
at::Tensor top_left_taps(const at::Tensor& uv, int64_t side) {
  const at::Tensor index = at::arange(side, at::kDouble);
  const at::Tensor texture = at::stack({index.view({1, side}).expand({side, side}),
                                        index.view({side, 1}).expand({side, side})});
  const at::Tensor pixel = nn::sample_latent(texture, uv).floor().to(at::kLong);
  return pixel.select(1, 1) * side + pixel.select(1, 0);
}

// How often consecutive rows read other texels than the row before.
int64_t changes(const at::Tensor& taps) { return taps.slice(0, 1).ne(taps.slice(0, 0, -1)).sum().item<int64_t>(); }

TEST(GaussianOrder, GaussiansReadingTheSameLatentTexelsAreContiguous) {
  at::manual_seed(7);
  const int64_t side = 16;
  // Past the border too, where the sampler clamps to the outermost texels.
  const at::Tensor uv = at::rand({20000, 2}, at::kDouble) * 1.1 - 0.05;
  const at::Tensor ordered = uv.index_select(0, uv_order(uv, side));
  const at::Tensor taps = top_left_taps(ordered, side);
  const int64_t groups = std::get<0>(at::_unique(taps)).numel();
  EXPECT_EQ(changes(taps), groups - 1);
  // Rows from the top: the taps only grow.
  EXPECT_TRUE(taps.slice(0, 1).ge(taps.slice(0, 0, -1)).all().item<bool>());

  // Cells of the same size half a texel off the taps (the earlier order)
  // would split most groups.
  const at::Tensor cell = (uv * side).floor().clamp(0, side - 1).to(at::kLong);
  const at::Tensor by_cell = uv.index_select(0, std::get<1>(((side - 1 - cell.select(1, 1)) * side + cell.select(1, 0))
                                                                .sort(true, 0, false)));
  EXPECT_GT(changes(top_left_taps(by_cell, side)), 10 * groups);
}

TEST(GaussianOrder, RefusesASideBelowOne) {
  EXPECT_THROW(uv_order(at::rand({4, 2}), 0), c10::Error);
}

}  // namespace
}  // namespace tega::trainer
