#pragma once
// `tega ingest multiface`: a Multiface capture -> tega's native dataset
// (docs/multiface.md, docs/layouts.md#dataset).

#include <filesystem>
#include <string>
#include <vector>

#include "tega/ingest/options.h"

namespace tega::ingest {

struct IngestSummary {
  std::filesystem::path dataset;
  int train_frames = 0, test_frames = 0, images = 0;
  int missing_images = 0, dropped_frames = 0;  // recorded in the manifest (docs/multiface.md#missing-images)
  std::vector<std::string> train_cameras, test_cameras;
};

// Reads the capture, checks every file the dataset needs (KRT, frame list,
// head poses, meshes, image sizes) before the heavy work, then writes the
// dataset through a staged directory: on any error nothing appears at `out`
// and the tega::Error names the file at fault. Images that are missing or
// unreadable are left out and recorded within options.missing_images' limits. An existing `out` is replaced
// only when `replace_existing`.
IngestSummary ingest_multiface(const std::filesystem::path& capture, const std::filesystem::path& out,
                               const IngestOptions& options, bool replace_existing = false);

}  // namespace tega::ingest
