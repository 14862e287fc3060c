// Training: the run's curves from RUN/metrics.csv (loss, PSNR on the training
// batch, Gaussian count per logged iteration) and its summary, RUN/run.json.

#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

#include "plot.h"
#include "report_context.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/progress.h"

namespace tega::report {
namespace fs = std::filesystem;

namespace {

struct Curves {
  std::vector<double> iteration, loss, psnr, gaussians, seconds;
};

// metrics.csv: "iteration,loss,psnr,gaussians,seconds" (docs/training.md#the-run-directory).
Curves read_metrics(const fs::path& file) {
  std::istringstream in(read_text_file(file));
  std::string line;
  std::getline(in, line);
  if (line.rfind("iteration,loss,psnr,gaussians", 0) != 0)
    throw Error(file, "is not a training metrics log (its header is '" + line +
                          "', not 'iteration,loss,psnr,gaussians,seconds')");
  Curves c;
  for (int row = 2; std::getline(in, line); ++row) {
    if (line.empty()) continue;
    std::istringstream fields(line);
    double v[5];
    char comma;
    if (!(fields >> v[0] >> comma >> v[1] >> comma >> v[2] >> comma >> v[3] >> comma >> v[4]))
      throw Error(file, "line " + std::to_string(row) + " is not five numbers: '" + line + "'");
    c.iteration.push_back(v[0]), c.loss.push_back(v[1]), c.psnr.push_back(v[2]);
    c.gaussians.push_back(v[3]), c.seconds.push_back(v[4]);
  }
  return c;
}

}  // namespace

Section training_section(const StageOutput& stage, ReportContext& context) {
  Section section{"Training", {}};
  const fs::path run = artifact(stage, "run");
  const Curves curves = read_metrics(run / "metrics.csv");
  const fs::path summary_file = run / "run.json";
  try {
    const auto summary = nlohmann::json::parse(read_text_file(summary_file));
    const auto number = [&](const char* key) {
      return summary.at(key).is_number() ? summary.at(key).get<double>() : NAN;
    };
    section.text("Run " + context.link(run) + "/:");
    section.table(
        {{"iterations", "Gaussians", "final loss", "train PSNR dB", "held-out PSNR dB", "time"},
         {{std::to_string(summary.at("iterations").get<long>()), std::to_string(summary.at("gaussians").get<long>()),
           fixed(number("final_loss"), 5), fixed(number("train_psnr"), 2), fixed(number("heldout_psnr"), 2),
           Progress::format_duration(number("seconds"))}}});
  } catch (const nlohmann::json::exception& e) {
    throw Error(summary_file, std::string("is not a run summary: ") + e.what());
  }
  if (curves.iteration.empty()) {
    section.text(context.link(run / "metrics.csv") + " has no rows yet.");
    return section;
  }
  context.add_figure(section, "training_curves.png",
                     draw_line_panels({{"loss", {{"loss", curves.iteration, curves.loss}}},
                                       {"PSNR on the training batch, dB", {{"PSNR", curves.iteration, curves.psnr}}},
                                       {"Gaussians", {{"Gaussians", curves.iteration, curves.gaussians}}}},
                                      "iteration"),
                     "Loss, PSNR and Gaussian count over the iterations");
  return section;
}

}  // namespace tega::report
