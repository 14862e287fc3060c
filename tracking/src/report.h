#pragma once
// A take's tracking report for a person to look at: residuals per frame as
// plots, and the tracked mesh drawn over a few photos from the camera that
// faces the head most squarely.

#include <filesystem>
#include <vector>

#include "frame_record.h"
#include "tega/core/camera.h"
#include "tega/core/take.h"

namespace tega {
class ThreadPool;
}

namespace tega::tracking {

// Writes report_dir/residuals.png and report_dir/overlay_<frame>_<camera>.png
// for `overlays` tracked frames spread over the take (their meshes are read
// back from the take's folder, report_dir's parent).
void write_take_report(const std::filesystem::path& report_dir, const std::vector<FrameRecord>& records,
                       const TakeInfo& take, const std::vector<Camera>& cameras, const HeadModel& model, int overlays,
                       ThreadPool& pool);

}  // namespace tega::tracking
