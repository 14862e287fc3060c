// Evaluation: the table of eval.json (the paper's Table 1 protocol, mean and
// standard deviation over the views of each split), linking eval.md.

#include <nlohmann/json.hpp>
#include <optional>

#include "report_context.h"
#include "tega/core/error.h"
#include "tega/core/files.h"

namespace tega::report {
namespace fs = std::filesystem;

namespace {

using MetricColumns = std::vector<std::pair<std::string, int>>;  // metric, decimals

const MetricColumns kMetrics = {
    {"psnr", 2},      {"ssim", 4},           {"l1", 4},
    {"lpips", 4},     {"psnr_masked", 2},    {"ssim_masked", 4},
    {"l1_masked", 4}, {"hf_psnr_masked", 2}, {"gradient_error_masked", 4},
    {"psnr_background", 2}, {"landmark_px", 2}, {"landmark_drift_px", 2}};

// Inside the head mask, in boxes around the eyes and the mouth: a table of their own.
const MetricColumns kCloseupMetrics = {
    {"closeup_eyes_psnr", 2},          {"closeup_eyes_ssim", 4},  {"closeup_eyes_hf_psnr", 2},
    {"closeup_eyes_gradient_error", 4}, {"closeup_mouth_psnr", 2}, {"closeup_mouth_ssim", 4},
    {"closeup_mouth_hf_psnr", 2},      {"closeup_mouth_gradient_error", 4}};

// eval.json writes non-finite numbers as strings ("inf", "nan").
std::string statistic(const nlohmann::json& value, int decimals) {
  return value.is_string() ? value.get<std::string>() : fixed(value.get<double>(), decimals);
}

// The rows (model, split, views) and a column per metric that some split has; nullopt when none has any.
std::optional<Table> metric_table(const nlohmann::json& eval, const MetricColumns& columns) {
  Table table{{"model", "split", "views"}, {}};
  MetricColumns shown;
  for (const auto& column : columns) {
    bool present = false;
    for (const auto& model : eval.at("models"))
      for (const auto& result : model.at("splits")) present |= result.at("metrics").contains(column.first);
    if (present) table.header.push_back(column.first), shown.push_back(column);
  }
  if (shown.empty()) return std::nullopt;
  for (const auto& model : eval.at("models")) {
    const nlohmann::json& splits = model.at("splits");
    for (auto it = splits.begin(); it != splits.end(); ++it) {
      const nlohmann::json& result = it.value();
      std::vector<std::string> row{model.at("name").get<std::string>(), it.key(),
                                   std::to_string(result.at("views").get<long>())};
      const auto& metrics = result.at("metrics");
      for (const auto& [metric, decimals] : shown)
        row.push_back(metrics.contains(metric) ? statistic(metrics.at(metric).at("mean"), decimals) + " ± " +
                                                     statistic(metrics.at(metric).at("std"), decimals)
                                               : "-");
      table.rows.push_back(std::move(row));
    }
  }
  return table;
}

}  // namespace

Section evaluation_section(const StageOutput& stage, ReportContext& context) {
  Section section{"Evaluation", {}};
  const fs::path file = artifact(stage, "eval");
  try {
    const auto eval = nlohmann::json::parse(read_text_file(file));
    if (eval.value("format", "") != "tega-eval")
      throw Error(file, "is not a tega eval file (its format is not 'tega-eval')");
    section.text("Evaluation " + context.link(file) +
                 " (the table as eval writes it: " + context.link(file.parent_path() / "eval.md") +
                 "). Reenactment: held-out frames from the training "
                 "cameras; novel view: training frames from held-out cameras; mean ± std over the views.");
    if (std::optional<Table> table = metric_table(eval, kMetrics)) section.table(std::move(*table));
    if (std::optional<Table> closeups = metric_table(eval, kCloseupMetrics)) {
      section.text("Close-ups: the same metrics inside the head mask, in boxes around the eyes and the mouth.");
      section.table(std::move(*closeups));
    }
    const nlohmann::json notes = eval.value("notes", nlohmann::json::object());
    // Each note names the metric it is about.
    for (const char* name : {"lpips", "landmark_px", "landmark_drift_px", "closeups"})
      if (notes.contains(name) && notes.at(name).is_string()) section.text(notes.at(name).get<std::string>());
  } catch (const nlohmann::json::exception& e) {
    throw Error(file, std::string("is not a tega eval file: ") + e.what());
  }
  return section;
}

}  // namespace tega::report
