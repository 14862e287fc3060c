// The clean plate: one frame of the empty studio from every camera.

#include "studio.h"
#include "tega/synth/random.h"

namespace tega::synth {

void render_clean_plate(const Studio& studio) {
  const std::string take = "clean_plate";
  const int cameras = static_cast<int>(studio.rig.cameras.size());
  for (const auto& cam : studio.rig.cameras) std::filesystem::create_directories(studio.root / "takes" / take / cam.name);
  studio.pool.parallel_for(0, cameras, [&](int64_t c) {
    const Camera& cam = studio.rig.cameras[c];
    const uint64_t noise = hash_of(uint64_t(studio.options.seed), hash_string(take.c_str()), c, 0);
    write_studio_image(capture_image(nullptr, studio.backgrounds[c], noise, studio.options.noise_sigma), studio.root / "takes" / take / cam.name / (frame_name(0) + ".png"));
    studio.progress.advance();
  });
  write_take_json(studio, take, "clean_plate", 1);
}

}  // namespace tega::synth
