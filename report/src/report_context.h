#pragma once
// What every section of a subject's page is built with, and what it adds
// beyond its own section: figures to write and ground-truth scores for the
// self-test table.

#include <filesystem>
#include <string>
#include <vector>

#include "page.h"
#include "tega/core/geometry.h"
#include "tega/report/report.h"
#include "workspace_outputs.h"

namespace tega::report {

// One line of the self-test: a stage's output scored against the studio's truth.
struct Score {
  std::string stage, measure, value, target;
  std::string verdict;  // "met", "missed" or "" (no target)
};

struct ReportContext {
  const SubjectOutputs& subject;
  const ReportOptions& options;
  std::filesystem::path page_dir;  // where the page will be: links are relative to it
  std::vector<Figure> figures;
  std::vector<Score> scores;
  std::vector<std::string> score_errors;  // a scoring that failed: "stage: error"

  // A file of the workspace as the page links to it.
  std::string link(const std::filesystem::path& file) const;
  // Adds a figure and puts it on `section`.
  void add_figure(Section& section, std::string file, Image8 image, std::string caption);
  bool scoring() const { return options.score_ground_truth && subject.virtual_studio(); }
};

// Each kind's section. They throw tega::Error (naming the file) when an output
// cannot be read; the caller puts the error on the page.
Section calibration_section(const StageOutput& stage, ReportContext& context);
Section mvs_section(const StageOutput& stage, ReportContext& context);
Section tracking_section(const StageOutput& stage, ReportContext& context);
Section matting_section(const StageOutput& stage, ReportContext& context);
Section training_section(const StageOutput& stage, ReportContext& context);
Section evaluation_section(const StageOutput& stage, ReportContext& context);
Section renders_section(const StageOutput& stage, ReportContext& context);

// Formatting shared by the sections.
std::string fixed(double value, int decimals);  // "nan" / "inf" spelled out
std::string verdict(bool met);
// `count` indices spread evenly over [0, n), first and last included when count >= 2.
std::vector<size_t> spread(size_t n, size_t count);
// From the world of the subject's calibrated rig, which later stages' meshes and poses are in, to
// the studio's truth's: the rigid motion that best carries the calibrated camera centres onto the
// true ones (align_camera_centres), so that one camera's error is not swung across the head a
// metre away, as a tie by the first camera would; that tie with fewer than 3 shared cameras. The
// identity where no calibrate stage ran (the stages then used the capture's own rig, the truth's).
RigidTransform calibrated_to_truth_world(const SubjectOutputs& subject);
// The artifact's path; throws tega::Error when the stage's kind provides no such artifact.
const std::filesystem::path& artifact(const StageOutput& stage, const std::string& name);

}  // namespace tega::report
