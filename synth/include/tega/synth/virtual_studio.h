#pragma once
// `tega synth`: renders a synthetic capture of a head in a virtual studio and
// writes it in the layout a real capture plus calibration produces, together
// with its ground truth and a ready dataset (docs/virtual-studio.md).

#include <filesystem>
#include <string>
#include <vector>

#include "tega/synth/head.h"
#include "tega/synth/options.h"

namespace tega::synth {

struct TakeSummary {
  std::string name;
  std::string kind;  // clean_plate, calibration or performance
  int frames = 0;
};

struct SynthSummary {
  std::filesystem::path root;
  std::string head;
  int cameras = 0, width = 0, height = 0;
  std::vector<TakeSummary> takes;
  bool calibration_skipped = false;  // built without OpenCV
  int64_t images = 0;                // camera images rendered
  int dataset_frames = 0;
  double seconds = 0;
};

// Throws tega::Error naming the option at fault.
void validate_options(const Options& options);

// The head the options ask for (procedural or loaded from options.head).
Head make_head(const Options& options);

// Where the ground truth of a capture rendered into `out` goes with
// Options::truth_apart: the sibling `out`.truth.
std::filesystem::path truth_directory(const std::filesystem::path& out);

// Renders everything into `out` (and, with Options::truth_apart, the ground
// truth into truth_directory(out)), each of which appears complete or not at
// all (tega::StagedDirectory); the truth is committed first. An existing
// `out` (or truth) is replaced only when `replace_existing`; otherwise it is
// an error naming it.
SynthSummary render_virtual_studio(const Options& options, const std::filesystem::path& out,
                                   bool replace_existing = false);

}  // namespace tega::synth
