#include "clean_plate.h"

#include "tega/core/error.h"
#include "tega/core/log.h"

namespace tega::matting {

std::optional<TakeInfo> clean_plate_take(const CaptureInfo& capture, const MatteOptions& options) {
  if (!options.use_clean_plate) return std::nullopt;
  std::string name = options.clean_plate_take;
  if (name.empty())
    for (const auto& take : capture.takes)
      if (take.kind == "clean_plate") name = take.name;
  if (name.empty()) {
    logging::warn("matte: %s has no clean_plate take: mattes come from the tracked mesh alone, without hair and "
                  "with a soft edge", capture.root.c_str());
    return std::nullopt;
  }
  TakeInfo take = read_take(capture.root / "takes" / name);
  if (take.kind != "clean_plate")
    throw Error(take.folder / "take.json", "is a " + take.kind + " take, not a clean plate (matte.clean_plate_take)");
  return take;
}

}  // namespace tega::matting
