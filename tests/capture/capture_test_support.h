#pragma once
// Rigs of Aravis' in-process simulated cameras, and reading back what a take holds.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "tega/capture/options.h"

namespace tega::test {

// `cameras` simulated cameras TEGA00, TEGA01, ... named cam00, cam01, ...
capture::RigConfig fake_rig(int cameras, int width = 160, int height = 120, double frame_rate = 30);

// frame_sets.csv as rows of column -> value.
std::vector<std::map<std::string, std::string>> read_frame_sets(const std::filesystem::path& take_folder);

// The value Aravis' simulated camera puts at (x, y) of frame `frame_id` at
// gain 0 and 10 ms exposure: its diagonal ramp.
inline int fake_camera_ramp(int x, int y, uint64_t frame_id) { return int((x + y + frame_id) % 255); }

}  // namespace tega::test
