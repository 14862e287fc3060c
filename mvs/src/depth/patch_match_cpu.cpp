// The CPU path: every row of a colour's sweep on the thread pool.

#include "patch_match_backend.h"
#include "tega/core/thread_pool.h"

namespace tega::mvs::detail {
namespace {

GreyImage grey_image(const StereoView& view) {
  return {view.grey.pixels.data(), view.grey.width, view.grey.height};
}

class CpuBackend final : public PatchMatchBackend {
 public:
  CpuBackend(const std::vector<StereoView>& views, ThreadPool& pool)
      : views_(views), pool_(pool), current_(views.size()), next_(views.size()) {}

  void finish_pass() override {
    for (size_t v = 0; v < next_.size(); ++v)
      if (!next_[v].depth.empty()) current_[v] = std::move(next_[v]);
    next_.assign(views_.size(), {});
  }
  void set_estimate(int view, const DepthMap& map) override { current_[size_t(view)] = map; }
  DepthMap estimate(int view) const override { return current_[size_t(view)]; }

  void run(const ViewTask& task, Parameters params, int first_iteration, int sweeps) override {
    const StereoView& view = views_[task.reference];
    ReferenceView ref = reference_geometry(view.camera);
    ref.image = grey_image(view);
    ref.mask = view.mask.empty() ? nullptr : view.mask.data();
    std::vector<SourceView> sources;
    for (int s : task.sources) {
      SourceView source = source_geometry(view.camera, views_[s].camera);
      source.image = grey_image(views_[s]);
      // A source without an estimate adds the same penalty to every hypothesis.
      if (params.geometric && !current_[s].depth.empty()) source.depth = current_[s].depth.data();
      sources.push_back(source);
    }
    const int width = ref.image.width, height = ref.image.height;
    DepthMap& map = next_[task.reference];
    map = params.geometric ? current_[task.reference] : DepthMap(width, height);
    const PixelStates states{map.depth.data(), map.normals.data(), map.cost.data()};

    if (!params.geometric) {
      pool_.parallel_for(0, height, [&](int64_t y) {
        for (int x = 0; x < width; ++x) initialise_pixel(ref, sources.data(), params, states, x, int(y));
      });
    }
    for (int sweep = 0; sweep < sweeps; ++sweep) {
      params.iteration = first_iteration + sweep;
      for (int colour = 0; colour < 2; ++colour) {
        pool_.parallel_for(0, height, [&](int64_t y) {
          for (int x = int((y + colour) & 1); x < width; x += 2)
            update_pixel(ref, sources.data(), params, states, x, int(y));
        });
      }
    }
  }

 private:
  const std::vector<StereoView>& views_;
  ThreadPool& pool_;
  std::vector<DepthMap> current_, next_;  // by view
};

}  // namespace

std::unique_ptr<PatchMatchBackend> make_cpu_backend(const std::vector<StereoView>& views, ThreadPool& pool) {
  return std::make_unique<CpuBackend>(views, pool);
}

}  // namespace tega::mvs::detail
