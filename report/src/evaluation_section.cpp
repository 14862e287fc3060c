// Evaluation: the table of eval.json (the paper's Table 1 protocol, mean and
// standard deviation over the views of each split), linking eval.md.

#include <algorithm>
#include <nlohmann/json.hpp>

#include "report_context.h"
#include "tega/core/error.h"
#include "tega/core/files.h"

namespace tega::report {
namespace fs = std::filesystem;

namespace {

const std::vector<std::pair<std::string, int>> kMetrics = {
    {"psnr", 2},      {"ssim", 4},           {"l1", 4},
    {"lpips", 4},     {"psnr_masked", 2},    {"ssim_masked", 4},
    {"l1_masked", 4}, {"hf_psnr_masked", 2}, {"gradient_error_masked", 4},
    {"landmark_px", 2}};

// eval.json writes non-finite numbers as strings ("inf", "nan").
std::string statistic(const nlohmann::json& value, int decimals) {
  return value.is_string() ? value.get<std::string>() : fixed(value.get<double>(), decimals);
}

}  // namespace

Section evaluation_section(const StageOutput& stage, ReportContext& context) {
  Section section{"Evaluation", {}};
  const fs::path file = artifact(stage, "eval");
  try {
    const auto eval = nlohmann::json::parse(read_text_file(file));
    if (eval.value("format", "") != "tega-eval")
      throw Error(file, "is not a tega eval file (its format is not 'tega-eval')");
    Table table{{"model", "split", "views"}, {}};
    std::vector<std::string> shown;
    for (const auto& [metric, decimals] : kMetrics) {
      bool present = false;
      for (const auto& model : eval.at("models"))
        for (const auto& result : model.at("splits")) present |= result.at("metrics").contains(metric);
      if (present) table.header.push_back(metric), shown.push_back(metric);
    }
    for (const auto& model : eval.at("models")) {
      const nlohmann::json& splits = model.at("splits");
      for (auto it = splits.begin(); it != splits.end(); ++it) {
        const nlohmann::json& result = it.value();
        std::vector<std::string> row{model.at("name").get<std::string>(), it.key(),
                                     std::to_string(result.at("views").get<long>())};
        for (const auto& metric : shown) {
          const auto& metrics = result.at("metrics");
          const int decimals =
              std::find_if(kMetrics.begin(), kMetrics.end(), [&](const auto& m) { return m.first == metric; })->second;
          row.push_back(metrics.contains(metric) ? statistic(metrics.at(metric).at("mean"), decimals) + " ± " +
                                                       statistic(metrics.at(metric).at("std"), decimals)
                                                 : "-");
        }
        table.rows.push_back(std::move(row));
      }
    }
    section.text("Evaluation " + context.link(file) +
                 " (the table as eval writes it: " + context.link(file.parent_path() / "eval.md") +
                 "). Reenactment: held-out frames from the training "
                 "cameras; novel view: training frames from held-out cameras; mean ± std over the views.");
    section.table(std::move(table));
    const nlohmann::json notes = eval.value("notes", nlohmann::json::object());
    for (const char* name : {"lpips", "landmarks"})
      if (notes.contains(name) && notes.at(name).is_string())
        section.text(std::string(name) + ": " + notes.at(name).get<std::string>());
  } catch (const nlohmann::json::exception& e) {
    throw Error(file, std::string("is not a tega eval file: ") + e.what());
  }
  return section;
}

}  // namespace tega::report
