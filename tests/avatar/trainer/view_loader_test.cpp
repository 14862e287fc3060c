#include "tega/trainer/view_loader.h"

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <set>

#include "tega/core/error.h"
#include "test_support.h"

namespace {

using tega::trainer::View;
using tega::trainer::ViewLoader;

std::vector<View> all_views() { return {{0, 0}, {0, 1}, {1, 0}, {1, 1}}; }

TEST(ViewLoader, DeliversTheRightPixelsForEveryViewOncePerEpoch) {
  tega::test::TempDir tmp;
  tega::test::write_tiny_dataset(tmp.path());
  const auto dataset = tega::read_dataset(tmp.path());
  ViewLoader loader(dataset, all_views(), 7, 2, 3);
  for (int epoch = 0; epoch < 3; ++epoch) {
    std::set<std::pair<int, int>> seen;
    for (int i = 0; i < 4; ++i) {
      const auto loaded = loader.next();
      seen.insert({loaded.view.camera, loaded.view.frame});
      ASSERT_EQ(loaded.rgba.sizes(), (std::vector<int64_t>{6, 8, 4}));
      EXPECT_EQ(loaded.rgba[2][3][0].item<uint8_t>(), 10 * loaded.view.camera + loaded.view.frame);
      EXPECT_EQ(loaded.rgba[2][3][3].item<uint8_t>(), 255);
    }
    EXPECT_EQ(seen.size(), 4u) << "epoch " << epoch;
  }
}

TEST(ViewLoader, OrderDependsOnlyOnSeedAndPosition) {
  tega::test::TempDir tmp;
  tega::test::write_tiny_dataset(tmp.path());
  const auto dataset = tega::read_dataset(tmp.path());
  ViewLoader a(dataset, all_views(), 11, 1, 2);
  ViewLoader b(dataset, all_views(), 11, 2, 5);
  std::vector<std::pair<int, int>> first;
  for (int i = 0; i < 10; ++i) {
    const auto v = a.next().view;
    first.push_back({v.camera, v.frame});
  }
  b.seek(6);  // a resumed run at iteration 6
  for (int i = 6; i < 10; ++i) {
    const auto v = b.next().view;
    EXPECT_EQ(std::make_pair(v.camera, v.frame), first[i]) << "position " << i;
  }
  ViewLoader other_seed(dataset, all_views(), 12, 1, 2);
  bool differs = false;
  for (int i = 0; i < 10; ++i) {
    const auto v = other_seed.view_at(i);
    differs |= std::make_pair(v.camera, v.frame) != first[i];
  }
  EXPECT_TRUE(differs);
}

TEST(ViewLoader, UnreadableImageIsNamed) {
  tega::test::TempDir tmp;
  tega::test::write_tiny_dataset(tmp.path());
  const auto dataset = tega::read_dataset(tmp.path());
  tega::test::write_text(dataset.image_path("cam00", "smile_000000"), "not a png");
  ViewLoader loader(dataset, {{0, 0}}, 1, 1, 1);
  try {
    loader.next();
    FAIL() << "expected an error";
  } catch (const tega::Error& e) {
    EXPECT_NE(std::string(e.what()).find("cam00/smile_000000.png"), std::string::npos) << e.what();
  }
}

}  // namespace
