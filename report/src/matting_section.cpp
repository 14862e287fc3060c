// Matting: per take how many frames were matted and which were not (not
// tracked), the share of each camera's image the subject covers (alpha >= 0.5)
// on a few frames, and in the virtual studio the mattes against the true alpha.

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>

#include "plot.h"
#include "report_context.h"
#include "tega/core/error.h"
#include "tega/core/files.h"

#include "tega/scoring/matte_scores.h"

namespace tega::report {
namespace fs = std::filesystem;

namespace {

struct MattedTake {
  std::string name;
  std::vector<std::string> cameras;
  int frames_matted = 0;
  std::vector<std::string> not_matted;  // "frame: reason"
};

MattedTake read_mattes_json(const fs::path& file) {
  try {
    const auto j = nlohmann::json::parse(read_text_file(file));
    MattedTake take{j.at("take").get<std::string>(),
                    j.at("cameras").get<std::vector<std::string>>(),
                    j.at("frames_matted").get<int>(),
                    {}};
    for (const auto& f : j.at("frames_not_tracked"))
      take.not_matted.push_back(std::to_string(f.at("frame").get<int>()) + ": " + f.value("status", "") + " " +
                                f.value("reason", ""));
    return take;
  } catch (const nlohmann::json::exception& e) {
    throw Error(file, std::string("is not a mattes summary: ") + e.what());
  }
}

// The share of pixels at alpha >= 0.5, over the camera's sampled mattes.
double coverage(const std::vector<fs::path>& mattes) {
  double covered = 0, pixels = 0;
  for (const auto& file : mattes) {
    const Image8 alpha = read_image_u8(file);
    for (size_t i = 0; i < alpha.pixels.size(); i += size_t(alpha.channels)) covered += alpha.pixels[i] >= 128;
    pixels += double(alpha.width) * alpha.height;
  }
  return pixels > 0 ? covered / pixels : 0;
}

// The matting issue's targets (docs/matting.md#figures): mean |alpha error|
// 0.02 per image, 0.1 within 3 px of the edge, silhouette IoU 0.98.
void score_take(const std::string& stage_name, const fs::path& mattes, const std::string& take, Section& section,
                ReportContext& context) {
  const scoring::MatteScores s = scoring::score_mattes(mattes, context.subject.truth, take);
  Table table{{"measure", "mean", "worst image", "target"}, {}};
  const std::string stage = stage_name + " (" + take + ")";
  const auto worst = [](const std::string& value, const std::string& image) { return value + " (" + image + ")"; };
  table.rows.push_back({"|alpha error|", fixed(s.mean_error, 4), worst(fixed(s.worst_mean_error, 4), s.worst_mean_image),
                        "<= 0.02 per image"});
  table.rows.push_back({"|alpha error| within 3 px of the edge", fixed(s.boundary_error, 3),
                        worst(fixed(s.worst_boundary_error, 3), s.worst_boundary_image), "<= 0.1"});
  table.rows.push_back({"silhouette IoU", fixed(s.iou, 4), worst(fixed(s.worst_iou, 4), s.worst_iou_image), ">= 0.98"});
  context.scores.push_back({stage, "alpha error, worst image", fixed(s.worst_mean_error, 4), "<= 0.02",
                            verdict(s.worst_mean_error <= 0.02)});
  context.scores.push_back({stage, "alpha error near the edge, worst image", fixed(s.worst_boundary_error, 3), "<= 0.1",
                            verdict(s.worst_boundary_error <= 0.1)});
  context.scores.push_back(
      {stage, "silhouette IoU, worst image", fixed(s.worst_iou, 4), ">= 0.98", verdict(s.worst_iou >= 0.98)});
  section.text("Take " + take + " against the virtual studio's true alpha (" + std::to_string(s.images) + " images):");
  section.table(std::move(table));
}

}  // namespace

Section matting_section(const StageOutput& stage, ReportContext& context) {
  Section section{"Matting", {}};
  const fs::path mattes = artifact(stage, "mattes");
  if (!fs::is_directory(mattes)) throw Error(mattes, "does not exist");
  std::vector<std::pair<fs::path, MattedTake>> takes;
  for (const auto& dir : fs::directory_iterator(mattes))
    if (fs::exists(dir.path() / "mattes.json"))
      takes.push_back({dir.path(), read_mattes_json(dir.path() / "mattes.json")});
  std::sort(takes.begin(), takes.end(), [](const auto& a, const auto& b) { return a.second.name < b.second.name; });
  if (takes.empty()) throw Error(mattes, "holds no matted take (no <take>/mattes.json)");
  Table table{{"take", "cameras", "frames matted", "frames not matted"}, {}};
  BarChart chart{"share of the image at alpha >= 0.5, %", {}, {}};
  for (const auto& [dir, take] : takes) {
    table.rows.push_back({take.name, std::to_string(take.cameras.size()), std::to_string(take.frames_matted),
                          std::to_string(take.not_matted.size())});
    for (const auto& camera : take.cameras) {
      std::vector<fs::path> files;
      if (fs::is_directory(dir / camera))
        for (const auto& f : fs::directory_iterator(dir / camera))
          if (f.path().extension() == ".png") files.push_back(f.path());
      std::sort(files.begin(), files.end());
      std::vector<fs::path> sampled;
      for (size_t i : spread(files.size(), size_t(context.options.coverage_frames_per_take)))
        sampled.push_back(files[i]);
      chart.labels.push_back(takes.size() > 1 ? take.name + "/" + camera : camera);
      chart.values.push_back(100 * coverage(sampled));
    }
  }
  section.text("Mattes " + context.link(mattes) + "/:");
  section.table(std::move(table));
  for (const auto& [dir, take] : takes)
    for (const auto& line : take.not_matted) section.text("Not matted in " + take.name + ": frame " + line);
  context.add_figure(section, "matte_coverage.png", draw_bar_chart(chart), "Matte coverage per camera");
  if (context.scoring()) {
    for (const auto& [dir, take] : takes) {
      try {
        score_take(stage.stage, mattes, take.name, section, context);
      } catch (const std::exception& e) {
        context.score_errors.push_back(stage.stage + " (" + take.name + "): " + e.what());
      }
    }
  }
  return section;
}

}  // namespace tega::report
