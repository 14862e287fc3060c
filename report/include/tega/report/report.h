#pragma once
// `tega report WORKSPACE` (docs/report.md): one page per subject of a pipeline
// workspace saying what each stage made and how well: calibration RMS per
// camera, MVS and tracking residuals, matte coverage, training curves, the
// evaluation table and a contact sheet of renders beside their photos. When
// the capture came from the virtual studio (it has ground_truth/), every
// stage's output is also scored against the truth: the studio's self-test.
//
// The page is built from what the workspace's committed shards hold (found
// through the pipeline's config and stage kinds, as `tega status` finds
// them). A stage that has not run, or whose output cannot be read, is said
// so on the page; it never stops the report.

#include <filesystem>
#include <string>
#include <vector>

#include "tega/core/image.h"

namespace tega::report {

struct ReportOptions {
  // Where the pages go: OUT/<subject>/report.md, report.html and the PNGs.
  // Empty (the default): WORKSPACE/report.
  std::filesystem::path out;
  // The subjects to report on, by name; empty (the default): every subject
  // of the config the workspace was last run with. An unknown name is an error.
  std::vector<std::string> subjects;
  // Score each stage against the virtual studio's ground truth when the
  // subject's capture has one (default true). The slow part of a report.
  bool score_ground_truth = true;
  // MVS meshes scored against the truth per take (default 3), spread evenly
  // over the take's frames: each takes seconds.
  int scored_frames_per_take = 3;
  // Frames per take and camera whose mattes are read for the coverage plot
  // (default 3), spread evenly over the matted frames.
  int coverage_frames_per_take = 3;
  // Views on the contact sheet of renders beside their photos (default 6)
  // and the width in pixels of each half of a view (default 192).
  int contact_sheet_views = 6;
  int contact_sheet_tile_width = 192;
  // The `tega` version that should have made the shards ("tega 0.1.0"); a
  // shard made by another or from other inputs is reported as stale (its
  // outputs are still shown). Empty (the default): this library's version.
  std::string tool_version;
};

// A PNG of the page: `file` is its name in the subject's folder.
struct Figure {
  std::string file;
  Image8 image;
};

struct SubjectReport {
  std::string subject;
  std::string markdown, html;  // the page, referring to `figures` by file name
  std::vector<Figure> figures;
};

struct Report {
  std::filesystem::path workspace;
  std::filesystem::path out;  // where write_report puts it (options.out resolved)
  std::vector<SubjectReport> subjects;
};

// Reads the workspace (its pipeline.json names the config of its latest run)
// and draws every page. Throws tega::Error only when the workspace itself
// cannot be read or a requested subject does not exist; a stage's unreadable
// output becomes a message on its page.
Report build_report(const std::filesystem::path& workspace, const ReportOptions& options);

// Writes report.out/<subject>/ for every subject: report.md, report.html and
// the figures, the folder staged and renamed into place (replacing an older
// one). Returns the pages' report.md files.
std::vector<std::filesystem::path> write_report(const Report& report);

}  // namespace tega::report
