#pragma once
// `--preview`: a contact sheet of one frame set, each camera's image shrunk
// to a tile at most 320 pixels wide, tiles in rig order, row by row; a
// missing camera's tile stays black. Atomic, so a viewer may reload it any time.
#include <filesystem>

#include "tega/capture/frame.h"
#include "tega/capture/pixel_format.h"

namespace tega::capture {

void write_contact_sheet(const FrameSet& set, const std::vector<PixelFormatInfo>& formats,
                         const std::filesystem::path& file);

}  // namespace tega::capture
