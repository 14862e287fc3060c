#pragma once
// The take of the empty studio that mattes subtract (MatteOptions).

#include <optional>

#include "tega/core/take.h"
#include "tega/matting/matte_options.h"

namespace tega::matting {

// The capture's clean plate take as the options choose it; none (with a
// warning) when the capture has none or the options turn it off. Throws
// tega::Error naming take.json when the named take is not a clean plate.
std::optional<TakeInfo> clean_plate_take(const CaptureInfo& capture, const MatteOptions& options);

}  // namespace tega::matting
